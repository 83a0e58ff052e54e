// The index file, version 1 (little-endian): "NPHANDIX" | u32 version | u32 meta length M |
// M bytes of JSON meta | u64 body length B | B bytes of the backend's body | u32 CRC-32 of
// everything before it.
#pragma once

#include <cstdint>
#include <filesystem>
#include <vector>

#include <nlohmann/json.hpp>

#include "nphand/features/descriptor.h"

namespace nphand {

// An index file taken apart: its meta (checked: backend, parameters, entries, descriptor
// config, the database's checksum and size) and its backend's body.
struct IndexFile {
  nlohmann::json meta;
  DescriptorConfig descriptor;
  std::vector<uint8_t> body;
};

// Throws nphand::Error naming the file and the problem (not an index, another version,
// truncated, trailing bytes, checksum, meta).
IndexFile ReadIndexFile(const std::filesystem::path& path);
// The bytes of an index file.
std::vector<uint8_t> EncodeIndexFile(const nlohmann::json& meta, const std::vector<uint8_t>& body);
// Writes the file atomically.
void WriteIndexFile(const std::filesystem::path& path, const nlohmann::json& meta, const std::vector<uint8_t>& body);

}  // namespace nphand
