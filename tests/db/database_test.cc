#include "nphand/db/database.h"

#include <sys/stat.h>

#include <cstring>
#include <fstream>
#include <functional>
#include <limits>

#include <gtest/gtest.h>

#include "nphand/db/builder.h"
#include "nphand/scene/gesture.h"
#include "nphand/util/check.h"
#include "nphand/util/io.h"
#include "testing/db_files.h"
#include "testing/testing.h"
#include "testing/tiny_db.h"

namespace nphand {
namespace {

// The header of a one-grasp database of `directions` viewpoints (10 x directions entries),
// or of the first of `shards` shards of it.
nlohmann::json SyntheticHeader(int directions, int shards) {
  DatabaseBuildOptions options;
  options.grasps = {1};
  options.gestures = {};
  options.directions = directions;
  options.descriptor.hog.cells = 2;
  options.descriptor.hog.bins = 4;  // 16 values
  options.shard_count = shards;
  return options.Header();
}

// A database of synthetic records with recognisable values, each at its enumeration place.
std::filesystem::path WriteSynthetic(const std::filesystem::path& path, int directions, int shards = 1) {
  const nlohmann::json header = SyntheticHeader(directions, shards);
  RecordLayout layout;
  layout.hog_dimension = 16;
  DatabaseWriter writer(path, header, DatabaseWriter::Mode::kFresh);
  std::vector<uint8_t> record(layout.RecordBytes());
  const int n = header["entries"].get<int>();
  for (int i = 0; i < n; ++i) {
    Entry e;
    e.meta = {1, static_cast<uint8_t>(i / directions / 2), (i / directions) % 2 == 1, true,
              static_cast<uint16_t>(i % directions), 0.05f * i};
    for (int k = 0; k < kPoseVectorSize; ++k) e.pose[k] = 0.01 * (i + k);
    for (int k = 0; k < kNumDofs; ++k) e.angles[k] = -0.02 * (i + k);
    for (int k = 0; k < kNumKeypoints; ++k) e.keypoints[k] = Eigen::Vector3d(0.01 * i, 0.01 * k, 0.5);
    e.hog.assign(16, 0.01f * i);
    e.crop = cv::Mat::zeros(kCropBitsSide, kCropBitsSide, CV_8UC1);
    e.crop.at<uint8_t>(i % kCropBitsSide, (3 * i) % kCropBitsSide) = 255;
    EncodeEntry(e, layout, record);
    writer.Append(record);
  }
  writer.Finish();
  return path;
}

void ExpectRefused(const std::filesystem::path& path, const std::string& needle) {
  try {
    Database::Open(path);
    ADD_FAILURE() << "opened " << path << " (expected: " << needle << ")";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(path.filename().string()), std::string::npos) << "names the file";
  }
}

TEST(DatabaseTest, RecordsRoundTrip) {
  const auto path = WriteSynthetic(testing::ScratchDir() / "s.db", 3);
  EXPECT_FALSE(std::filesystem::exists(path.string() + ".partial"));
  EXPECT_FALSE(std::filesystem::exists(path.string() + ".partial.blocks"));
  const Database db = Database::Open(path);
  ASSERT_EQ(db.size(), 30u);
  for (int i = 0; i < 30; ++i) {
    const EntryMeta meta = db.Meta(i);
    EXPECT_EQ(meta.grasp, 1);
    EXPECT_EQ(meta.step, i / 6);
    EXPECT_EQ(meta.with_object, (i / 3) % 2 == 1);
    EXPECT_EQ(meta.viewpoint, i % 3);
    EXPECT_EQ(meta.roll, 0.05f * i);
    EXPECT_FLOAT_EQ(static_cast<float>(db.Pose(i)[3]), 0.01f * (i + 3));
    EXPECT_FLOAT_EQ(static_cast<float>(db.Angles(i)[20]), -0.02f * (i + 20));
    EXPECT_NEAR((db.Keypoints(i)[4] - Eigen::Vector3d(0.01 * i, 0.04, 0.5)).norm(), 0.0, 1e-6);
    EXPECT_EQ(db.Hog(i)[15], 0.01f * i);
    const cv::Mat crop = db.Crop(i);
    EXPECT_EQ(cv::countNonZero(crop), 1);
    EXPECT_EQ(crop.at<uint8_t>(i % kCropBitsSide, (3 * i) % kCropBitsSide), 255);
  }
}

TEST(DatabaseTest, EveryFlippedByteIsRefused) {
  const auto dir = testing::ScratchDir();
  const std::vector<uint8_t> good = ReadFileBytes(WriteSynthetic(dir / "good.db", 2, 10));
  const auto path = dir / "bad.db";
  for (size_t i = 0; i < good.size(); ++i) {
    std::vector<uint8_t> bad = good;
    bad[i] ^= 0x41;
    WriteFileAtomic(path, bad);
    bool refused = false;
    try {
      Database::Open(path);
    } catch (const Error&) {
      refused = true;
    }
    ASSERT_TRUE(refused) << "byte " << i << " of " << good.size() << " flipped and accepted";
  }
}

TEST(DatabaseTest, TruncatedForeignAndUnfinishedFilesAreRefusedByName) {
  const auto dir = testing::ScratchDir();
  const std::vector<uint8_t> good = ReadFileBytes(WriteSynthetic(dir / "good.db", 2, 10));
  for (size_t length : {size_t{0}, size_t{5}, size_t{20}, size_t{100}, good.size() / 2, good.size() - 1}) {
    WriteFileAtomic(dir / "cut.db", std::span<const uint8_t>(good.data(), length));
    ExpectRefused(dir / "cut.db", length == 0 ? "empty" : "");
  }
  WriteFileAtomic(dir / "png.db", std::string("\x89PNG\r\n\x1a\n and so on, not a database"));
  ExpectRefused(dir / "png.db", "not an nphand database");
  std::vector<uint8_t> future = good;
  future[8] = 9;
  WriteFileAtomic(dir / "future.db", future);
  ExpectRefused(dir / "future.db", "version 9");
  ExpectRefused(dir / "missing.db", "cannot open");
  // A writer that never finished leaves only its .partial file (and its block checksums).
  { DatabaseWriter writer(dir / "unfinished.db", SyntheticHeader(2, 10), DatabaseWriter::Mode::kFresh); }
  EXPECT_FALSE(std::filesystem::exists(dir / "unfinished.db"));
  EXPECT_TRUE(std::filesystem::exists(dir / "unfinished.db.partial"));
}

TEST(DatabaseTest, WhatIsNotARegularFileIsRefusedByNameWithoutWaiting) {
  const auto dir = testing::ScratchDir();
  ASSERT_EQ(::mkfifo((dir / "fifo.db").c_str(), 0600), 0);
  ExpectRefused(dir / "fifo.db", "FIFO");  // opening a FIFO for reading used to wait for a writer
  std::filesystem::create_directories(dir / "folder.db");
  ExpectRefused(dir / "folder.db", "folder");
}

// Every header field the format defines is checked at open, with a message naming it.
TEST(DatabaseTest, HeaderSchemaIsValidatedAtOpen) {
  const auto dir = testing::ScratchDir();
  const std::vector<uint8_t> good = ReadFileBytes(WriteSynthetic(dir / "good.db", 2, 10));
  const nlohmann::json header = testing::HeaderOf(good);
  const auto refuse = [&](const std::function<void(nlohmann::json&)>& edit, const std::string& needle) {
    nlohmann::json bad = header;
    edit(bad);
    WriteFileAtomic(dir / "bad.db", testing::WithHeader(good, bad));
    ExpectRefused(dir / "bad.db", needle);
  };
  WriteFileAtomic(dir / "same.db", testing::WithHeader(good, header));
  EXPECT_NO_THROW(Database::Open(dir / "same.db")) << "the tampering itself keeps a good file good";
  refuse([](nlohmann::json& h) { h.erase("render"); }, "lacks the field 'render'");
  refuse([](nlohmann::json& h) { h.erase("crop"); }, "lacks the field 'crop'");
  refuse([](nlohmann::json& h) { h["hog"].erase("name"); }, "'hog.name'");
  refuse([](nlohmann::json& h) { h["render"]["fov_deg"] = "wide"; }, "'render.fov_deg' must be a number");
  refuse([](nlohmann::json& h) { h["render"]["distance_m"] = -1; }, "'render.distance_m'");
  refuse([](nlohmann::json& h) { h["hog"]["name"] = 7; }, "'hog.name' must be a string");
  refuse([](nlohmann::json& h) { h["hog"]["dimension"] = 512; }, "'hog.dimension'");
  refuse([](nlohmann::json& h) { h["hog"]["normalization"] = "l7"; }, "'hog.normalization'");
  refuse([](nlohmann::json& h) { h["grasps"] = {0}; }, "'grasps[0]'");
  refuse([](nlohmann::json& h) { h["grasps"] = nlohmann::json::array(); }, "'grasps'");
  refuse([](nlohmann::json& h) { h["viewpoints"] = 1; }, "'viewpoints'");
  refuse([](nlohmann::json& h) { h["total_entries"] = 7; }, "'total_entries'");
  refuse([](nlohmann::json& h) { h["entries"] = 3; }, "'shard'");
  refuse([](nlohmann::json& h) { h["shard"]["index"] = 10; }, "'shard.index'");
  refuse([](nlohmann::json& h) { h["hand"] = "left"; }, "'hand'");
  refuse([](nlohmann::json& h) { h["keypoints"] = "fingertip"; }, "'keypoints' must be \"fingertip ends, thumb base\"");
  refuse([](nlohmann::json& h) { h["gestures"] = {kFirstGestureId}; }, "lacks the field 'gesture_names'");
  refuse([](nlohmann::json& h) { h["gestures"] = {kNumGrasps}, h["gesture_names"] = {"fist"}; }, "'gestures[0]'");
  refuse([](nlohmann::json& h) { h["gestures"] = {kFirstGestureId}, h["gesture_names"] = {"peace"}; },
         "'gesture_names[0]' must be the name of gestures[0]");
  refuse([](nlohmann::json& h) { h["gestures"] = {kFirstGestureId}, h["gesture_names"] = {"fist"}; },
         "'total_entries' must be (grasps x 2 + gestures)");
  refuse([](nlohmann::json& h) { h = nlohmann::json::array({1, 2}); }, "not a JSON object");
}

// Content read from a file is user input: impossible records are refused by number.
TEST(DatabaseTest, RecordsWithImpossibleContentAreRefusedDespiteAValidChecksum) {
  const auto dir = testing::ScratchDir();
  const std::vector<uint8_t> good = ReadFileBytes(WriteSynthetic(dir / "good.db", 2, 10));
  const size_t records = testing::RecordsOffset(good);
  RecordLayout layout;
  layout.hog_dimension = 16;
  const size_t second = records + layout.RecordBytes();
  const auto refuse = [&](const std::function<void(std::vector<uint8_t>&)>& edit, const std::string& needle) {
    std::vector<uint8_t> bad = good;
    edit(bad);
    testing::SealRecords(&bad);
    WriteFileAtomic(dir / "bad.db", bad);
    ExpectRefused(dir / "bad.db", needle);
  };
  refuse([&](std::vector<uint8_t>& f) { f[records] = 255; }, "record 0 says grasp 255");
  refuse([&](std::vector<uint8_t>& f) { f[records + 1] = 200; }, "record 0 says grasp 1, step 200");
  refuse([&](std::vector<uint8_t>& f) { f[records + 2] = 7; }, "record 0");
  refuse([&](std::vector<uint8_t>& f) { std::copy_n(f.begin() + records, layout.RecordBytes(), f.begin() + second); },
         "record 1 says grasp 1, step 0, object 0, viewpoint 0 where the header's enumeration has grasp 1, step 0, "
         "object 0, viewpoint 1");
  refuse([&](std::vector<uint8_t>& f) { std::fill_n(f.begin() + records + layout.CropOffset(), 512, 0); },
         "record 0 has a hand but an empty crop");
  refuse([&](std::vector<uint8_t>& f) { f[second + 3] = 0; }, "record 1 has an impossible roll");
  refuse([&](std::vector<uint8_t>& f) {
    const float nan = std::numeric_limits<float>::quiet_NaN();
    std::memcpy(f.data() + second + layout.HogOffset(), &nan, 4);
  }, "record 1 has a HOG value");
  refuse([&](std::vector<uint8_t>& f) {
    const float big = 1e9f;
    std::memcpy(f.data() + records + layout.KeypointsOffset(), &big, 4);
  }, "record 0 has a pose, angle or keypoint");
}

TEST(DatabaseTest, SecondWriterOfOnePathIsRefusedByName) {
  const auto dir = testing::ScratchDir();
  DatabaseWriter first(dir / "x.db", SyntheticHeader(2, 10), DatabaseWriter::Mode::kFresh);
  try {
    DatabaseWriter second(dir / "x.db", SyntheticHeader(2, 10), DatabaseWriter::Mode::kResume);
    ADD_FAILURE() << "two writers of one file";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("x.db.partial: another nphand process is writing it"), std::string::npos)
        << e.what();
  }
  first.Discard();
  EXPECT_FALSE(std::filesystem::exists(dir / "x.db.partial"));
  EXPECT_NO_THROW(DatabaseWriter(dir / "x.db", SyntheticHeader(2, 10), DatabaseWriter::Mode::kFresh));
}

