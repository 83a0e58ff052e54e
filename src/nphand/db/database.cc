#include "nphand/db/database.h"

#include <cerrno>
#include <cstring>

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

#include "nphand/util/check.h"

namespace nphand {
namespace {

constexpr char kMagic[8] = {'N', 'P', 'H', 'A', 'N', 'D', 'D', 'B'};
constexpr char kFooterMagic[8] = {'N', 'P', 'H', 'E', 'N', 'D', 0, 0};
constexpr size_t kFooterBytes = 8 + 8 + 4;
constexpr size_t kAlignment = 64;
constexpr uint32_t kMaxHeaderBytes = 16u << 20;

uint32_t Crc(uint32_t crc, const uint8_t* data, size_t size) {
  while (size > 0) {
    const uInt chunk = static_cast<uInt>(std::min<size_t>(size, 1u << 30));
    crc = static_cast<uint32_t>(crc32(crc, data, chunk));
    data += chunk;
    size -= chunk;
  }
  return crc;
}

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
  Put<uint32_t>(&out, Crc(0, reinterpret_cast<const uint8_t*>(text.data()), text.size()));
  out.resize((out.size() + kAlignment - 1) / kAlignment * kAlignment, 0);
  return out;
}

RecordLayout LayoutOf(const nlohmann::json& header, const std::string& source) {
  RecordLayout layout;
  try {
    layout.hog_dimension = header.at("hog").at("dimension").get<int>();
    NPHAND_THROW_CHECK(header.at("record_bytes").get<size_t>() == layout.RecordBytes(), source,
                       ": the header's record size does not match its features");
  } catch (const nlohmann::json::exception& e) {
    NPHAND_THROW(source, ": the header lacks a field (", e.what(), ")");
  }
  NPHAND_THROW_CHECK(layout.hog_dimension > 0 && layout.hog_dimension < 100000, source, ": bad HOG dimension");
  return layout;
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
  NPHAND_THROW_CHECK(Get<uint32_t>(text + header_bytes) == Crc(0, text, header_bytes), source,
                     ": checksum mismatch in the header");
  nlohmann::json header = nlohmann::json::parse(text, text + header_bytes, nullptr, false);
  NPHAND_THROW_CHECK(!header.is_discarded() && header.is_object(), source, ": the header is not valid JSON");
  const size_t data = (16 + size_t{header_bytes} + 4 + kAlignment - 1) / kAlignment * kAlignment;
  NPHAND_THROW_CHECK(data <= size, source, ": truncated after the header");
  for (size_t i = 16 + size_t{header_bytes} + 4; i < data; ++i) {
    NPHAND_THROW_CHECK(bytes[i] == 0, source, ": corrupt padding after the header");
  }
  return {std::move(header), data};
}

}  // namespace

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

DatabaseWriter::DatabaseWriter(const std::filesystem::path& path, const nlohmann::json& header)
    : path_(path), partial_(path.string() + ".partial") {
  record_bytes_ = LayoutOf(header, path.string()).RecordBytes();
  file_ = std::fopen(partial_.c_str(), "wb");
  NPHAND_THROW_CHECK(file_ != nullptr, partial_.string(), ": cannot open for writing (", std::strerror(errno), ")");
  const std::vector<uint8_t> prologue = Prologue(header);
  NPHAND_THROW_CHECK(std::fwrite(prologue.data(), 1, prologue.size(), file_) == prologue.size(), partial_.string(),
                     ": write failed");
}

std::unique_ptr<DatabaseWriter> DatabaseWriter::OpenForResume(const std::filesystem::path& path,
                                                              const nlohmann::json& header) {
  const std::filesystem::path partial = path.string() + ".partial";
  if (!std::filesystem::exists(partial)) return nullptr;
  const std::vector<uint8_t> expected = Prologue(header);
  const uint64_t size = std::filesystem::file_size(partial);
  std::unique_ptr<DatabaseWriter> writer(new DatabaseWriter());
  writer->path_ = path;
  writer->partial_ = partial;
  writer->record_bytes_ = LayoutOf(header, path.string()).RecordBytes();
  writer->file_ = std::fopen(partial.c_str(), "r+b");
  NPHAND_THROW_CHECK(writer->file_ != nullptr, partial.string(), ": cannot open to resume (", std::strerror(errno), ")");
  // Only a partial file of the same build (the same prologue) is continued.
  std::vector<uint8_t> prologue(expected.size());
  if (size < expected.size() || std::fread(prologue.data(), 1, prologue.size(), writer->file_) != prologue.size() ||
      prologue != expected) {
    return nullptr;
  }
  writer->count_ = (size - expected.size()) / writer->record_bytes_;
  std::vector<uint8_t> record(writer->record_bytes_);
  for (uint64_t i = 0; i < writer->count_; ++i) {
    NPHAND_THROW_CHECK(std::fread(record.data(), 1, record.size(), writer->file_) == record.size(), partial.string(),
                       ": read failed while resuming");
    writer->crc_ = Crc(writer->crc_, record.data(), record.size());
  }
  const uint64_t keep = expected.size() + writer->count_ * writer->record_bytes_;
  NPHAND_THROW_CHECK(::ftruncate(fileno(writer->file_), static_cast<off_t>(keep)) == 0, partial.string(),
                     ": cannot drop a torn record");
  std::fseek(writer->file_, static_cast<long>(keep), SEEK_SET);
  return writer;
}

