// Fuzzes the frame readers of `nphand estimate` (apps/frame_source.h): the first byte picks
// how the rest is read — as an image in a folder (.png, .jpg, .bmp) or as a video file —
// and every frame is read to the end. A folder's image that cannot be read must become a
// frame with an error, never an exception; a video may be refused with nphand::Error.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>

#include "apps/frame_source.h"
#include "nphand/util/check.h"
#include "tests/fuzz/fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  static const char* kExtensions[] = {".png", ".jpg", ".bmp"};
  static const std::filesystem::path folder = nphand::fuzz::ScratchPath("frames");
  static const std::filesystem::path video = nphand::fuzz::ScratchPath("video");
  const std::span<const uint8_t> bytes(data + 1, size - 1);
  const int kind = data[0] % 4;
  if (kind < 3) {
    std::filesystem::remove_all(folder);
    std::filesystem::create_directories(folder);
    nphand::fuzz::WriteBytes(folder / (std::string("frame") + kExtensions[kind]), bytes);
    nphand::FrameSource source(folder.string(), 30.0);
    int frames = 0;
    while (const std::optional<nphand::Frame> frame = source.Next()) {
      if (frame->error.empty() && frame->bgr.empty()) std::abort();  // a frame is an image or an error
      ++frames;
    }
    if (frames != 1) std::abort();
    return 0;
  }
  nphand::fuzz::WriteBytes(video, bytes);
  try {
    nphand::FrameSource source(video.string(), 30.0);
    for (int frames = 0; frames < 64 && source.Next().has_value(); ++frames) {
    }
  } catch (const nphand::Error&) {
  }
  return 0;
}
