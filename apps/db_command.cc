#include "apps/db_command.h"

#include <chrono>
#include <iostream>

#include "nphand/util/check.h"

namespace nphand {

nlohmann::json RunDbBuild(DbBuildCommandOptions options) {
  if (!options.shard.empty()) {
    const size_t slash = options.shard.find('/');
    try {
      NPHAND_THROW_CHECK(slash != std::string::npos, "bad");
      options.build.shard_index = std::stoi(options.shard.substr(0, slash));
      options.build.shard_count = std::stoi(options.shard.substr(slash + 1));
    } catch (const std::exception&) {
      NPHAND_THROW("--shard '", options.shard, "': expected i/N, e.g. 0/4");
    }
  }
  if (options.out.has_parent_path()) std::filesystem::create_directories(options.out.parent_path());
  const HandModel hand = HandModel::Load(Handedness::kRight, options.asset_dir);
  const BuildSummary summary = BuildDatabase(hand, options.build, options.out, options.quiet ? nullptr : &std::cerr);
  return {{"path", options.out.string()},
          {"entries", summary.entries},
          {"resumed", summary.resumed},
          {"no_hand", summary.no_hand},
          {"seconds", summary.seconds}};
}

nlohmann::json RunDbMerge(const std::vector<std::filesystem::path>& shards, const std::filesystem::path& out) {
  MergeDatabases(shards, out);
  return DescribeDatabase(Database::Open(out));
}

nlohmann::json RunDbInfo(const std::filesystem::path& path) {
  const auto start = std::chrono::steady_clock::now();
  const Database db = Database::Open(path);
  const double open_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  nlohmann::json info = DescribeDatabase(db);
  info["path"] = path.string();
  info["open_seconds"] = open_seconds;
  return info;
}

}  // namespace nphand
