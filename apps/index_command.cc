#include "apps/index_command.h"

#include <chrono>
#include <iostream>

#include "nphand/util/check.h"
#include "nphand/util/file.h"

namespace nphand {

nlohmann::json RunIndexBuild(const IndexBuildCommandOptions& options) {
  std::string why;
  NPHAND_THROW_CHECK(options.index.Check(&why), "index build: ", why);
  const std::filesystem::path out = options.out.empty() ? std::filesystem::path(options.db.string() + ".idx") : options.out;
  CheckOutputFile(out, "index build --out");
  const auto start = std::chrono::steady_clock::now();
  const Database db = Database::Open(options.db);
  const std::unique_ptr<KnnIndex> index = BuildIndex(db, options.index, &std::cerr);
  index->Save(out, db);
  nlohmann::json summary = index->Describe();
  summary["path"] = out.string();
  summary["seconds"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return summary;
}

nlohmann::json RunIndexInfo(const std::filesystem::path& path) {
  nlohmann::json meta = ReadIndexMeta(path);
  meta["path"] = path.string();
  meta["file_bytes"] = std::filesystem::file_size(path);
  return meta;
}

}  // namespace nphand
