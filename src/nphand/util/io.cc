#include "nphand/util/io.h"

#include <openssl/evp.h>
#include <zlib.h>

#include <algorithm>

#include "nphand/util/check.h"
#include "nphand/util/file.h"

namespace nphand {

std::vector<uint8_t> ReadFileBytes(const std::filesystem::path& path) {
  const File file = File::OpenRegular(path);
  std::vector<uint8_t> bytes(file.Size());
  NPHAND_THROW_CHECK(file.ReadAt(0, bytes), path.string(), ": the file shrank while being read");
  return bytes;
}

void WriteFileAtomic(const std::filesystem::path& path, std::span<const uint8_t> bytes) {
  // The temporary file is locked: a second writer of the same path is refused by name
  // instead of writing into the first one's bytes.
  const std::filesystem::path tmp = path.string() + ".tmp";
  File file = File::OpenLocked(tmp);
  try {
    file.Truncate(0);
    file.WriteAt(0, bytes);
    file.Sync();
    std::error_code ec;
    std::filesystem::rename(tmp, path, ec);
    NPHAND_THROW_CHECK(!ec, path.string(), ": cannot rename the temporary file into place (", ec.message(), ")");
  } catch (const Error&) {
    std::error_code ec;
    std::filesystem::remove(tmp, ec);
    throw;
  }
}

void WriteFileAtomic(const std::filesystem::path& path, const std::string& text) {
  WriteFileAtomic(path, std::span<const uint8_t>(reinterpret_cast<const uint8_t*>(text.data()), text.size()));
}

uint32_t Crc32(uint32_t crc, std::span<const uint8_t> bytes) {
  const uint8_t* data = bytes.data();
  size_t size = bytes.size();
  while (size > 0) {
    const uInt chunk = static_cast<uInt>(std::min<size_t>(size, 1u << 30));
    crc = static_cast<uint32_t>(crc32(crc, data, chunk));
    data += chunk;
    size -= chunk;
  }
  return crc;
}

std::string Sha256Hex(std::span<const uint8_t> bytes) {
  unsigned char digest[EVP_MAX_MD_SIZE];
  unsigned int length = 0;
  NPHAND_CHECK(EVP_Digest(bytes.data(), bytes.size(), digest, &length, EVP_sha256(), nullptr) == 1);
  static const char kHex[] = "0123456789abcdef";
  std::string hex;
  hex.reserve(2 * length);
  for (unsigned int i = 0; i < length; ++i) {
    hex.push_back(kHex[digest[i] >> 4]);
    hex.push_back(kHex[digest[i] & 15]);
  }
  return hex;
}

}  // namespace nphand
