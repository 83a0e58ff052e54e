// The database file: fixed-size records of (pose, image feature) pairs with a JSON header.
//
// Layout (little-endian), version 1:
//   "NPHANDDB" | u32 version | u32 header length H | H bytes of JSON header | u32 CRC-32 of
//   the header | zero padding to a multiple of 64 | N records of `record_bytes` | "NPHEND\0\0"
//   | u64 N | u32 CRC-32 of the records
// The header says what the records hold (see RecordLayout), how they were built and which
// part of the full enumeration they cover (shards). Records are memory-mapped on open.
// Every way a file can be wrong (foreign, another version, truncated, a flipped byte) is
// refused with an nphand::Error naming the file and the problem.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <span>
#include <string>

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "nphand/model/hand_model.h"

namespace nphand {

inline constexpr uint32_t kDatabaseVersion = 1;
inline constexpr int kCropBitsSide = 64;  // the stored hand crop: 64 x 64 bits

// One record, packed: metadata, then the pose, angles, keypoints, HOG and the crop's bits.
// The crop is the hand as rendered (never turned); the HOG is of the crop turned by
// EntryMeta::roll when the database normalises roll.
struct RecordLayout {
  int hog_dimension = 512;
  size_t RecordBytes() const;
  // grasp, step, with_object, has_hand (u8 each), u16 viewpoint, u16 0, f32 roll
  static constexpr size_t kMetaBytes = 12;
  size_t PoseOffset() const { return kMetaBytes; }
  size_t AnglesOffset() const { return PoseOffset() + 4 * kPoseVectorSize; }
  size_t KeypointsOffset() const { return AnglesOffset() + 4 * kNumDofs; }
  size_t HogOffset() const { return KeypointsOffset() + 4 * 3 * kNumKeypoints; }
  size_t CropOffset() const { return HogOffset() + 4 * static_cast<size_t>(hog_dimension); }
  static constexpr size_t kCropBytes = kCropBitsSide * kCropBitsSide / 8;
};

// What one record says of its origin.
struct EntryMeta {
  uint8_t grasp = 0;         // taxonomy number 1..33
  uint8_t step = 0;          // 0 (pre-shape) .. 4 (grasp)
  bool with_object = false;  // rendered with the grasp's object
  bool has_hand = false;     // false when the object hides the whole hand: no features
  uint16_t viewpoint = 0;    // index into the view sphere
  float roll = 0.0f;         // radians the hand was turned before its HOG (roll normalisation)
};

// A record's content, for writing.
struct Entry {
  EntryMeta meta;
  PoseVector pose = PoseVector::Zero();
  JointAngles angles{};
  Keypoints3d keypoints{};   // camera orientation, wrist at the origin, metres
  std::vector<float> hog;    // RecordLayout::hog_dimension values
  cv::Mat crop;              // CV_8UC1, kCropBitsSide square, non-zero = hand
};

// Serialises entries into the record format.
void EncodeEntry(const Entry& entry, const RecordLayout& layout, std::span<uint8_t> record);

// Writes a database file atomically: records go to "<path>.partial"; Finish() adds the
// footer, flushes and renames. An unfinished writer leaves the partial file, from which
// OpenForResume continues.
class DatabaseWriter {
 public:
  // Starts a new partial file.
  DatabaseWriter(const std::filesystem::path& path, const nlohmann::json& header);
  // Continues "<path>.partial" if it holds the same header; its complete records are kept
  // (a torn last record is dropped). Returns nullptr when there is nothing to resume.
  static std::unique_ptr<DatabaseWriter> OpenForResume(const std::filesystem::path& path,
                                                       const nlohmann::json& header);
  ~DatabaseWriter();
  DatabaseWriter(const DatabaseWriter&) = delete;
  DatabaseWriter& operator=(const DatabaseWriter&) = delete;

  // Appends whole records (a multiple of the record size) and flushes them.
  void Append(std::span<const uint8_t> records);
  uint64_t records_written() const { return count_; }
  // Writes the footer and renames the partial file to the final path.
  void Finish();

 private:
  DatabaseWriter() = default;
  std::filesystem::path path_, partial_;
  size_t record_bytes_ = 0;
  uint64_t count_ = 0;
  uint32_t crc_ = 0;
  std::FILE* file_ = nullptr;
};

class Database {
 public:
  // Maps `path` and checks it: magic, version, header checksum, sizes and (unless
  // `verify_records` is false) the records' checksum. Throws nphand::Error otherwise.
  static Database Open(const std::filesystem::path& path, bool verify_records = true);
  ~Database();
  Database(Database&& other) noexcept;
  Database& operator=(Database&& other) noexcept;
  Database(const Database&) = delete;
  Database& operator=(const Database&) = delete;

  size_t size() const { return count_; }
  const nlohmann::json& header() const { return header_; }
  const RecordLayout& layout() const { return layout_; }
  uint64_t file_bytes() const { return mapped_bytes_; }

  EntryMeta Meta(size_t i) const;
  PoseVector Pose(size_t i) const;
  JointAngles Angles(size_t i) const;
  Keypoints3d Keypoints(size_t i) const;
  std::span<const float> Hog(size_t i) const;
  // The stored hand crop as CV_8UC1 (255 = hand), kCropBitsSide square.
  cv::Mat Crop(size_t i) const;
  // The raw bytes of records [begin, end).
  std::span<const uint8_t> Records(size_t begin, size_t end) const;

 private:
  Database() = default;
  const uint8_t* Record(size_t i) const;

  std::filesystem::path path_;
  nlohmann::json header_;
  RecordLayout layout_;
  const uint8_t* mapped_ = nullptr;
  size_t mapped_bytes_ = 0;
  const uint8_t* records_ = nullptr;
  size_t count_ = 0;
};

}  // namespace nphand
