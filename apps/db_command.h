// `nphand db build | merge | info`: the database file's life.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "nphand/db/builder.h"

namespace nphand {

struct DbBuildCommandOptions {
  std::filesystem::path out = "out/nphand.db";
  DatabaseBuildOptions build;
  std::vector<std::string> gestures;  // gesture names, "all" or "none": replace build.gestures when given
  std::string shard;  // "i/N" or empty
  std::filesystem::path asset_dir = DefaultAssetDir();
  bool quiet = false;  // no progress line
  bool reuse = false;  // keep an existing `out` that opens, verifies and has these options' header
};

// Builds (or resumes) the database; returns {entries, resumed, no_hand, seconds, path}.
nlohmann::json RunDbBuild(DbBuildCommandOptions options);
// Merges shards into `out`; returns DescribeDatabase of the result.
nlohmann::json RunDbMerge(const std::vector<std::filesystem::path>& shards, const std::filesystem::path& out);
// Opens (and verifies) a database; returns DescribeDatabase plus the seconds the open took.
nlohmann::json RunDbInfo(const std::filesystem::path& path);

}  // namespace nphand
