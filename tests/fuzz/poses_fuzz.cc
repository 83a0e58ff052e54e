// Fuzzes the reader of estimated poses (`nphand eval poses`): the bytes are a poses.jsonl
// compared against a fixed truth.jsonl (NPHAND_FUZZ_TRUTH, made by scripts/fuzz.sh from a
// rendered sequence): lines that are not JSON, fields missing or of the wrong type, wrong
// counts of keypoints, frames out of step.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "nphand/eval/pose_errors.h"
#include "nphand/util/check.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const char* truth = std::getenv("NPHAND_FUZZ_TRUTH");
  if (truth == nullptr) std::abort();
  static const std::filesystem::path poses =
      std::filesystem::temp_directory_path() / ("nphand_fuzz_poses_" + std::to_string(::getpid()) + ".jsonl");
  {
    std::ofstream out(poses, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  }
  try {
    const nphand::PoseErrorSummary summary = nphand::ComparePoses(truth, poses);
    nphand::ToJson(summary);
  } catch (const nphand::Error&) {
  }
  return 0;
}
