#include "nphand/db/database.h"

#include <gtest/gtest.h>

#include "nphand/util/check.h"
#include "nphand/util/io.h"
#include "testing/testing.h"
#include "testing/tiny_db.h"

namespace nphand {
namespace {

// A database of `n` synthetic records with recognisable values.
std::filesystem::path WriteSynthetic(const std::filesystem::path& path, int n) {
  RecordLayout layout;
  layout.hog_dimension = 16;
  const nlohmann::json header = {{"entries", n}, {"record_bytes", layout.RecordBytes()}, {"hog", {{"dimension", 16}}}};
  DatabaseWriter writer(path, header);
  std::vector<uint8_t> record(layout.RecordBytes());
  for (int i = 0; i < n; ++i) {
    Entry e;
    e.meta = {static_cast<uint8_t>(i % 33 + 1), static_cast<uint8_t>(i % 5), i % 2 == 1, true, static_cast<uint16_t>(i),
              0.25f * i};
    for (int k = 0; k < kPoseVectorSize; ++k) e.pose[k] = 0.01 * (i + k);
    for (int k = 0; k < kNumDofs; ++k) e.angles[k] = -0.02 * (i + k);
    for (int k = 0; k < kNumKeypoints; ++k) e.keypoints[k] = Eigen::Vector3d(i, k, 0.5);
    e.hog.assign(16, static_cast<float>(i));
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
  const auto path = WriteSynthetic(testing::ScratchDir() / "s.db", 7);
  EXPECT_FALSE(std::filesystem::exists(path.string() + ".partial"));
  const Database db = Database::Open(path);
  ASSERT_EQ(db.size(), 7u);
  for (int i = 0; i < 7; ++i) {
    const EntryMeta meta = db.Meta(i);
    EXPECT_EQ(meta.grasp, i % 33 + 1);
    EXPECT_EQ(meta.step, i % 5);
    EXPECT_EQ(meta.with_object, i % 2 == 1);
    EXPECT_EQ(meta.viewpoint, i);
    EXPECT_EQ(meta.roll, 0.25f * i);
    EXPECT_FLOAT_EQ(static_cast<float>(db.Pose(i)[3]), 0.01f * (i + 3));
    EXPECT_FLOAT_EQ(static_cast<float>(db.Angles(i)[20]), -0.02f * (i + 20));
    EXPECT_EQ(db.Keypoints(i)[4], Eigen::Vector3d(i, 4, 0.5));
    EXPECT_EQ(db.Hog(i)[15], static_cast<float>(i));
    const cv::Mat crop = db.Crop(i);
    EXPECT_EQ(cv::countNonZero(crop), 1);
    EXPECT_EQ(crop.at<uint8_t>(i % kCropBitsSide, (3 * i) % kCropBitsSide), 255);
  }
}

TEST(DatabaseTest, EveryFlippedByteIsRefused) {
  const auto dir = testing::ScratchDir();
  const std::vector<uint8_t> good = ReadFileBytes(WriteSynthetic(dir / "good.db", 2));
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
  const std::vector<uint8_t> good = ReadFileBytes(WriteSynthetic(dir / "good.db", 3));
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
  // A writer that never finished leaves only its .partial file.
  {
    RecordLayout layout;
    layout.hog_dimension = 16;
    DatabaseWriter writer(dir / "unfinished.db", {{"entries", 1}, {"record_bytes", layout.RecordBytes()},
                                                  {"hog", {{"dimension", 16}}}});
  }
  EXPECT_FALSE(std::filesystem::exists(dir / "unfinished.db"));
  EXPECT_TRUE(std::filesystem::exists(dir / "unfinished.db.partial"));
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
}

}  // namespace
}  // namespace nphand
