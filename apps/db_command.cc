#include "apps/db_command.h"

#include <algorithm>
#include <charconv>
#include <chrono>
#include <tuple>
#include <iostream>

#include "nphand/features/crop.h"
#include "nphand/scene/gesture.h"
#include "nphand/util/check.h"
#include "nphand/util/file.h"

namespace nphand {

namespace {

// "i/N" with two whole numbers and nothing else.
std::pair<int, int> ParseShard(const std::string& text) {
  const size_t slash = text.find('/');
  int index = -1, count = -1;
  const char* end = text.data() + text.size();
  const bool ok = slash != std::string::npos &&
                  std::from_chars(text.data(), text.data() + slash, index) ==
                      std::from_chars_result{text.data() + slash, std::errc()} &&
                  std::from_chars(text.data() + slash + 1, end, count) == std::from_chars_result{end, std::errc()};
  NPHAND_THROW_CHECK(ok, "--shard '", text, "': expected i/N, e.g. 0/4");
  return {index, count};
}

}  // namespace

nlohmann::json RunDbBuild(DbBuildCommandOptions options) {
  if (!options.gestures.empty()) options.build.gestures = GestureIdsNamed(options.gestures, "db build --gestures");
  if (!options.shard.empty()) {
    std::tie(options.build.shard_index, options.build.shard_count) = ParseShard(options.shard);
  }
  std::string why;
  NPHAND_THROW_CHECK(options.build.Check(&why), "db build: ", why);
  CheckOutputFile(options.out, "db build --out");
  CheckOutputsApart({{options.asset_dir / "right.glb", "the hand asset"}}, {{options.out, "db build --out"}});
  std::string reuse_note;
  std::error_code error;
  if (options.reuse && std::filesystem::exists(options.out, error)) {
    try {
      const Database existing = Database::Open(options.out);
      if (existing.header() == options.build.Header()) {
        return {{"path", options.out.string()}, {"entries", existing.size()}, {"reused", true}};
      }
      reuse_note = "the existing file was built with other options";
    } catch (const Error& e) {
      reuse_note = std::string("the existing file cannot be used: ") + e.what();
    }
  }
  const HandModel hand = HandModel::Load(Handedness::kRight, options.asset_dir);
  const BuildSummary summary = BuildDatabase(hand, options.build, options.out, options.quiet ? nullptr : &std::cerr);
  return {{"path", options.out.string()},     {"entries", summary.entries},         {"resumed", summary.resumed},
          {"no_hand", summary.no_hand},       {"seconds", summary.seconds},         {"resume_note", summary.resume_note},
          {"reused", false},                  {"reuse_note", reuse_note}};
}

nlohmann::json RunDbMerge(const std::vector<std::filesystem::path>& shards, const std::filesystem::path& out) {
  std::vector<NamedPath> inputs;
  for (const std::filesystem::path& shard : shards) inputs.push_back({shard, "a shard"});
  CheckOutputsApart(inputs, {{out, "db merge --out"}});
  MergeDatabases(shards, out);
  return DescribeDatabase(Database::Open(out));
}

nlohmann::json RunDbInfo(const std::filesystem::path& path) {
  const auto start = std::chrono::steady_clock::now();
  const Database db = Database::Open(path);
  const double open_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  nlohmann::json info = DescribeDatabase(db);
  // How thin a hand's silhouette can be: what the estimator's max_elongation rests on.
  std::vector<double> elongation;
  for (size_t i = 0; i < db.size(); ++i) {
    if (db.Meta(i).has_hand) elongation.push_back(Elongation(db.Crop(i)));
  }
  std::sort(elongation.begin(), elongation.end());
  if (!elongation.empty()) {
    const auto quantile = [&](double q) { return elongation[std::min(elongation.size() - 1, static_cast<size_t>(q * elongation.size()))]; };
    info["silhouette_elongation"] = {{"median", quantile(0.5)}, {"q99", quantile(0.99)}, {"q999", quantile(0.999)},
                                     {"q9999", quantile(0.9999)}, {"max", elongation.back()}};
  }
  info["path"] = path.string();
  info["open_seconds"] = open_seconds;
  return info;
}

}  // namespace nphand
