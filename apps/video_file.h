// A video nphand writes (the overlay of `nphand estimate`, the video of `nphand sequence`):
// MPEG-4 under "<path>.partial.mp4", locked against a second writer from the start, renamed
// to `path` only once what reached the disk has been read back whole.
#pragma once

#include <cstdint>
#include <filesystem>

#include <opencv2/core.hpp>
#include <opencv2/videoio.hpp>

#include "nphand/util/file.h"

namespace nphand {

class VideoFile {
 public:
  // Locks (and empties) "<path>.partial.mp4"; throws naming it if another process holds it.
  VideoFile(const std::filesystem::path& path, double fps);
  // Removes the partial file unless Finish() succeeded.
  ~VideoFile();
  VideoFile(const VideoFile&) = delete;
  VideoFile& operator=(const VideoFile&) = delete;

  // Sets the frame size if no frame has set it yet.
  void Size(cv::Size size);
  cv::Size size() const { return size_; }
  // Appends a picture (8-bit BGR). The first sets the size; a later one of another size is
  // scaled to fit it with its aspect kept, on a dark border.
  void Write(const cv::Mat& picture);
  uint64_t frames() const { return frames_; }
  // Closes the video and reads it back: OpenCV's writer reports no failed write (a full
  // disk), so the file must open and hold every frame written. Then renames it to `path`.
  // Throws, removing the partial file, if it does not.
  void Finish();

 private:
  std::filesystem::path path_, partial_;
  File lock_;
  double fps_;
  cv::VideoWriter video_;
  cv::Size size_;
  uint64_t frames_ = 0;
  bool done_ = false;
};

}  // namespace nphand
