#include "apps/db_command.h"

#include <gtest/gtest.h>

#include "apps/eval_command.h"
#include "nphand/db/database.h"
#include "nphand/scene/gesture.h"
#include "nphand/util/check.h"
#include "nphand/util/io.h"
#include "testing/testing.h"
#include "testing/tiny_db.h"

namespace nphand {
namespace {

using testing::ExpectError;

// "0/2x" and "0/2/3" used to be taken as 0/2.
TEST(DbCommandTest, ShardMustBeExactlyTwoNumbers) {
  for (const std::string shard : {"0/2x", "0/2/3", "x", "0/", "/2", " 0/2", "0/2 "}) {
    DbBuildCommandOptions options;
    options.shard = shard;
    options.out = testing::ScratchDir() / "x.db";
    ExpectError([&] { RunDbBuild(options); }, "--shard '" + shard + "': expected i/N");
  }
}

TEST(DbCommandTest, DestinationIsCheckedBeforeTheBuild) {
  DbBuildCommandOptions options;
  options.out = testing::ScratchDir();
  options.asset_dir = "/nonexistent";  // were the hand loaded first, this would be the error
  ExpectError([&] { RunDbBuild(options); }, "is a folder");
  options.out = "";
  ExpectError([&] { RunDbBuild(options); }, "the output path is empty");
  ExpectError([&] { RunDbMerge({"a.db", "b.db"}, testing::ScratchDir()); }, "is a folder");
}

// --gestures: names (as the CLI and files spell them, or as people write them), all or none.
TEST(DbCommandTest, GesturesAreNamedOrAllOrNone) {
  DbBuildCommandOptions options;
  options.build = testing::TinyDatabaseOptions();
  options.build.gestures = GestureIds();  // the library's default, which the option replaces
  options.quiet = true;
  options.out = testing::ScratchDir() / "none.db";
  options.gestures = {"none"};
  EXPECT_EQ(RunDbBuild(options)["entries"], 160);
  options.out = testing::ScratchDir() / "two.db";
  options.gestures = {"peace", "Thumbs Up"};
  EXPECT_EQ(RunDbBuild(options)["entries"], 160 + 2 * 5 * 8);
  EXPECT_EQ(Database::Open(options.out).header()["gesture_names"], nlohmann::json::array({"peace", "thumbs_up"}));
  options.out = testing::ScratchDir() / "all.db";
  options.build.gestures = {};
  options.gestures = {"all"};
  EXPECT_EQ(RunDbBuild(options)["entries"], 160 + kNumGestures * 5 * 8);
  options.gestures = {"all", "fist"};
  ExpectError([&] { RunDbBuild(options); }, "db build --gestures: 'all' and 'none' stand alone, not among names");
}

TEST(DbCommandTest, StudyOutputIsCheckedBeforeTheStudy) {
  EvalFeaturesCommandOptions options;
  options.db = "/nonexistent.db";  // were the study run first, this would be the error
  options.out_dir = testing::ScratchDir();
  options.name = "../x";
  ExpectError([&] { RunEvalFeatures(options); }, "must be a file name");
  options.name = "study";
  options.out_dir = testing::ScratchDir() / "a_file";
  WriteFileAtomic(options.out_dir, std::string("x"));
  ExpectError([&] { RunEvalFeatures(options); }, "is a file, not a folder");
}

}  // namespace
}  // namespace nphand
