// Fuzzes the resumption of an interrupted build: the input is a partial file and its block
// checksums; the writer resumes them for the seed database's header, the build is completed
// with blank records, and the finished file must then pass its structural checks: whatever
// the partial held, resuming never yields a file that fails its own checksum.
// Input: u32 partial length | partial bytes | block checksum bytes.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

#include "nphand/db/database.h"
#include "nphand/util/check.h"
#include "tests/fuzz/fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 4) return 0;
  uint32_t partial_bytes = 0;
  std::memcpy(&partial_bytes, data, 4);
  if (partial_bytes > size - 4) return 0;
  const std::filesystem::path path = nphand::fuzz::ScratchPath("resumed.db");
  nphand::fuzz::WriteBytes(path.string() + ".partial", {data + 4, partial_bytes});
  nphand::fuzz::WriteBytes(path.string() + ".partial.blocks", {data + 4 + partial_bytes, size - 4 - partial_bytes});

  const nlohmann::json& header = nphand::fuzz::SeedHeader();
  nphand::DatabaseWriter writer(path, header, nphand::DatabaseWriter::Mode::kResume);
  const uint64_t entries = header["entries"].get<uint64_t>();
  const size_t record_bytes = header["record_bytes"].get<size_t>();
  const std::vector<uint8_t> blank(record_bytes, 0);
  while (writer.records_written() < entries) writer.Append(blank);
  writer.Finish();
  try {
    nphand::Database::Open(path, /*verify_records=*/false);
  } catch (const nphand::Error& e) {
    std::fprintf(stderr, "resumed file refused: %s\n", e.what());
    std::abort();
  }
  return 0;
}
