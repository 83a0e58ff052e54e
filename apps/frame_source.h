// Where `nphand estimate` reads frames: a video file, a folder of images (in name order) or
// a camera (its index). Each gives a clear one-line error when it cannot be opened; an
// image of a folder that cannot be read is one frame with an error, not the end of the run.
#pragma once

#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/videoio.hpp>

namespace nphand {

struct Frame {
  cv::Mat bgr;  // empty when `error` is set
  double time_s = 0.0;
  std::string name;                   // the image's file name, for folders (not UTF-8: escaped)
  std::string error;                  // why the frame could not be read (a folder's image)
  std::vector<std::string> warnings;  // read, but damaged (a truncated JPEG)
};

class FrameSource {
 public:
  // `input`: an existing video file or image folder, or a camera index ("0"). `fps` times
  // the frames of a folder (a video and a camera time their own). Throws nphand::Error when
  // the input is missing, not readable, an empty folder or a camera that is not there.
  FrameSource(const std::string& input, double fps);
  // The next frame, or nothing at the end. A folder's image that cannot be read or decoded
  // gives a frame with `error` set (naming why) and the folder goes on.
  std::optional<Frame> Next();
  // Frames in all, if known (folders, most videos: what the container says); 0 otherwise.
  uint64_t count() const { return count_; }
  // Frames given so far.
  uint64_t read() const { return next_; }
  // Every image of a folder, in order; empty for a video or a camera.
  const std::vector<std::filesystem::path>& images() const { return images_; }
  double fps() const { return fps_; }
  const std::string& kind() const { return kind_; }

 private:
  std::string input_, kind_;
  double fps_ = 30.0;
  uint64_t count_ = 0;
  uint64_t next_ = 0;
  std::vector<std::filesystem::path> images_;
  cv::VideoCapture capture_;
};

}  // namespace nphand
