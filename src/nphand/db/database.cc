#include "nphand/db/database.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <optional>
#include <set>

#include <sys/mman.h>
#include <unistd.h>
#include <zlib.h>  // crc32_combine

#include "nphand/features/hog.h"
#include "nphand/scene/gesture.h"
#include "nphand/util/check.h"
#include "nphand/util/io.h"

namespace nphand {
namespace {

constexpr char kMagic[8] = {'N', 'P', 'H', 'A', 'N', 'D', 'D', 'B'};
constexpr char kFooterMagic[8] = {'N', 'P', 'H', 'E', 'N', 'D', 0, 0};
constexpr size_t kFooterBytes = 8 + 8 + 4;
constexpr size_t kAlignment = 64;
constexpr uint32_t kMaxHeaderBytes = 16u << 20;

template <typename T>
void Put(std::vector<uint8_t>* out, T value) {
  const auto* bytes = reinterpret_cast<const uint8_t*>(&value);
  out->insert(out->end(), bytes, bytes + sizeof(T));
}

template <typename T>
T Get(const uint8_t* p) {
  T value;
  std::memcpy(&value, p, sizeof(T));
  return value;
}

// Magic, version, header, its CRC and the padding: everything before the records.
std::vector<uint8_t> Prologue(const nlohmann::json& header) {
  const std::string text = header.dump();
  std::vector<uint8_t> out(kMagic, kMagic + 8);
  Put<uint32_t>(&out, kDatabaseVersion);
  Put<uint32_t>(&out, static_cast<uint32_t>(text.size()));
  out.insert(out.end(), text.begin(), text.end());
  Put<uint32_t>(&out, Crc32(0, {reinterpret_cast<const uint8_t*>(text.data()), text.size()}));
  out.resize((out.size() + kAlignment - 1) / kAlignment * kAlignment, 0);
  return out;
}

// Reads typed header fields, naming the file and the field's path when one is missing, of
// the wrong type or out of range.
class HeaderFields {
 public:
  explicit HeaderFields(const std::string& source) : source_(source) {}

  const nlohmann::json& Object(const nlohmann::json& parent, const std::string& key, const std::string& path) const {
    const nlohmann::json& value = At(parent, key, path);
    NPHAND_THROW_CHECK(value.is_object(), source_, ": header field '", path, "' must be an object");
    return value;
  }
  const nlohmann::json& Array(const nlohmann::json& parent, const std::string& key, const std::string& path) const {
    const nlohmann::json& value = At(parent, key, path);
    NPHAND_THROW_CHECK(value.is_array(), source_, ": header field '", path, "' must be an array");
    return value;
  }
  int64_t Integer(const nlohmann::json& parent, const std::string& key, const std::string& path, int64_t min,
                  int64_t max) const {
    return Integer(At(parent, key, path), path, min, max);
  }
  int64_t Integer(const nlohmann::json& value, const std::string& path, int64_t min, int64_t max) const {
    NPHAND_THROW_CHECK(value.is_number_integer() && value.get<int64_t>() >= min && value.get<int64_t>() <= max, source_,
                       ": header field '", path, "' must be an integer in [", min, ", ", max, "], not ",
                       value.dump());
    return value.get<int64_t>();
  }
  double Number(const nlohmann::json& parent, const std::string& key, const std::string& path, double min,
                double max) const {
    return Number(At(parent, key, path), path, min, max);
  }
  double Number(const nlohmann::json& value, const std::string& path, double min, double max) const {
    NPHAND_THROW_CHECK(value.is_number() && value.get<double>() >= min && value.get<double>() <= max, source_,
                       ": header field '", path, "' must be a number in [", min, ", ", max, "], not ", value.dump());
    return value.get<double>();
  }
  bool Boolean(const nlohmann::json& parent, const std::string& key, const std::string& path) const {
    const nlohmann::json& value = At(parent, key, path);
    NPHAND_THROW_CHECK(value.is_boolean(), source_, ": header field '", path, "' must be true or false, not ",
                       value.dump());
    return value.get<bool>();
  }
  std::string String(const nlohmann::json& parent, const std::string& key, const std::string& path) const {
    return String(At(parent, key, path), path);
  }
  std::string String(const nlohmann::json& value, const std::string& path) const {
    NPHAND_THROW_CHECK(value.is_string(), source_, ": header field '", path, "' must be a string, not ", value.dump());
    return value.get<std::string>();
  }
  void Expect(bool condition, const std::string& path, const std::string& what) const {
    NPHAND_THROW_CHECK(condition, source_, ": header field '", path, "' ", what);
  }