DatabaseWriter::~DatabaseWriter() {
  if (file_ != nullptr) std::fclose(file_);
}

void DatabaseWriter::Append(std::span<const uint8_t> records) {
  NPHAND_CHECK(file_ != nullptr && records.size() % record_bytes_ == 0);
  NPHAND_THROW_CHECK(std::fwrite(records.data(), 1, records.size(), file_) == records.size() && std::fflush(file_) == 0,
                     partial_.string(), ": write failed (", std::strerror(errno), ")");
  crc_ = Crc(crc_, records.data(), records.size());
  count_ += records.size() / record_bytes_;
}

void DatabaseWriter::Finish() {
  NPHAND_CHECK(file_ != nullptr);
  std::vector<uint8_t> footer(kFooterMagic, kFooterMagic + 8);
  Put<uint64_t>(&footer, count_);
  Put<uint32_t>(&footer, crc_);
  const bool ok = std::fwrite(footer.data(), 1, footer.size(), file_) == footer.size() && std::fflush(file_) == 0 &&
                  ::fsync(fileno(file_)) == 0;
  std::fclose(file_);
  file_ = nullptr;
  NPHAND_THROW_CHECK(ok, partial_.string(), ": writing the footer failed (", std::strerror(errno), ")");
  std::error_code ec;
  std::filesystem::rename(partial_, path_, ec);
  NPHAND_THROW_CHECK(!ec, path_.string(), ": cannot rename the finished file into place (", ec.message(), ")");
}

Database Database::Open(const std::filesystem::path& path, bool verify_records) {
  const std::string source = path.string();
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  NPHAND_THROW_CHECK(fd >= 0, source, ": cannot open (", std::strerror(errno), ")");
  struct stat info {};
  const bool statted = ::fstat(fd, &info) == 0;
  const size_t size = statted ? static_cast<size_t>(info.st_size) : 0;
  void* mapped = size > 0 ? ::mmap(nullptr, size, PROT_READ, MAP_PRIVATE, fd, 0) : MAP_FAILED;
  ::close(fd);
  NPHAND_THROW_CHECK(mapped != MAP_FAILED, source, size == 0 ? ": empty file" : ": cannot map the file");
  Database db;
  db.path_ = path;
  db.mapped_ = static_cast<const uint8_t*>(mapped);
  db.mapped_bytes_ = size;

  auto [header, data] = ReadPrologue(db.mapped_, size, source);
  db.header_ = std::move(header);
  db.layout_ = LayoutOf(db.header_, source);
  const size_t record_bytes = db.layout_.RecordBytes();
  NPHAND_THROW_CHECK(size >= data + kFooterBytes, source, ": truncated (no footer)");
  const uint8_t* footer = db.mapped_ + size - kFooterBytes;
  NPHAND_THROW_CHECK(std::memcmp(footer, kFooterMagic, 8) == 0, source,
                     ": truncated or unfinished (no footer; an interrupted build resumes from its .partial file)");
  const uint64_t count = Get<uint64_t>(footer + 8);
  NPHAND_THROW_CHECK(count == (size - kFooterBytes - data) / record_bytes &&
                         data + count * record_bytes + kFooterBytes == size,
                     source, ": the record count ", count, " does not match the file size ", size);
  NPHAND_THROW_CHECK(db.header_.value("entries", uint64_t{0}) == count, source, ": the header says ",
                     db.header_.value("entries", uint64_t{0}), " entries, the file holds ", count);
  db.records_ = db.mapped_ + data;
  db.count_ = count;
  if (verify_records) {
    NPHAND_THROW_CHECK(Crc(0, db.records_, count * record_bytes) == Get<uint32_t>(footer + 16), source,
                       ": checksum mismatch in the records");
  }
  return db;
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
