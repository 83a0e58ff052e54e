// Fuzzes what lies behind the checksums: the input is a header's JSON text and the records,
// and the target seals them into a file with valid checksums and footer, so that every
// mutation reaches the header schema and the record content checks.
// Input: u32 header length | header text | record bytes.
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <vector>

#include <zlib.h>

#include "tests/fuzz/fuzz_support.h"

namespace {

template <typename T>
void Put(std::vector<uint8_t>* out, T value) {
  const size_t at = out->size();
  out->resize(at + sizeof(T));
  std::memcpy(out->data() + at, &value, sizeof(T));
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 4) return 0;
  uint32_t header_bytes = 0;
  std::memcpy(&header_bytes, data, 4);
  if (header_bytes > size - 4) return 0;
  const uint8_t* header = data + 4;
  const uint8_t* records = header + header_bytes;
  const size_t record_bytes = size - 4 - header_bytes;

  std::vector<uint8_t> file = {'N', 'P', 'H', 'A', 'N', 'D', 'D', 'B'};
  Put<uint32_t>(&file, 1);
  Put<uint32_t>(&file, header_bytes);
  file.insert(file.end(), header, header + header_bytes);
  Put<uint32_t>(&file, static_cast<uint32_t>(crc32(0, header, header_bytes)));
  file.resize((file.size() + 63) / 64 * 64, 0);
  file.insert(file.end(), records, records + record_bytes);
  // The record count is what the header says the record size makes of the bytes given.
  const nlohmann::json parsed = nlohmann::json::parse(header, header + header_bytes, nullptr, false);
  uint64_t count = 0;
  if (parsed.is_object() && parsed.contains("record_bytes") && parsed["record_bytes"].is_number_unsigned() &&
      parsed["record_bytes"].get<uint64_t>() > 0) {
    count = record_bytes / parsed["record_bytes"].get<uint64_t>();
  }
  for (char c : {'N', 'P', 'H', 'E', 'N', 'D', '\0', '\0'}) file.push_back(static_cast<uint8_t>(c));
  Put<uint64_t>(&file, count);
  Put<uint32_t>(&file, static_cast<uint32_t>(crc32(0, records, static_cast<uInt>(record_bytes))));

  const std::filesystem::path path = nphand::fuzz::ScratchPath("content.db");
  nphand::fuzz::WriteBytes(path, file);
  nphand::fuzz::OpenAndReadEverything(path);
  return 0;
}
