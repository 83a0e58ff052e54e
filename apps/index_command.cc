#include "apps/index_command.h"

#include <chrono>
#include <iostream>

#include "nphand/util/check.h"
#include "nphand/util/file.h"

namespace nphand {

std::filesystem::path IndexPathOf(const std::filesystem::path& db, const std::filesystem::path& index) {
  return index.empty() ? std::filesystem::path(db.string() + ".idx") : index;
}

nlohmann::json RunIndexBuild(const IndexBuildCommandOptions& options) {
  std::string why;
  NPHAND_THROW_CHECK(options.index.Check(&why), "index build: ", why);
  const std::filesystem::path out = IndexPathOf(options.db, options.out);
  CheckOutputFile(out, "index build --out");
  CheckOutputsApart({{options.db, "--db"}}, {{out, "index build --out"}});
  const auto start = std::chrono::steady_clock::now();
  const Database db = Database::Open(options.db);
  std::string reuse_note;
  std::error_code error;
  if (options.reuse && std::filesystem::exists(out, error)) {
    try {
      const std::unique_ptr<KnnIndex> existing = LoadIndex(out, db);
      if (existing->Backend() == options.index.backend) {
        nlohmann::json summary = existing->Describe();
        summary["path"] = out.string();
        summary["reused"] = true;
        return summary;
      }
      reuse_note = "the existing index has another backend (" + existing->Backend() + ")";
    } catch (const Error& e) {
      reuse_note = std::string("the existing index cannot be used: ") + e.what();
    }
  }
  const std::unique_ptr<KnnIndex> index = BuildIndex(db, options.index, &std::cerr);
  index->Save(out, db);
  nlohmann::json summary = index->Describe();
  summary["path"] = out.string();
  summary["seconds"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  summary["reused"] = false;
  if (!reuse_note.empty()) summary["reuse_note"] = reuse_note;
  return summary;
}

nlohmann::json RunIndexInfo(const std::filesystem::path& path) {
  nlohmann::json meta = ReadIndexMeta(path);
  meta["path"] = path.string();
  meta["file_bytes"] = std::filesystem::file_size(path);
  return meta;
}

}  // namespace nphand
