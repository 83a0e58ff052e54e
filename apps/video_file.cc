#include "apps/video_file.h"

#include "nphand/render/draw.h"
#include "nphand/util/check.h"

namespace nphand {

VideoFile::VideoFile(const std::filesystem::path& path, double fps)
    : path_(path), partial_(path.string() + ".partial.mp4"), lock_(File::OpenLocked(partial_)), fps_(fps) {
  lock_.Truncate(0);
}

VideoFile::~VideoFile() {
  if (done_) return;
  video_.release();
  std::error_code ec;
  std::filesystem::remove(partial_, ec);
}

void VideoFile::Size(cv::Size size) {
  if (size_.area() == 0) size_ = size;
}

void VideoFile::Write(const cv::Mat& picture) {
  Size(picture.size());
  if (!video_.isOpened()) {
    video_.open(partial_.string(), cv::CAP_FFMPEG, cv::VideoWriter::fourcc('m', 'p', '4', 'v'), fps_, size_);
    NPHAND_THROW_CHECK(video_.isOpened(), partial_.string(), ": cannot open a video writer (MPEG-4)");
  }
  video_.write(FitInto(picture, size_, cv::Scalar(32, 32, 32)));
  ++frames_;
}

void VideoFile::Finish() {
  video_.release();
  cv::VideoCapture check(partial_.string(), cv::CAP_FFMPEG);
  const double held = check.isOpened() ? check.get(cv::CAP_PROP_FRAME_COUNT) : 0.0;
  check.release();
  NPHAND_THROW_CHECK(held == static_cast<double>(frames_), path_.string(), ": the video is damaged: ", partial_.string(),
                     " holds ", static_cast<uint64_t>(held), " of the ", frames_,
                     " frames written (is the disk full?); it was removed");
  std::error_code ec;
  std::filesystem::rename(partial_, path_, ec);
  NPHAND_THROW_CHECK(!ec, path_.string(), ": cannot rename ", partial_.string(), " into place (", ec.message(), ")");
  done_ = true;
}

}  // namespace nphand
