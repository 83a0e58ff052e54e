#include "nphand/db/builder.h"

#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include "nphand/scene/gesture.h"
#include "nphand/util/check.h"
#include "nphand/util/io.h"
#include "testing/db_files.h"
#include "testing/testing.h"
#include "testing/tiny_db.h"

namespace nphand {
namespace {

using testing::RightHand;
using testing::TinyDatabaseOptions;

TEST(BuilderTest, SameOptionsSameBytesWhateverTheThreads) {
  const auto dir = testing::ScratchDir();
  DatabaseBuildOptions options = TinyDatabaseOptions();
  options.threads = 1;
  BuildDatabase(RightHand(), options, dir / "one.db", nullptr);
  options.threads = 2;
  const BuildSummary summary = BuildDatabase(RightHand(), options, dir / "two.db", nullptr);
  EXPECT_EQ(summary.entries, 160u);
  EXPECT_EQ(ReadFileBytes(dir / "one.db"), ReadFileBytes(dir / "two.db"));
}

TEST(BuilderTest, EntriesFollowTheEnumerationAndMatchTheirGrasp) {
  const Database db = Database::Open(testing::BuildTinyDatabase(testing::ScratchDir() / "tiny.db"));
  const DatabaseBuildOptions options = TinyDatabaseOptions();
  const Grasp sphere = MakeGrasp(RightHand(), GraspTaxonomy()[12]);
  for (size_t i = 0; i < db.size(); ++i) {
    const EntryMeta meta = db.Meta(i);
    const size_t view = i % 8, with = (i / 8) % 2, step = (i / 16) % 5, grasp = i / 80;
    ASSERT_EQ(meta.viewpoint, view);
    ASSERT_EQ(meta.with_object, with == 1);
    ASSERT_EQ(meta.step, step);
    ASSERT_EQ(meta.grasp, options.grasps[grasp]);
    // The stored pose is the grasp's step seen from the viewpoint; keypoints follow it.
    const HandPose pose = FromPoseVector(db.Pose(i), Handedness::kRight);
    if (meta.grasp == 13) {
      for (int k = 0; k < kNumDofs; ++k) EXPECT_NEAR(pose.angles[k], sphere.steps[step][k], 1e-5);
    }
    const Keypoints3d expected = RightHand().KeypointsOf(pose);
    EXPECT_LT((db.Keypoints(i)[20] - expected[20]).norm(), 1e-5);
  }
}

// Gestures follow the grasps: each its steps from every viewpoint, without an object; the
// header names them, and a build without gestures says nothing of them (its bytes are those
// of the files from before gestures).
TEST(BuilderTest, GesturesFollowTheGraspsWithoutAnObject) {
  DatabaseBuildOptions options = TinyDatabaseOptions();
  options.gestures = {GestureByName("peace").id, GestureByName("fist").id};
  const auto dir = testing::ScratchDir();
  EXPECT_EQ(BuildDatabase(RightHand(), options, dir / "gestures.db", nullptr).entries, 160u + 2 * 5 * 8);
  const Database db = Database::Open(dir / "gestures.db");
  EXPECT_EQ(db.header()["gestures"], nlohmann::json::array({GestureByName("peace").id, GestureByName("fist").id}));
  EXPECT_EQ(db.header()["gesture_names"], nlohmann::json::array({"peace", "fist"}));
  // A build without gestures writes the header of the files before them, with the fingertips'
  // keypoints since: these fields, this order.
  const nlohmann::json before = TinyDatabaseOptions().Header();
  std::vector<std::string> keys;
  for (const auto& [key, value] : before.items()) keys.push_back(key);
  EXPECT_EQ(keys, (std::vector<std::string>{"crop", "entries", "format", "grasp_objects", "grasps", "hand",
                                            "hand_asset_sha256", "hog", "keypoints", "order", "record_bytes",
                                            "render", "steps", "total_entries", "view_sphere", "view_sphere_coverage",
                                            "viewpoints"}));
  EXPECT_EQ(before["order"], "((grasp * steps + step) * 2 + with_object) * viewpoints + viewpoint");
  const auto peace = GestureSteps(GestureByName("peace")), fist = GestureSteps(GestureByName("fist"));
  for (size_t i = 160; i < db.size(); ++i) {
    const EntryMeta meta = db.Meta(i);
    const size_t view = (i - 160) % 8, step = ((i - 160) / 8) % 5, gesture = (i - 160) / 40;
    ASSERT_EQ(meta.viewpoint, view);
    ASSERT_EQ(meta.step, step);
    ASSERT_FALSE(meta.with_object);
    ASSERT_TRUE(meta.has_hand);
    ASSERT_EQ(meta.grasp, options.gestures[gesture]);
    const JointAngles angles = db.Angles(i);
    for (int k = 0; k < kNumDofs; ++k) EXPECT_NEAR(angles[k], (gesture == 0 ? peace : fist)[step][k], 1e-6);
  }
  const nlohmann::json info = DescribeDatabase(db);
  EXPECT_EQ(info["grasps"], 2);
  EXPECT_EQ(info["gestures"], 2);
  EXPECT_EQ(info["without_object"], 80 + 80);
  EXPECT_EQ(DescribeDatabase(Database::Open(testing::BuildTinyDatabase(dir / "tiny.db")))["gestures"], 0);
}

TEST(BuilderTest, ShardsMergeIntoTheUnshardedFileByteForByte) {
  const auto dir = testing::ScratchDir();
  DatabaseBuildOptions options = TinyDatabaseOptions();
  BuildDatabase(RightHand(), options, dir / "whole.db", nullptr);
  std::vector<std::filesystem::path> shards;
  for (int i = 2; i >= 0; --i) {  // any order
    options.shard_index = i;
    options.shard_count = 3;
    shards.push_back(dir / ("part" + std::to_string(i) + ".db"));
    BuildDatabase(RightHand(), options, shards.back(), nullptr);
  }
  MergeDatabases(shards, dir / "merged.db");
  EXPECT_EQ(ReadFileBytes(dir / "whole.db"), ReadFileBytes(dir / "merged.db"));
  EXPECT_THROW(MergeDatabases({shards[0], shards[1]}, dir / "short.db"), Error);
  EXPECT_THROW(MergeDatabases({dir / "whole.db"}, dir / "again.db"), Error);
}

// An interrupted build: the first `records` of `whole` written in blocks of 25, as the
// writer leaves them when the process dies, then `tail` bytes of a torn record.
void Interrupt(const Database& whole, const std::filesystem::path& path, size_t records, size_t tail) {
  {
    DatabaseWriter writer(path, TinyDatabaseOptions().Header(), DatabaseWriter::Mode::kFresh);
    for (size_t begin = 0; begin < records; begin += 25) writer.Append(whole.Records(begin, std::min(records, begin + 25)));
  }
  std::vector<uint8_t> partial = ReadFileBytes(path.string() + ".partial");
  partial.resize(partial.size() + tail, 7);
  WriteFileAtomic(path.string() + ".partial", partial);
}

TEST(BuilderTest, InterruptedBuildResumesToTheSameBytes) {
  const auto dir = testing::ScratchDir();
  const std::vector<uint8_t> whole = ReadFileBytes(testing::BuildTinyDatabase(dir / "whole.db"));
  Interrupt(Database::Open(dir / "whole.db"), dir / "resumed.db", 50, 100);
  const BuildSummary summary = BuildDatabase(RightHand(), TinyDatabaseOptions(), dir / "resumed.db", nullptr);
  EXPECT_EQ(summary.resumed, 50u);
  EXPECT_EQ(summary.resume_note, "") << "a torn last record is the normal end of an interrupted build";
  EXPECT_EQ(summary.entries, 160u);
  EXPECT_EQ(ReadFileBytes(dir / "resumed.db"), whole);
  EXPECT_FALSE(std::filesystem::exists(dir / "resumed.db.partial"));
  EXPECT_FALSE(std::filesystem::exists(dir / "resumed.db.partial.blocks"));
}

// A byte flipped in a finished record of the partial file used to reach the final file
// under a fresh, valid checksum.
TEST(BuilderTest, ResumeRebuildsFromTheFirstBlockThatFailsItsChecksum) {
  const auto dir = testing::ScratchDir();
  const std::vector<uint8_t> whole = ReadFileBytes(testing::BuildTinyDatabase(dir / "whole.db"));
  const Database db = Database::Open(dir / "whole.db");
  Interrupt(db, dir / "resumed.db", 100, 0);
  std::vector<uint8_t> partial = ReadFileBytes(dir / "resumed.db.partial");
  partial[testing::RecordsOffset(partial) + 60 * db.layout().RecordBytes() + 1000] ^= 0x10;  // record 60
  WriteFileAtomic(dir / "resumed.db.partial", partial);
  const BuildSummary summary = BuildDatabase(RightHand(), TinyDatabaseOptions(), dir / "resumed.db", nullptr);
  EXPECT_EQ(summary.resumed, 50u) << "records 50 to 74 form the block that fails";
  EXPECT_NE(summary.resume_note.find("records 50 to 74 fail their checksum"), std::string::npos)
      << summary.resume_note;
  EXPECT_EQ(ReadFileBytes(dir / "resumed.db"), whole);
}

// A partial file with more records than the build makes used to give a file that db info
// then refused.
TEST(BuilderTest, ResumeDropsRecordsBeyondTheBuild) {
  const auto dir = testing::ScratchDir();
  const std::vector<uint8_t> whole = ReadFileBytes(testing::BuildTinyDatabase(dir / "whole.db"));
  const Database db = Database::Open(dir / "whole.db");
  Interrupt(db, dir / "resumed.db", 160, 0);
  std::vector<uint8_t> partial = ReadFileBytes(dir / "resumed.db.partial");
  const std::span<const uint8_t> extra = db.Records(0, 3);
  partial.insert(partial.end(), extra.begin(), extra.end());
  WriteFileAtomic(dir / "resumed.db.partial", partial);
  const BuildSummary summary = BuildDatabase(RightHand(), TinyDatabaseOptions(), dir / "resumed.db", nullptr);
  EXPECT_EQ(summary.resumed, 160u);
  EXPECT_NE(summary.resume_note.find("more records than this build makes"), std::string::npos) << summary.resume_note;
  EXPECT_EQ(ReadFileBytes(dir / "resumed.db"), whole);
}

TEST(BuilderTest, PartialFileWithoutBlockChecksumsIsStartedAfresh) {
  const auto dir = testing::ScratchDir();
  const std::vector<uint8_t> whole = ReadFileBytes(testing::BuildTinyDatabase(dir / "whole.db"));
  Interrupt(Database::Open(dir / "whole.db"), dir / "resumed.db", 50, 0);
  std::filesystem::remove(dir / "resumed.db.partial.blocks");
  const BuildSummary summary = BuildDatabase(RightHand(), TinyDatabaseOptions(), dir / "resumed.db", nullptr);
  EXPECT_EQ(summary.resumed, 0u);
  EXPECT_NE(summary.resume_note.find("cannot be verified"), std::string::npos) << summary.resume_note;
  EXPECT_EQ(ReadFileBytes(dir / "resumed.db"), whole);
}

TEST(BuilderTest, PartialFileOfOtherOptionsIsStartedAfreshAndSaidSo) {
  const auto dir = testing::ScratchDir();
  DatabaseBuildOptions other = TinyDatabaseOptions();
  other.descriptor.normalize_roll = false;
  {
    DatabaseWriter writer(dir / "tiny.db", other.Header(), DatabaseWriter::Mode::kFresh);
  }
  const BuildSummary summary = BuildDatabase(RightHand(), TinyDatabaseOptions(), dir / "tiny.db", nullptr);
  EXPECT_EQ(summary.resumed, 0u);
  EXPECT_NE(summary.resume_note.find("other options"), std::string::npos) << summary.resume_note;
  EXPECT_EQ(Database::Open(dir / "tiny.db").size(), 160u);
}

// Two builds into one --out used to corrupt the result while one of them reported success.
TEST(BuilderTest, SecondBuildIntoTheSamePathIsRefusedWhileTheFirstRuns) {
  const auto dir = testing::ScratchDir();
  DatabaseBuildOptions raw = TinyDatabaseOptions();
  raw.descriptor.normalize_roll = false;
  DatabaseWriter running(dir / "x.db", raw.Header(), DatabaseWriter::Mode::kResume);
  try {
    BuildDatabase(RightHand(), TinyDatabaseOptions(), dir / "x.db", nullptr);
    ADD_FAILURE() << "two builds wrote one file";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("another nphand process is writing it"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(std::filesystem::exists(dir / "x.db"));
}

// Destinations used to be checked only at the final rename, after all the work.
TEST(BuilderTest, BadDestinationsAreRefusedBeforeAnyWork) {
  const auto dir = testing::ScratchDir();
  std::filesystem::create_directories(dir / "folder");
  for (const std::filesystem::path& out : {dir / "folder", std::filesystem::path(), dir / "folder" / "",
                                           dir / "folder" / ".."}) {
    EXPECT_THROW(BuildDatabase(RightHand(), TinyDatabaseOptions(), out, nullptr), Error) << out;
  }
  EXPECT_TRUE(std::filesystem::is_empty(dir / "folder")) << "no partial file is left";
  DatabaseBuildOptions options = TinyDatabaseOptions();
  options.shard_count = 2;
  BuildDatabase(RightHand(), options, dir / "a.db", nullptr);
  options.shard_index = 1;
  BuildDatabase(RightHand(), options, dir / "b.db", nullptr);
  EXPECT_THROW(MergeDatabases({dir / "a.db", dir / "b.db"}, dir / "folder"), Error);
  EXPECT_TRUE(std::filesystem::is_empty(dir / "folder"));
  EXPECT_FALSE(std::filesystem::exists(dir / "folder.partial"));
}

TEST(BuilderTest, RollNormalisedHogIsTheHogOfTheTurnedCrop) {
  const Database db = Database::Open(testing::BuildTinyDatabase(testing::ScratchDir() / "tiny.db"));
  EXPECT_TRUE(db.header()["hog"]["normalize_roll"].get<bool>());
  EXPECT_EQ(db.header()["grasp_objects"][1]["object"], "sphere");  // grasp 13, Precision Sphere
  int turned = 0, checked = 0, same_sign = 0;
  for (size_t i = 0; i < db.size(); i += 7) {
    if (!db.Meta(i).has_hand) continue;
    // The stored crop is the hand as rendered; turning it reproduces the stored roll's axis
    // (its direction along the axis comes from a third moment, which a nearly symmetric
    // hand leaves to chance at another resolution).
    const HandCrop crop = *CropHand(db.Crop(i), {kCropBitsSide, 0.1, true});
    EXPECT_NEAR(std::remainder(crop.roll - db.Meta(i).roll, std::numbers::pi), 0.0, 0.1) << i;
    same_sign += std::abs(std::remainder(crop.roll - db.Meta(i).roll, 2 * std::numbers::pi)) < 0.1;
    turned += std::abs(db.Meta(i).roll) > 0.1;
    ++checked;
  }
  EXPECT_GT(turned, 5);
  EXPECT_GT(same_sign, checked * 3 / 4);
}

TEST(BuilderTest, InfoCountsWhatTheFileHolds) {
  const Database db = Database::Open(testing::BuildTinyDatabase(testing::ScratchDir() / "tiny.db"));
  const nlohmann::json info = DescribeDatabase(db);
  EXPECT_EQ(info["entries"], 160);
  EXPECT_EQ(info["grasps"], 2);
  EXPECT_EQ(info["steps"], 5);
  EXPECT_EQ(info["viewpoints"], 8);
  EXPECT_EQ(info["with_object"], 80);
  EXPECT_EQ(info["without_object"], 80);
  EXPECT_EQ(info["features"][0]["dimension"], 512);
  EXPECT_EQ(info["file_bytes"], db.file_bytes());
  EXPECT_GT(info["view_sphere"]["covering_radius_deg"].get<double>(), 30.0) << "8 directions cover the sphere coarsely";
  EXPECT_EQ(info["view_sphere"]["covering_radius_deg"], db.header()["view_sphere_coverage"]["covering_radius_deg"])
      << "measured once, at build time";
}

// A file whose header lacks the coverage (as files from before it was stored) has it
// measured, as it was before, in O(n log n): 65535 directions used to take minutes.
TEST(BuilderTest, InfoMeasuresTheCoverageOfOlderFiles) {
  const auto dir = testing::ScratchDir();
  const std::vector<uint8_t> bytes = ReadFileBytes(testing::BuildTinyDatabase(dir / "tiny.db"));
  nlohmann::json header = testing::HeaderOf(bytes);
  header.erase("view_sphere_coverage");
  WriteFileAtomic(dir / "older.db", testing::WithHeader(bytes, header));
  const nlohmann::json info = DescribeDatabase(Database::Open(dir / "older.db"));
  EXPECT_NEAR(info["view_sphere"]["covering_radius_deg"].get<double>(),
              DescribeDatabase(Database::Open(dir / "tiny.db"))["view_sphere"]["covering_radius_deg"].get<double>(),
              1e-4);
}

TEST(BuilderTest, BadOptionsAreRefused) {
  DatabaseBuildOptions options = TinyDatabaseOptions();
  options.grasps = {0};
  EXPECT_THROW(BuildDatabase(RightHand(), options, testing::ScratchDir() / "x.db", nullptr), Error);
  std::string why;
  options = TinyDatabaseOptions();
  options.gestures = {kNumGrasps};
  EXPECT_FALSE(options.Check(&why));
  EXPECT_NE(why.find("gestures are hand shapes 34 to"), std::string::npos) << why;
  options.gestures = {kFirstGestureId, kFirstGestureId};
  EXPECT_FALSE(options.Check(&why));
  EXPECT_NE(why.find("a gesture is listed twice"), std::string::npos) << why;
  options = TinyDatabaseOptions();
  options.shard_index = 3;
  options.shard_count = 3;
  EXPECT_FALSE(options.Check(&why));
  EXPECT_NE(why.find("shard"), std::string::npos);
}

}  // namespace
}  // namespace nphand
