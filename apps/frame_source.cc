#include "apps/frame_source.h"

#include <algorithm>
#include <cctype>

#include <opencv2/imgcodecs.hpp>

#include "nphand/util/check.h"
#include "nphand/util/io.h"
#include "nphand/util/text.h"

namespace nphand {
namespace {

bool IsImage(const std::filesystem::path& path) {
  const std::string ext = AsciiLower(path.extension().string());
  return ext == ".png" || ext == ".jpg" || ext == ".jpeg" || ext == ".bmp" || ext == ".tif" || ext == ".tiff";
}

// A JPEG ends with its end-of-image marker (FF D9). One cut short still decodes (libjpeg
// fills the rest grey and only warns on stderr), so it is checked here.
bool JpegEndsWhole(const std::vector<uint8_t>& bytes) {
  size_t end = bytes.size();
  while (end > 0 && bytes[end - 1] == 0) --end;  // padding after the marker
  return end >= 4 && bytes[0] == 0xFF && bytes[1] == 0xD8 && bytes[end - 2] == 0xFF && bytes[end - 1] == 0xD9;
}

// Reads and decodes one image of a folder into `frame`, or says why it cannot.
void ReadImage(const std::filesystem::path& path, Frame* frame) {
  std::vector<uint8_t> bytes;
  try {
    bytes = ReadFileBytes(path);
  } catch (const Error& e) {
    frame->error = Utf8OrEscaped(e.what());
    return;
  }
  if (bytes.empty()) {
    frame->error = "the file is empty";
    return;
  }
  try {
    frame->bgr = cv::imdecode(bytes, cv::IMREAD_COLOR);
  } catch (const cv::Exception& e) {
    // Some decoders throw instead of returning nothing, e.g. for a header promising more
    // pixels than OpenCV accepts.
    frame->error = "cannot decode this image: " + Utf8OrEscaped(e.err);
    return;
  }
  if (frame->bgr.empty()) {
    frame->error = "cannot decode this image (truncated, damaged or not an image)";
    return;
  }
  if (bytes.size() >= 2 && bytes[0] == 0xFF && bytes[1] == 0xD8 && !JpegEndsWhole(bytes)) {
    frame->warnings.push_back("truncated JPEG: no end-of-image marker, so the lower part of the image is missing");
  }
}

}  // namespace

FrameSource::FrameSource(const std::string& input, double fps) : input_(input), fps_(fps) {
  NPHAND_THROW_CHECK(!input.empty(), "--input: give a video file, an image folder or a camera index");
  NPHAND_THROW_CHECK(fps > 0.0 && fps <= 1000.0, "--fps must be within (0, 1000]");
  const std::filesystem::path path(input);
  std::error_code error;
  if (std::filesystem::is_directory(path, error)) {
    kind_ = "folder";
    for (const auto& item : std::filesystem::directory_iterator(path)) {
      if (item.is_regular_file() && IsImage(item.path())) images_.push_back(item.path());
    }
    std::sort(images_.begin(), images_.end());
    NPHAND_THROW_CHECK(!images_.empty(), input, ": no images in this folder (.png, .jpg, .bmp, .tif)");
    count_ = images_.size();
    return;
  }
  const bool digits = std::all_of(input.begin(), input.end(), [](unsigned char c) { return std::isdigit(c); });
  if (digits && !std::filesystem::exists(path, error)) {
    kind_ = "camera";
    NPHAND_THROW_CHECK(input.size() < 4, "--input ", input, ": not a camera index (0..999)");
    // Video4Linux only: probing every back end (FireWire, GStreamer) for a missing camera is
    // slow and leaks in those libraries.
    capture_.open(std::stoi(input), cv::CAP_V4L2);
    NPHAND_THROW_CHECK(capture_.isOpened(), "camera ", input, " is not there (or cannot be opened)");
    const double camera_fps = capture_.get(cv::CAP_PROP_FPS);
    if (camera_fps > 0.0) fps_ = camera_fps;
    return;
  }
  NPHAND_THROW_CHECK(std::filesystem::exists(path, error), input, ": no such file or folder");
  NPHAND_THROW_CHECK(std::filesystem::is_regular_file(path, error), input, ": not a video file or an image folder");
  kind_ = "video";
  // FFmpeg reads every common container; GStreamer, the other back end Debian's OpenCV
  // tries, fails on a file that is not a video with an assertion of its own.
  capture_.open(input, cv::CAP_FFMPEG);
  NPHAND_THROW_CHECK(capture_.isOpened(), input,
                     ": cannot read this as a video (not a video, or damaged: an MP4 cut short before its index cannot be read at all)");
  const double video_fps = capture_.get(cv::CAP_PROP_FPS);
  if (video_fps > 0.0) fps_ = video_fps;
  const double frames = capture_.get(cv::CAP_PROP_FRAME_COUNT);
  count_ = frames > 0.0 ? static_cast<uint64_t>(frames) : 0;
}

std::optional<Frame> FrameSource::Next() {
  Frame frame;
  frame.time_s = static_cast<double>(next_) / fps_;
  if (kind_ == "folder") {
    if (next_ >= images_.size()) return std::nullopt;
    const std::filesystem::path& path = images_[next_];
    frame.name = Utf8OrEscaped(path.filename().string());
    ReadImage(path, &frame);
    if (!frame.error.empty()) {
      ++next_;
      return frame;
    }
  } else {
    bool read = false;
    try {
      read = capture_.read(frame.bgr);
    } catch (const cv::Exception& e) {
      NPHAND_THROW(input_, ": frame ", next_, " cannot be decoded: ", Utf8OrEscaped(e.err));
    }
    if (!read || frame.bgr.empty()) {
      // A video that gives not even its first frame is not a video.
      NPHAND_THROW_CHECK(next_ > 0, input_, ": no frame could be read from this ", kind_);
      return std::nullopt;
    }
  }
  NPHAND_THROW_CHECK(frame.bgr.type() == CV_8UC3, input_, ": frame ", next_, " is not an 8-bit colour image");
  ++next_;
  return frame;
}

}  // namespace nphand
