#include "apps/index_command.h"

#include <gtest/gtest.h>

#include "nphand/util/check.h"
#include "testing/testing.h"
#include "testing/tiny_db.h"

namespace nphand {
namespace {

TEST(IndexCommandTest, BuildsAnIndexBesideTheDatabaseAndDescribesIt) {
  const auto dir = testing::ScratchDir();
  IndexBuildCommandOptions options;
  options.db = testing::BuildTinyDatabase(dir / "tiny.db");
  const nlohmann::json built = RunIndexBuild(options);
  EXPECT_EQ(built["path"], (dir / "tiny.db.idx").string());
  EXPECT_EQ(built["backend"], "hnswlib-sq8") << "the default the nearest-neighbour study chose";
  const nlohmann::json info = RunIndexInfo(dir / "tiny.db.idx");
  EXPECT_EQ(info["backend"], "hnswlib-sq8");
  EXPECT_EQ(info["parameters"]["ef_search"], 500);
  EXPECT_EQ(info["database"]["checksum"], Database::Open(options.db).checksum());
  EXPECT_EQ(info["entries"], built["entries"]);
  EXPECT_GT(info["file_bytes"].get<int>(), 0);
}

TEST(IndexCommandTest, BadOptionsAreRefusedBeforeAnyWork) {
  IndexBuildCommandOptions options;
  options.db = "/nonexistent.db";
  options.index.backend = "annoy";
  testing::ExpectError([&] { RunIndexBuild(options); }, "unknown index backend 'annoy'");
  options.index.backend = "exact";
  options.out = testing::ScratchDir();
  testing::ExpectError([&] { RunIndexBuild(options); }, "is a folder");
  testing::ExpectError([&] { RunIndexInfo(testing::ScratchDir()); }, "is a folder");
}

}  // namespace
}  // namespace nphand
