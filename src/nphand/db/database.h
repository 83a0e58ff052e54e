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

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "nphand/features/descriptor.h"
#include "nphand/model/hand_model.h"
#include "nphand/util/file.h"

namespace nphand {

// 2: a roll-normalised mask is turned about its own box centre, bilinearly (1 turned it
// about the image centre by nearest neighbour, so its descriptor hung on where the hand sat).
inline constexpr uint32_t kDatabaseVersion = 2;
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
  uint8_t grasp = 0;         // hand shape: a taxonomy number 1..33, or a gesture's (scene/gesture.h)
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

// The header's "keypoints": the records' fingertip keypoints lie at the fingers' ends and the
// thumb's CMC at the thumb's base (HandModel::bind_keypoints). Files without the field hold
// the asset's joints there: files from before 2026-12-06 its tip joints, 9.6-12.6 mm short of
// the fingers' ends, and files from 2026-12-06 (their header's "keypoint_tips") its thumb
// pivot, 8 mm out along the metacarpal.
inline constexpr const char* kKeypointRule = "fingertip ends, thumb base";

// Checks a header against the format's schema; throws nphand::Error naming `source` and
// the field ("x.db: header field 'render.fov_deg' must be a number in [5, 120]").
void ValidateHeader(const nlohmann::json& header, const std::string& source);

// The fixed order of the entries of a build (the header's "order"): entry
// ((grasp position * steps + step) * 2 + with_object) * viewpoints + viewpoint, then, where
// the build holds gestures, grasp entries + (gesture position * steps + step) * viewpoints +
// viewpoint (a gesture has no object); record i of a shard is entry begin + i. An entry is
// a pure function of its number.
struct Enumeration {
  std::vector<int> grasps;    // taxonomy numbers, in the build's order
  std::vector<int> gestures;  // gestures' shape numbers, in the build's order (none in older files)
  uint64_t steps = 0, viewpoints = 0;
  uint64_t begin = 0;         // the file's first entry (0 unless it is a shard)

  // From a valid header (see ValidateHeader).
  explicit Enumeration(const nlohmann::json& header);
  // What entry `entry` is: hand shape number, step, object flag and viewpoint.
  EntryMeta At(uint64_t entry) const;
  // The position of its hand shape in `grasps` followed by `gestures`.
  size_t ShapePosition(uint64_t entry) const;
  uint64_t GraspEntries() const { return grasps.size() * steps * 2 * viewpoints; }
};

// Serialises entries into the record format.
void EncodeEntry(const Entry& entry, const RecordLayout& layout, std::span<uint8_t> record);

// Writes a database file atomically: records go to "<path>.partial", locked against other
// writers for the writer's life; Finish() adds the footer, flushes and renames. Each
// appended block of records has its CRC-32 in "<path>.partial.blocks", so that a resumed
// build keeps only records that are still what was written.
class DatabaseWriter {
 public:
  enum class Mode {
    kFresh,   // start the partial file afresh
    kResume,  // continue a partial file of the same header: its verified blocks are kept
  };
  // Locks "<path>.partial" (throws naming it when another writer holds it) and opens it.
  // The header must be a valid database header (see Database::Open).
  DatabaseWriter(const std::filesystem::path& path, const nlohmann::json& header, Mode mode);
  DatabaseWriter(const DatabaseWriter&) = delete;
  DatabaseWriter& operator=(const DatabaseWriter&) = delete;

  // Appends whole records (a multiple of the record size) as one block.
  void Append(std::span<const uint8_t> records);
  uint64_t records_written() const { return count_; }
  // Why a partial file that was there was not continued, or not all of it (another build's
  // header, a block that fails its checksum, more records than the header says); empty
  // when there was none or all of it was kept.
  const std::string& resume_note() const { return note_; }
  // Writes the footer, flushes and renames the partial file to the final path. Throws if
  // the records written are not the header's count.
  void Finish();
  // Removes the partial file and its block checksums: for a failure a rerun cannot mend.
  void Discard();

 private:
  void StartAfresh();
  void Resume();

  std::filesystem::path path_;
  std::vector<uint8_t> prologue_;
  size_t record_bytes_ = 0;
  uint64_t expected_ = 0;  // records the header says the file holds
  uint64_t count_ = 0;
  uint32_t crc_ = 0;
  std::string note_;
  File file_, blocks_;
};

class Database {
 public:
  // Maps `path` and checks it: a regular file, magic, version, header checksum and schema
  // (every field the format defines, with its type, range and agreement with the others),
  // sizes and, unless `verify_records` is false, the records' checksum and content (each
  // record is the entry of the enumeration at its place, its numbers finite and in range, a
  // hand crop where it has a hand). Throws nphand::Error naming the file and the problem.
  static Database Open(const std::filesystem::path& path, bool verify_records = true);
  ~Database();
  Database(Database&& other) noexcept;
  Database& operator=(Database&& other) noexcept;
  Database(const Database&) = delete;
  Database& operator=(const Database&) = delete;

  size_t size() const { return count_; }
  const nlohmann::json& header() const { return header_; }
  const RecordLayout& layout() const { return layout_; }
  // How the stored HOG was computed: a query must be described the same way.
  const DescriptorConfig& descriptor() const { return descriptor_; }
  uint64_t file_bytes() const { return mapped_bytes_; }
  // The header's and the records' CRC-32 as 16 hex digits: what an index records of the
  // database it was built from.
  const std::string& checksum() const { return checksum_; }

  EntryMeta Meta(size_t i) const;
  PoseVector Pose(size_t i) const;
  JointAngles Angles(size_t i) const;
  Keypoints3d Keypoints(size_t i) const;
  std::span<const float> Hog(size_t i) const;
  // The stored hand crop as CV_8UC1 (255 = hand), kCropBitsSide square.
  cv::Mat Crop(size_t i) const;
  // The raw bytes of records [begin, end).
  std::span<const uint8_t> Records(size_t begin, size_t end) const;
  // Hands the mapped pages of records [begin, end) back to the kernel: they stay in the
  // page cache and are read again when used, but no longer count in this process's resident
  // memory. For passes over every record (Open's verification, an index load, a table of
  // what an estimator needs), a stretch at a time, so that a 650 MB file read once never
  // stays resident.
  void ReleasePages(size_t begin, size_t end) const;

 private:
  Database() = default;
  const uint8_t* Record(size_t i) const;
  // Throws naming the first record of [begin, end) whose content the header rules out.
  void VerifyRecords(const Enumeration& enumeration, size_t begin, size_t end) const;

  std::filesystem::path path_;
  nlohmann::json header_;
  RecordLayout layout_;
  DescriptorConfig descriptor_;
  std::string checksum_;
  const uint8_t* mapped_ = nullptr;
  size_t mapped_bytes_ = 0;
  const uint8_t* records_ = nullptr;
  size_t count_ = 0;
};

// Calls visit(i) for every record i of `db` in order, handing each stretch of records'
// pages back to the kernel once visited (see Database::ReleasePages). The stretch before
// is released again: the kernel maps a fault's neighbouring cached pages too (fault-around),
// some of them already released.
template <typename Visit>
void ScanRecords(const Database& db, Visit&& visit) {
  constexpr size_t kStretch = 1024;
  size_t previous = 0;
  for (size_t begin = 0; begin < db.size(); begin += kStretch) {
    const size_t end = std::min(db.size(), begin + kStretch);
    for (size_t i = begin; i < end; ++i) visit(i);
    db.ReleasePages(previous, end);
    previous = begin;
  }
}

}  // namespace nphand
