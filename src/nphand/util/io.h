// File input and output: whole-file reads, atomic writes, content hashes.
#pragma once

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

namespace nphand {

// Reads a whole regular file. Throws nphand::Error naming the path when it cannot (also
// for a folder or a FIFO: see File::OpenRegular).
std::vector<uint8_t> ReadFileBytes(const std::filesystem::path& path);

// Writes `bytes` to `path` atomically: a temporary file beside it, flushed, then renamed
// over `path`. A crash leaves either the old file or the new one, never half of one.
void WriteFileAtomic(const std::filesystem::path& path, std::span<const uint8_t> bytes);
void WriteFileAtomic(const std::filesystem::path& path, const std::string& text);

// CRC-32 (zlib's) of `bytes`, continuing `crc` (0 to start); any size.
uint32_t Crc32(uint32_t crc, std::span<const uint8_t> bytes);

// Lower-case hex SHA-256 of `bytes`.
std::string Sha256Hex(std::span<const uint8_t> bytes);

}  // namespace nphand