TEST(DatabaseTest, WriterRefusesAWrongRecordCount) {
  const auto dir = testing::ScratchDir();
  RecordLayout layout;
  layout.hog_dimension = 16;
  DatabaseWriter writer(dir / "x.db", SyntheticHeader(2, 10), DatabaseWriter::Mode::kFresh);  // 2 records
  const std::vector<uint8_t> three(3 * layout.RecordBytes(), 0);
  EXPECT_THROW(writer.Append(three), Error);
  EXPECT_THROW(writer.Finish(), Error);
}

// Kilobytes of the mapping holding `address` that are resident in this process
// (/proc/self/smaps), or -1 when no mapping holds it.
long ResidentKb(const void* address) {
  std::ifstream smaps("/proc/self/smaps");
  const auto at = reinterpret_cast<uintptr_t>(address);
  std::string line;
  bool inside = false;
  while (std::getline(smaps, line)) {
    uintptr_t begin = 0, end = 0;
    if (std::sscanf(line.c_str(), "%lx-%lx ", &begin, &end) == 2 && line.find(' ') > line.find('-')) {
      inside = at >= begin && at < end;
    } else if (inside && line.rfind("Rss:", 0) == 0) {
      return std::stol(line.substr(4));
    }
  }
  return -1;
}

TEST(DatabaseTest, PassesOverTheRecordsLeaveNoneResident) {
  const Database db = Database::Open(testing::BuildTinyDatabase(testing::ScratchDir() / "tiny.db"));
  const std::span<const uint8_t> records = db.Records(0, db.size());
  const long file_kb = static_cast<long>(records.size() / 1024);
  EXPECT_LT(ResidentKb(records.data()), file_kb / 4) << "Open's verification released what it read";
  const std::vector<uint8_t> copy(records.begin(), records.end());
  db.ReleasePages(0, db.size());
  std::vector<size_t> visited;
  double sum = 0.0;
  ScanRecords(db, [&](size_t i) {
    visited.push_back(i);
    sum += db.Hog(i)[0];
  });
  ASSERT_EQ(visited.size(), db.size());
  for (size_t i = 0; i < visited.size(); ++i) EXPECT_EQ(visited[i], i);
  EXPECT_LT(ResidentKb(records.data()), file_kb / 4) << "a scan releases what it read";
  for (size_t i = 0; i < db.size(); ++i) sum += db.Hog(i)[0];
  EXPECT_GT(ResidentKb(records.data()), file_kb / 2) << "plain reads stay resident (the check can see them)";
  db.ReleasePages(0, db.size());
  EXPECT_LT(ResidentKb(records.data()), file_kb / 4);
  EXPECT_TRUE(std::equal(copy.begin(), copy.end(), db.Records(0, db.size()).begin())) << "released pages read back";
  EXPECT_GE(sum, 0.0);
}

TEST(DatabaseTest, TinyBuiltDatabaseOpensAndHoldsHandCrops) {
  const Database db = Database::Open(testing::BuildTinyDatabase(testing::ScratchDir() / "tiny.db"));
  ASSERT_EQ(db.size(), 160u);
  int with_hand = 0;
  for (size_t i = 0; i < db.size(); ++i) {
    if (!db.Meta(i).has_hand) continue;
    ++with_hand;
    EXPECT_GT(cv::countNonZero(db.Crop(i)), 100) << i;
    double norm = 0;
    for (float v : db.Hog(i)) norm += v * v;
    EXPECT_NEAR(norm, 1.0, 1e-4) << i;
  }
  EXPECT_GT(with_hand, 150);
  EXPECT_EQ(db.descriptor(), testing::TinyDatabaseOptions().descriptor) << "the file says how it was described";
}

}  // namespace
}  // namespace nphand