 private:
  const nlohmann::json& At(const nlohmann::json& parent, const std::string& key, const std::string& path) const {
    const auto it = parent.find(key);
    NPHAND_THROW_CHECK(it != parent.end(), source_, ": the header lacks the field '", path, "'");
    return *it;
  }
  const std::string& source_;
};

RecordLayout LayoutOf(const nlohmann::json& header, const std::string& source) {
  ValidateHeader(header, source);
  RecordLayout layout;
  layout.hog_dimension = header["hog"]["dimension"].get<int>();
  return layout;
}

// The descriptor config a (validated) header records: its "crop" block and its "hog" block,
// which holds the roll normalisation.
DescriptorConfig DescriptorOf(const nlohmann::json& header, const std::string& source) {
  return DescriptorConfigFromJson({{"crop_size", header["crop"]["size"]},
                                   {"crop_margin", header["crop"]["margin"]},
                                   {"normalize_roll", header["hog"]["normalize_roll"]},
                                   {"hog", header["hog"]}},
                                  source);
}

// Whether every float of `p` is a number in [min, max]. Written without early exits, so
// that it vectorises.
bool AllInRange(const uint8_t* p, size_t count, float min, float max) {
  bool ok = true;
  for (size_t i = 0; i < count; ++i) {
    const float v = Get<float>(p + 4 * i);
    ok &= (v >= min) & (v <= max);  // false for NaN
  }
  return ok;
}

bool AllZero(const uint8_t* p, size_t count) {
  uint8_t any = 0;
  for (size_t i = 0; i < count; ++i) any |= p[i];
  return any == 0;
}

// Parses and checks the prologue at the start of `bytes`; returns the header and where the
// records begin.
std::pair<nlohmann::json, size_t> ReadPrologue(const uint8_t* bytes, size_t size, const std::string& source) {
  NPHAND_THROW_CHECK(size >= 16 && std::memcmp(bytes, kMagic, 8) == 0, source, ": not an nphand database (bad magic)");
  const uint32_t version = Get<uint32_t>(bytes + 8);
  NPHAND_THROW_CHECK(version == kDatabaseVersion, source, ": database format version ", version,
                     " is not supported (this nphand reads version ", kDatabaseVersion, ")");
  const uint32_t header_bytes = Get<uint32_t>(bytes + 12);
  NPHAND_THROW_CHECK(header_bytes <= kMaxHeaderBytes && 16 + size_t{header_bytes} + 4 <= size, source,
                     ": truncated header");
  const uint8_t* text = bytes + 16;
  NPHAND_THROW_CHECK(Get<uint32_t>(text + header_bytes) == Crc32(0, std::span<const uint8_t>(text, header_bytes)), source,
                     ": checksum mismatch in the header");
  nlohmann::json header = nlohmann::json::parse(text, text + header_bytes, nullptr, false);
  NPHAND_THROW_CHECK(!header.is_discarded(), source, ": the header is not valid JSON");
  const size_t data = (16 + size_t{header_bytes} + 4 + kAlignment - 1) / kAlignment * kAlignment;
  NPHAND_THROW_CHECK(data <= size, source, ": truncated after the header");
  for (size_t i = 16 + size_t{header_bytes} + 4; i < data; ++i) {
    NPHAND_THROW_CHECK(bytes[i] == 0, source, ": corrupt padding after the header");
  }
  return {std::move(header), data};
}

}  // namespace

void ValidateHeader(const nlohmann::json& header, const std::string& source) {
  const HeaderFields f(source);
  NPHAND_THROW_CHECK(header.is_object(), source, ": the header is not a JSON object");
  f.Expect(f.String(header, "format", "format") == "nphand database", "format", "must be \"nphand database\"");
  f.Expect(f.String(header, "hand", "hand") == "right", "hand", "must be \"right\" (the database holds right hands)");
  f.Expect(f.String(header, "view_sphere", "view_sphere") == "fibonacci", "view_sphere", "must be \"fibonacci\"");
  f.String(header, "order", "order");
  if (header.contains("view_sphere_coverage")) {  // optional: older files lack it
    const nlohmann::json& coverage = f.Object(header, "view_sphere_coverage", "view_sphere_coverage");
    f.Number(coverage, "max_neighbour_deg", "view_sphere_coverage.max_neighbour_deg", 0.0, 180.0);
    f.Number(coverage, "covering_radius_deg", "view_sphere_coverage.covering_radius_deg", 0.0, 180.0);
  }
  f.String(header, "hand_asset_sha256", "hand_asset_sha256");
  if (header.contains("keypoints")) {  // optional: older files lack it
    f.Expect(f.String(header, "keypoints", "keypoints") == kKeypointRule, "keypoints",
             std::string("must be \"") + kKeypointRule + "\"");
  }

  const nlohmann::json& grasps = f.Array(header, "grasps", "grasps");
  f.Expect(!grasps.empty() && grasps.size() <= kNumGrasps, "grasps", "must list 1 to 33 grasps");
  std::set<int64_t> seen;
  for (size_t i = 0; i < grasps.size(); ++i) {
    seen.insert(f.Integer(grasps[i], "grasps[" + std::to_string(i) + "]", 1, kNumGrasps));
  }
  f.Expect(seen.size() == grasps.size(), "grasps", "lists a grasp twice");
  const nlohmann::json& objects = f.Array(header, "grasp_objects", "grasp_objects");
  f.Expect(objects.size() == grasps.size(), "grasp_objects", "must have one object per grasp");
  for (size_t i = 0; i < objects.size(); ++i) {
    const std::string at = "grasp_objects[" + std::to_string(i) + "]";
    f.Expect(objects[i].is_object(), at, "must be an object");
    f.Expect(f.Integer(objects[i], "grasp", at + ".grasp", 1, kNumGrasps) == grasps[i].get<int64_t>(), at + ".grasp",
             "must follow the order of 'grasps'");
    f.String(objects[i], "name", at + ".name");
    f.String(objects[i], "object", at + ".object");
    const nlohmann::json& size = f.Array(objects[i], "size_m", at + ".size_m");
    for (size_t k = 0; k < size.size(); ++k) f.Number(size[k], at + ".size_m[" + std::to_string(k) + "]", 0.0, 10.0);
  }

  size_t gestures = 0;
  if (header.contains("gestures")) {  // optional: a build without gestures has neither field
    const nlohmann::json& ids = f.Array(header, "gestures", "gestures");
    const nlohmann::json& names = f.Array(header, "gesture_names", "gesture_names");
    f.Expect(!ids.empty() && ids.size() <= kNumGestures, "gestures",
             "must list 1 to " + std::to_string(kNumGestures) + " gestures");
    f.Expect(names.size() == ids.size(), "gesture_names", "must name each gesture");
    std::set<int64_t> listed;
    for (size_t i = 0; i < ids.size(); ++i) {
      const std::string at = "gestures[" + std::to_string(i) + "]";
      const int64_t id = f.Integer(ids[i], at, kFirstGestureId, kNumHandShapes);
      listed.insert(id);
      f.Expect(f.String(names[i], "gesture_names[" + std::to_string(i) + "]") == HandShapeKey(static_cast<int>(id)),
               "gesture_names[" + std::to_string(i) + "]", "must be the name of " + at);
    }
    f.Expect(listed.size() == ids.size(), "gestures", "lists a gesture twice");
    gestures = ids.size();
  }

  const int64_t steps = f.Integer(header, "steps", "steps", 1, 255);
  const int64_t viewpoints = f.Integer(header, "viewpoints", "viewpoints", 2, 65535);
  const uint64_t total = (static_cast<uint64_t>(grasps.size()) * 2 + gestures) * steps * viewpoints;
  f.Expect(f.Integer(header, "total_entries", "total_entries", 0, INT64_MAX) == static_cast<int64_t>(total),
           "total_entries", "must be (grasps x 2 + gestures) x steps x viewpoints = " + std::to_string(total));
  const int64_t entries = f.Integer(header, "entries", "entries", 0, static_cast<int64_t>(total));
  if (header.contains("shard")) {
    const nlohmann::json& shard = f.Object(header, "shard", "shard");
    const int64_t count = f.Integer(shard, "count", "shard.count", 2, 1 << 20);
    f.Integer(shard, "index", "shard.index", 0, count - 1);
    const int64_t begin = f.Integer(shard, "begin", "shard.begin", 0, static_cast<int64_t>(total));
    const int64_t end = f.Integer(shard, "end", "shard.end", begin, static_cast<int64_t>(total));
    f.Expect(end - begin == entries, "shard", "must cover 'entries' records (end - begin)");
  } else {
    f.Expect(entries == static_cast<int64_t>(total), "entries", "must equal total_entries in a file that is no shard");
  }

  const nlohmann::json& render = f.Object(header, "render", "render");
  f.Integer(render, "image_size", "render.image_size", 16, 8192);
  f.Number(render, "fov_deg", "render.fov_deg", 5.0, 120.0);
  f.Number(render, "distance_m", "render.distance_m", 0.1, 10.0);
  const nlohmann::json& crop = f.Object(header, "crop", "crop");
  f.Integer(crop, "size", "crop.size", kCropBitsSide, kCropBitsSide);
  f.Number(crop, "margin", "crop.margin", 0.0, 1.0);

  const nlohmann::json& hog = f.Object(header, "hog", "hog");
  HogOptions options;
  options.cells = static_cast<int>(f.Integer(hog, "cells", "hog.cells", 1, kCropBitsSide));
  options.bins = static_cast<int>(f.Integer(hog, "bins", "hog.bins", 1, 360));
  options.pyramid = f.Boolean(hog, "pyramid", "hog.pyramid");
  options.signed_orientation = f.Boolean(hog, "signed", "hog.signed");
  const std::string normalization = f.String(hog, "normalization", "hog.normalization");
  f.Expect(normalization == ToString(HogNormalization::kGlobalL2) || normalization == ToString(HogNormalization::kCellSum),
           "hog.normalization", "is not a HOG normalisation nphand knows");
  options.normalization = HogNormalizationFromString(normalization);
  f.Boolean(hog, "normalize_roll", "hog.normalize_roll");
  std::string why;
  f.Expect(options.Check(&why), "hog", "describes an impossible HOG (" + why + ")");
  f.Expect(kCropBitsSide % options.cells == 0, "hog.cells", "must divide the crop side");
  f.Expect(f.String(hog, "name", "hog.name") == options.Name(), "hog.name", "must be " + options.Name());
  f.Expect(f.Integer(hog, "dimension", "hog.dimension", 1, 1 << 20) == options.Dimension(), "hog.dimension",
           "must be " + std::to_string(options.Dimension()) + " for " + options.Name());
  RecordLayout layout;
  layout.hog_dimension = options.Dimension();
  f.Expect(f.Integer(header, "record_bytes", "record_bytes", 1, 1 << 30) == static_cast<int64_t>(layout.RecordBytes()),
           "record_bytes", "does not match the features (" + std::to_string(layout.RecordBytes()) + " bytes)");
}

Enumeration::Enumeration(const nlohmann::json& header)
    : grasps(header["grasps"].get<std::vector<int>>()),
      gestures(header.contains("gestures") ? header["gestures"].get<std::vector<int>>() : std::vector<int>{}),
      steps(header["steps"].get<uint64_t>()),
      viewpoints(header["viewpoints"].get<uint64_t>()),
      begin(header.contains("shard") ? header["shard"]["begin"].get<uint64_t>() : 0) {}

size_t Enumeration::ShapePosition(uint64_t entry) const {
  return entry < GraspEntries() ? entry / viewpoints / 2 / steps
                                : grasps.size() + (entry - GraspEntries()) / viewpoints / steps;
}

EntryMeta Enumeration::At(uint64_t entry) const {
  EntryMeta meta;
  meta.viewpoint = static_cast<uint16_t>(entry % viewpoints);
  const size_t shape = ShapePosition(entry);
  if (entry < GraspEntries()) {
    meta.with_object = (entry / viewpoints) % 2 == 1;
    meta.step = static_cast<uint8_t>((entry / viewpoints / 2) % steps);
    meta.grasp = static_cast<uint8_t>(grasps[shape]);
  } else {
    meta.step = static_cast<uint8_t>(((entry - GraspEntries()) / viewpoints) % steps);
    meta.grasp = static_cast<uint8_t>(gestures[shape - grasps.size()]);
  }
  return meta;
}

size_t RecordLayout::RecordBytes() const { return CropOffset() + kCropBytes; }

void EncodeEntry(const Entry& e, const RecordLayout& layout, std::span<uint8_t> record) {
  NPHAND_CHECK(record.size() == layout.RecordBytes());
  NPHAND_CHECK(e.hog.size() == static_cast<size_t>(layout.hog_dimension));
  NPHAND_CHECK(e.crop.type() == CV_8UC1 && e.crop.rows == kCropBitsSide && e.crop.cols == kCropBitsSide);
  std::fill(record.begin(), record.end(), 0);
  uint8_t* r = record.data();
  r[0] = e.meta.grasp;
  r[1] = e.meta.step;
  r[2] = e.meta.with_object ? 1 : 0;
  r[3] = e.meta.has_hand ? 1 : 0;
  std::memcpy(r + 4, &e.meta.viewpoint, 2);
  std::memcpy(r + 8, &e.meta.roll, 4);
  float* pose = reinterpret_cast<float*>(r + layout.PoseOffset());
  for (int i = 0; i < kPoseVectorSize; ++i) pose[i] = static_cast<float>(e.pose[i]);
  float* angles = reinterpret_cast<float*>(r + layout.AnglesOffset());
  for (int i = 0; i < kNumDofs; ++i) angles[i] = static_cast<float>(e.angles[i]);
  float* keypoints = reinterpret_cast<float*>(r + layout.KeypointsOffset());
  for (int k = 0; k < kNumKeypoints; ++k) {
    for (int c = 0; c < 3; ++c) keypoints[3 * k + c] = static_cast<float>(e.keypoints[k][c]);
  }
  std::memcpy(r + layout.HogOffset(), e.hog.data(), 4 * e.hog.size());
  uint8_t* bits = r + layout.CropOffset();
  for (int y = 0; y < kCropBitsSide; ++y) {
    for (int x = 0; x < kCropBitsSide; ++x) {
      if (e.crop.at<uint8_t>(y, x) != 0) bits[(y * kCropBitsSide + x) / 8] |= uint8_t(1u << (x % 8));
    }
  }
}

namespace {

constexpr char kBlocksMagic[8] = {'N', 'P', 'H', 'B', 'L', 'K', 'S', '1'};
constexpr size_t kBlockEntryBytes = 8 + 4;  // u64 records, u32 CRC-32 of their bytes

std::filesystem::path PartialOf(const std::filesystem::path& path) { return path.string() + ".partial"; }
std::filesystem::path BlocksOf(const std::filesystem::path& path) { return path.string() + ".partial.blocks"; }

}  // namespace

DatabaseWriter::DatabaseWriter(const std::filesystem::path& path, const nlohmann::json& header, Mode mode)
    : path_(path), prologue_(Prologue(header)) {
  const RecordLayout layout = LayoutOf(header, path.string());
  record_bytes_ = layout.RecordBytes();
  expected_ = header["entries"].get<uint64_t>();
  file_ = File::OpenLocked(PartialOf(path));
  blocks_ = File::OpenLocked(BlocksOf(path));
  if (mode == Mode::kResume && file_.Size() > 0) {
    Resume();
  } else {
    StartAfresh();
  }
}

void DatabaseWriter::StartAfresh() {
  file_.Truncate(0);
  file_.WriteAt(0, prologue_);
  blocks_.Truncate(0);
  blocks_.WriteAt(0, std::span<const uint8_t>(reinterpret_cast<const uint8_t*>(kBlocksMagic), 8));
  count_ = 0;
  crc_ = 0;
}

void DatabaseWriter::Resume() {
  const std::string partial = file_.path().string();
  std::vector<uint8_t> prologue(prologue_.size());
  if (!file_.ReadAt(0, prologue) || prologue != prologue_) {
    note_ = partial + ": left by a build with other options (another header); starting over";
    StartAfresh();
    return;
  }
  std::vector<uint8_t> magic(8);
  if (!blocks_.ReadAt(0, magic) || std::memcmp(magic.data(), kBlocksMagic, 8) != 0) {
    note_ = blocks_.path().string() + ": missing or foreign, so the records of " + partial +
            " cannot be verified; starting over";
    StartAfresh();
    return;
  }
  // Keep the blocks whose bytes still match their checksums, up to the first that does not.
  const uint64_t size = file_.Size();
  uint64_t kept_blocks = 0;
  std::vector<uint8_t> entry(kBlockEntryBytes), block;
  while (blocks_.ReadAt(8 + kept_blocks * kBlockEntryBytes, entry)) {
    const uint64_t records = Get<uint64_t>(entry.data());
    const uint64_t offset = prologue_.size() + count_ * record_bytes_;
    if (records == 0 || records > expected_ - count_ || records * record_bytes_ > size - offset) break;
    block.resize(records * record_bytes_);
    if (!file_.ReadAt(offset, block) || Crc32(0, block) != Get<uint32_t>(entry.data() + 8)) {
      note_ = partial + ": records " + std::to_string(count_) + " to " + std::to_string(count_ + records - 1) +
              " fail their checksum; building again from record " + std::to_string(count_);
      break;
    }
    crc_ = Crc32(crc_, block);
    count_ += records;
    ++kept_blocks;
  }
  const uint64_t kept_bytes = prologue_.size() + count_ * record_bytes_;
  if (note_.empty() && size - kept_bytes >= record_bytes_ && count_ == expected_) {
    note_ = partial + ": holds more records than this build makes; the extra ones are dropped";
  }
  file_.Truncate(kept_bytes);
  blocks_.Truncate(8 + kept_blocks * kBlockEntryBytes);
}

void DatabaseWriter::Append(std::span<const uint8_t> records) {
  NPHAND_CHECK(file_.fd() >= 0 && records.size() % record_bytes_ == 0);
  const uint64_t count = records.size() / record_bytes_;
  NPHAND_THROW_CHECK(count_ + count <= expected_, file_.path().string(), ": ", count_ + count,
                     " records would exceed the header's ", expected_);
  file_.WriteAt(prologue_.size() + count_ * record_bytes_, records);
  const uint32_t block_crc = Crc32(0, records);
  std::vector<uint8_t> entry;
  Put<uint64_t>(&entry, count);
  Put<uint32_t>(&entry, block_crc);
  blocks_.Append(entry);
  crc_ = static_cast<uint32_t>(crc32_combine(crc_, block_crc, static_cast<z_off_t>(records.size())));
  count_ += count;
}

void DatabaseWriter::Finish() {
  NPHAND_CHECK(file_.fd() >= 0);
  NPHAND_THROW_CHECK(count_ == expected_, file_.path().string(), ": holds ", count_, " records, the header says ",
                     expected_);
  std::vector<uint8_t> footer(kFooterMagic, kFooterMagic + 8);
  Put<uint64_t>(&footer, count_);
  Put<uint32_t>(&footer, crc_);
  file_.WriteAt(prologue_.size() + count_ * record_bytes_, footer);
  file_.Sync();
  std::error_code ec;
  std::filesystem::rename(file_.path(), path_, ec);
  NPHAND_THROW_CHECK(!ec, path_.string(), ": cannot rename the finished file into place (", ec.message(), ")");
  std::filesystem::remove(blocks_.path(), ec);
  file_.Close();
  blocks_.Close();
}

void DatabaseWriter::Discard() {
  std::error_code ec;
  std::filesystem::remove(file_.path(), ec);
  std::filesystem::remove(blocks_.path(), ec);
  file_.Close();
  blocks_.Close();
}

Database Database::Open(const std::filesystem::path& path, bool verify_records) {
  const std::string source = path.string();
  const File file = File::OpenRegular(path);
  const size_t size = file.Size();
  NPHAND_THROW_CHECK(size > 0, source, ": empty file");
  void* mapped = ::mmap(nullptr, size, PROT_READ, MAP_PRIVATE, file.fd(), 0);
  NPHAND_THROW_CHECK(mapped != MAP_FAILED, source, ": cannot map the file (", std::strerror(errno), ")");
  Database db;
  db.path_ = path;
  db.mapped_ = static_cast<const uint8_t*>(mapped);
  db.mapped_bytes_ = size;

  auto [header, data] = ReadPrologue(db.mapped_, size, source);
  db.header_ = std::move(header);
  db.layout_ = LayoutOf(db.header_, source);
  db.descriptor_ = DescriptorOf(db.header_, source);
  const size_t record_bytes = db.layout_.RecordBytes();
  NPHAND_THROW_CHECK(size >= data + kFooterBytes, source, ": truncated (no footer)");
  const uint8_t* footer = db.mapped_ + size - kFooterBytes;
  NPHAND_THROW_CHECK(std::memcmp(footer, kFooterMagic, 8) == 0, source,
                     ": truncated or unfinished (no footer; an interrupted build resumes from its .partial file)");
  const uint64_t count = Get<uint64_t>(footer + 8);
  NPHAND_THROW_CHECK(count == (size - kFooterBytes - data) / record_bytes &&
                         data + count * record_bytes + kFooterBytes == size,
                     source, ": the record count ", count, " does not match the file size ", size);
  NPHAND_THROW_CHECK(db.header_["entries"].get<uint64_t>() == count, source, ": the header says ",
                     db.header_["entries"].get<uint64_t>(), " entries, the file holds ", count);
  db.records_ = db.mapped_ + data;
  db.count_ = count;
  char checksum[17];
  std::snprintf(checksum, sizeof(checksum), "%08x%08x", Get<uint32_t>(db.mapped_ + 16 + Get<uint32_t>(db.mapped_ + 12)),
                Get<uint32_t>(footer + 16));
  db.checksum_ = checksum;
  if (verify_records) {
    // A block at a time, its content checked while it is in the cache. A file that fails its
    // checksum is reported as such: its odd content is damage, not a craft.
    constexpr size_t kBlock = 64;
    uint32_t crc = 0;
    const Enumeration enumeration(db.header_);
    std::optional<Error> impossible;
    size_t previous = 0;  // the block before, released again as ScanRecords does
    for (size_t begin = 0; begin < count; begin += kBlock) {
      const size_t end = std::min<size_t>(count, begin + kBlock);
      crc = Crc32(crc, {db.records_ + begin * record_bytes, (end - begin) * record_bytes});
      if (!impossible) {
        try {
          db.VerifyRecords(enumeration, begin, end);
        } catch (const Error& e) {
          impossible = e;
        }
      }
      db.ReleasePages(previous, end);
      previous = begin;
    }
    NPHAND_THROW_CHECK(crc == Get<uint32_t>(footer + 16), source, ": checksum mismatch in the records");
    if (impossible) throw *impossible;
  }
  return db;
}

void Database::ReleasePages(size_t begin, size_t end) const {
  NPHAND_CHECK(begin <= end && end <= count_);
  // Whole pages: from the one holding the first byte to the end of the one holding the last.
  const uintptr_t page = static_cast<uintptr_t>(::sysconf(_SC_PAGESIZE));
  const uintptr_t first = reinterpret_cast<uintptr_t>(records_ + begin * layout_.RecordBytes()) / page * page;
  const uintptr_t last = reinterpret_cast<uintptr_t>(records_ + end * layout_.RecordBytes());
  if (last > first) ::madvise(reinterpret_cast<void*>(first), last - first, MADV_DONTNEED);
}

void Database::VerifyRecords(const Enumeration& enumeration, size_t begin, size_t end) const {
  const std::string source = path_.string();
  const RecordLayout& l = layout_;
  for (size_t i = begin; i < end; ++i) {
    const uint8_t* r = records_ + i * l.RecordBytes();
    const EntryMeta meta = Meta(i), expected = enumeration.At(enumeration.begin + i);
    NPHAND_THROW_CHECK(meta.grasp == expected.grasp && meta.step == expected.step &&
                           meta.with_object == expected.with_object && meta.viewpoint == expected.viewpoint,
                       source, ": record ", i, " says grasp ", int{meta.grasp}, ", step ", int{meta.step}, ", object ",
                       meta.with_object, ", viewpoint ", meta.viewpoint, " where the header's enumeration has grasp ",
                       int{expected.grasp}, ", step ", int{expected.step}, ", object ", expected.with_object,
                       ", viewpoint ", expected.viewpoint);
    NPHAND_THROW_CHECK(r[2] <= 1 && r[3] <= 1 && r[6] == 0 && r[7] == 0, source, ": record ", i,
                       " has impossible flags");
    NPHAND_THROW_CHECK(std::abs(meta.roll) <= 3.1416f && (meta.has_hand || meta.roll == 0.0f), source, ": record ", i,
                       " has an impossible roll ", meta.roll);
    NPHAND_THROW_CHECK(AllInRange(r + l.PoseOffset(), kPoseVectorSize, -1.0001f, 1.0001f) &&
                           AllInRange(r + l.AnglesOffset(), kNumDofs, -3.1416f, 3.1416f) &&
                           AllInRange(r + l.KeypointsOffset(), 3 * kNumKeypoints, -10.0f, 10.0f),
                       source, ": record ", i, " has a pose, angle or keypoint that is not a number or out of range");
    NPHAND_THROW_CHECK(AllInRange(r + l.HogOffset(), l.hog_dimension, 0.0f, meta.has_hand ? 1.0001f : 0.0f), source,
                       ": record ", i, " has a HOG value that is not a number or out of range");
    const uint8_t* bits = r + l.CropOffset();
    const bool empty = AllZero(bits, RecordLayout::kCropBytes);
    NPHAND_THROW_CHECK(empty != meta.has_hand, source, ": record ", i,
                       meta.has_hand ? " has a hand but an empty crop" : " has no hand but a crop");
  }
}

Database::~Database() {
  if (mapped_ != nullptr) ::munmap(const_cast<uint8_t*>(mapped_), mapped_bytes_);
}

Database::Database(Database&& other) noexcept { *this = std::move(other); }

Database& Database::operator=(Database&& other) noexcept {
  if (this != &other) {
    if (mapped_ != nullptr) ::munmap(const_cast<uint8_t*>(mapped_), mapped_bytes_);
    path_ = std::move(other.path_);
    header_ = std::move(other.header_);
    layout_ = other.layout_;
    descriptor_ = other.descriptor_;
    checksum_ = std::move(other.checksum_);
    mapped_ = std::exchange(other.mapped_, nullptr);
    mapped_bytes_ = std::exchange(other.mapped_bytes_, 0);
    records_ = std::exchange(other.records_, nullptr);
    count_ = std::exchange(other.count_, 0);
  }
  return *this;
}

const uint8_t* Database::Record(size_t i) const {
  NPHAND_CHECK(i < count_, "record ", i, " of ", count_);
  return records_ + i * layout_.RecordBytes();
}

EntryMeta Database::Meta(size_t i) const {
  const uint8_t* r = Record(i);
  return {r[0], r[1], r[2] != 0, r[3] != 0, Get<uint16_t>(r + 4), Get<float>(r + 8)};
}

PoseVector Database::Pose(size_t i) const {
  const uint8_t* r = Record(i) + layout_.PoseOffset();
  PoseVector pose;
  for (int k = 0; k < kPoseVectorSize; ++k) pose[k] = Get<float>(r + 4 * k);
  return pose;
}

JointAngles Database::Angles(size_t i) const {
  const uint8_t* r = Record(i) + layout_.AnglesOffset();
  JointAngles angles;
  for (int k = 0; k < kNumDofs; ++k) angles[k] = Get<float>(r + 4 * k);
  return angles;
}

Keypoints3d Database::Keypoints(size_t i) const {
  const uint8_t* r = Record(i) + layout_.KeypointsOffset();
  Keypoints3d keypoints;
  for (int k = 0; k < kNumKeypoints; ++k) {
    for (int c = 0; c < 3; ++c) keypoints[k][c] = Get<float>(r + 4 * (3 * k + c));
  }
  return keypoints;
}

std::span<const float> Database::Hog(size_t i) const {
  // Records are 4-byte aligned: the record size and the offsets are multiples of 4.
  return {reinterpret_cast<const float*>(Record(i) + layout_.HogOffset()), static_cast<size_t>(layout_.hog_dimension)};
}

cv::Mat Database::Crop(size_t i) const {
  const uint8_t* bits = Record(i) + layout_.CropOffset();
  cv::Mat crop(kCropBitsSide, kCropBitsSide, CV_8UC1);
  for (int y = 0; y < kCropBitsSide; ++y) {
    for (int x = 0; x < kCropBitsSide; ++x) {
      crop.at<uint8_t>(y, x) = (bits[(y * kCropBitsSide + x) / 8] >> (x % 8)) & 1 ? 255 : 0;
    }
  }
  return crop;
}

std::span<const uint8_t> Database::Records(size_t begin, size_t end) const {
  NPHAND_CHECK(begin <= end && end <= count_);
  return {records_ + begin * layout_.RecordBytes(), (end - begin) * layout_.RecordBytes()};
}

}  // namespace nphand
