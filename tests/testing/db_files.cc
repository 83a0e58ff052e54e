#include "testing/db_files.h"

#include <cstring>

#include <zlib.h>

namespace nphand::testing {
namespace {

constexpr size_t kFooterBytes = 20;

uint32_t HeaderBytes(const std::vector<uint8_t>& file) {
  uint32_t length = 0;
  std::memcpy(&length, file.data() + 12, 4);
  return length;
}

}  // namespace

size_t RecordsOffset(const std::vector<uint8_t>& file) { return (16 + size_t{HeaderBytes(file)} + 4 + 63) / 64 * 64; }

nlohmann::json HeaderOf(const std::vector<uint8_t>& file) {
  return nlohmann::json::parse(file.begin() + 16, file.begin() + 16 + HeaderBytes(file));
}

std::vector<uint8_t> WithHeader(const std::vector<uint8_t>& file, const nlohmann::json& header) {
  const std::string text = header.dump();
  const uint32_t length = static_cast<uint32_t>(text.size());
  const uint32_t crc = static_cast<uint32_t>(crc32(0, reinterpret_cast<const Bytef*>(text.data()), length));
  std::vector<uint8_t> out(16 + text.size() + 4);
  std::memcpy(out.data(), file.data(), 12);
  std::memcpy(out.data() + 12, &length, 4);
  std::memcpy(out.data() + 16, text.data(), text.size());
  std::memcpy(out.data() + 16 + text.size(), &crc, 4);
  out.resize((out.size() + 63) / 64 * 64, 0);
  out.insert(out.end(), file.begin() + RecordsOffset(file), file.end());
  return out;
}

void SealRecords(std::vector<uint8_t>* file) {
  const size_t begin = RecordsOffset(*file), end = file->size() - kFooterBytes;
  const uint32_t crc = static_cast<uint32_t>(crc32(0, file->data() + begin, static_cast<uInt>(end - begin)));
  std::memcpy(file->data() + file->size() - 4, &crc, 4);
}

}  // namespace nphand::testing
