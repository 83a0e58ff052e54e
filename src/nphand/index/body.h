// The body of an index file: a flat little-endian stream of numbers and length-prefixed
// arrays. The reader checks every length against what is left and what the caller allows,
// so a crafted body gives an nphand::Error naming the file, never an oversized allocation
// or a read past the end. Backends decode a body into their own structures and validate
// them; no third-party reader ever sees file bytes.
#pragma once

#include <cstdint>
#include <cstring>
#include <memory>
#include <ostream>
#include <span>
#include <string>
#include <type_traits>
#include <vector>

#include "nphand/util/check.h"

namespace nphand {

class BodyWriter {
 public:
  template <typename T>
  void Put(T value) {
    static_assert(std::is_arithmetic_v<T>);
    const size_t at = bytes_.size();
    bytes_.resize(at + sizeof(T));
    std::memcpy(bytes_.data() + at, &value, sizeof(T));
  }
  // A u64 count, then the values.
  template <typename T>
  void PutArray(std::span<const T> values) {
    static_assert(std::is_arithmetic_v<T>);
    Put<uint64_t>(values.size());
    const size_t at = bytes_.size();
    bytes_.resize(at + values.size_bytes());
    if (!values.empty()) std::memcpy(bytes_.data() + at, values.data(), values.size_bytes());
  }
  std::vector<uint8_t> Take() { return std::move(bytes_); }

 private:
  std::vector<uint8_t> bytes_;
};

class BodyReader {
 public:
  // `source` names the file in errors.
  BodyReader(std::span<const uint8_t> bytes, std::string source) : bytes_(bytes), source_(std::move(source)) {}

  template <typename T>
  T Get() {
    static_assert(std::is_arithmetic_v<T>);
    NPHAND_THROW_CHECK(bytes_.size() - at_ >= sizeof(T), source_, ": the index body is truncated");
    T value;
    std::memcpy(&value, bytes_.data() + at_, sizeof(T));
    at_ += sizeof(T);
    return value;
  }
  // An array of exactly `count` values (its stored count must say so).
  template <typename T>
  std::vector<T> GetArray(uint64_t count, const char* what) {
    std::vector<T> values = GetArrayAtMost<T>(count, what);
    NPHAND_THROW_CHECK(values.size() == count, source_, ": the index body holds ", values.size(), " ", what, ", ",
                       count, " were expected");
    return values;
  }
  // An array of at most `max_count` values.
  template <typename T>
  std::vector<T> GetArrayAtMost(uint64_t max_count, const char* what) {
    static_assert(std::is_arithmetic_v<T>);
    const uint64_t count = Get<uint64_t>();
    NPHAND_THROW_CHECK(count <= max_count, source_, ": the index body holds ", count, " ", what, ", at most ",
                       max_count, " were expected");
    NPHAND_THROW_CHECK((bytes_.size() - at_) / sizeof(T) >= count, source_, ": the index body is truncated");
    std::vector<T> values(count);
    if (count > 0) std::memcpy(values.data(), bytes_.data() + at_, count * sizeof(T));
    at_ += count * sizeof(T);
    return values;
  }
  // Throws unless every byte was read.
  void Finish() const {
    NPHAND_THROW_CHECK(at_ == bytes_.size(), source_, ": ", bytes_.size() - at_, " bytes after the index body");
  }
  const std::string& source() const { return source_; }

 private:
  std::span<const uint8_t> bytes_;
  size_t at_ = 0;
  std::string source_;
};

// An adapter `Index` (constructed from a set and options, with Build(progress) and
// Load(BodyReader&)) built, or loaded from a body.
template <typename Index, typename Set, typename Options>
std::unique_ptr<Index> BuildAdapter(Set set, const Options& options, std::ostream* progress) {
  auto index = std::make_unique<Index>(std::move(set), options);
  index->Build(progress);
  return index;
}
template <typename Index, typename Set, typename Options>
std::unique_ptr<Index> LoadAdapter(Set set, const Options& options, std::span<const uint8_t> body,
                                   const std::string& source) {
  auto index = std::make_unique<Index>(std::move(set), options);
  BodyReader reader(body, source);
  index->Load(reader);
  return index;
}

}  // namespace nphand
