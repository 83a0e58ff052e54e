// Fuzzes Database::Open (and every reader after it) with whole files: magic, version,
// header length and checksum, padding, sizes, footer and the records' checksum.
#include <cstddef>
#include <cstdint>

#include "tests/fuzz/fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::filesystem::path path = nphand::fuzz::ScratchPath("file.db");
  nphand::fuzz::WriteBytes(path, {data, size});
  nphand::fuzz::OpenAndReadEverything(path);
  return 0;
}
