#include "nphand/index/index_file.h"

#include <cstring>

#include "nphand/index/knn_index.h"
#include "nphand/util/check.h"
#include "nphand/util/io.h"

namespace nphand {
namespace {

constexpr char kMagic[8] = {'N', 'P', 'H', 'A', 'N', 'D', 'I', 'X'};

template <typename T>
T Get(const uint8_t* p) {
  T value;
  std::memcpy(&value, p, sizeof(T));
  return value;
}

}  // namespace

IndexFile ReadIndexFile(const std::filesystem::path& path) {
  const std::string source = path.string();
  const std::vector<uint8_t> bytes = ReadFileBytes(path);
  const size_t size = bytes.size();
  NPHAND_THROW_CHECK(size >= 12 && std::memcmp(bytes.data(), kMagic, 8) == 0, source,
                     ": not an nphand index (bad magic)");
  const uint32_t version = Get<uint32_t>(bytes.data() + 8);
  NPHAND_THROW_CHECK(version == kIndexVersion, source, ": index format version ", version,
                     " is not supported (this nphand reads version ", kIndexVersion, "; rebuild with nphand index build)");
  NPHAND_THROW_CHECK(size >= 16, source, ": truncated");
  const uint64_t meta_bytes = Get<uint32_t>(bytes.data() + 12);
  NPHAND_THROW_CHECK(16 + meta_bytes + 8 <= size, source, ": truncated");
  const uint64_t body_bytes = Get<uint64_t>(bytes.data() + 16 + meta_bytes);
  const uint64_t body = 16 + meta_bytes + 8;
  NPHAND_THROW_CHECK(body_bytes <= size && body + body_bytes + 4 <= size, source, ": truncated");
  NPHAND_THROW_CHECK(body + body_bytes + 4 == size, source, ": ", size - body - body_bytes - 4,
                     " bytes after the end of the index");
  NPHAND_THROW_CHECK(Crc32(0, std::span<const uint8_t>(bytes.data(), size - 4)) == Get<uint32_t>(bytes.data() + size - 4), source,
                     ": checksum mismatch (the file is corrupt)");

  IndexFile file;
  file.meta = nlohmann::json::parse(bytes.begin() + 16, bytes.begin() + 16 + meta_bytes, nullptr, false);
  const nlohmann::json& m = file.meta;
  const bool valid = m.is_object() && m.contains("backend") && m["backend"].is_string() && m.contains("parameters") &&
                     m["parameters"].is_object() && m.contains("entries") && m["entries"].is_number_unsigned() &&
                     m.contains("descriptor") && m.contains("database") && m["database"].is_object() &&
                     m["database"].contains("checksum") && m["database"]["checksum"].is_string() &&
                     m["database"].contains("entries") && m["database"]["entries"].is_number_unsigned();
  NPHAND_THROW_CHECK(valid, source, ": the index's meta lacks a field or has one of the wrong type");
  file.descriptor = DescriptorConfigFromJson(m["descriptor"], source);
  file.body.assign(bytes.begin() + body, bytes.begin() + body + body_bytes);
  return file;
}

void WriteIndexFile(const std::filesystem::path& path, const nlohmann::json& meta, const std::vector<uint8_t>& body) {
  WriteFileAtomic(path, EncodeIndexFile(meta, body));
}

std::vector<uint8_t> EncodeIndexFile(const nlohmann::json& meta, const std::vector<uint8_t>& body) {
  const std::string text = meta.dump();
  std::vector<uint8_t> bytes(8 + 4 + 4 + text.size() + 8 + body.size() + 4);
  size_t at = 0;
  const auto put = [&](const void* data, size_t size) {
    if (size > 0) std::memcpy(bytes.data() + at, data, size);
    at += size;
  };
  const uint32_t version = kIndexVersion, meta_bytes = static_cast<uint32_t>(text.size());
  const uint64_t body_bytes = body.size();
  put(kMagic, 8);
  put(&version, 4);
  put(&meta_bytes, 4);
  put(text.data(), text.size());
  put(&body_bytes, 8);
  put(body.data(), body.size());
  const uint32_t crc = Crc32(0, std::span<const uint8_t>(bytes.data(), at));
  put(&crc, 4);
  return bytes;
}

}  // namespace nphand
