// Where `nphand estimate` reads frames: a video file, a folder of images (in name order) or
// a camera (its index). Each gives a clear one-line error when it cannot be read.
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
  cv::Mat bgr;
  double time_s = 0.0;
  std::string name;  // the image's file name, for folders
};

class FrameSource {
 public:
  // `input`: an existing video file or image folder, or a camera index ("0"). `fps` times
  // the frames of a folder (a video and a camera time their own). Throws nphand::Error when
  // the input is missing, not readable, an empty folder or a camera that is not there.
  FrameSource(const std::string& input, double fps);
  // The next frame, or nothing at the end. Throws nphand::Error for an image that cannot
  // be read (naming it).
  std::optional<Frame> Next();
  // Frames in all, if known (folders, most videos); 0 otherwise.
  uint64_t count() const { return count_; }
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
