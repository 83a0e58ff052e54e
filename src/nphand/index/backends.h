// Every index backend behind one set of options: build an index of a database, load one.
#pragma once

#include <filesystem>
#include <memory>
#include <ostream>
#include <string>

#include "nphand/index/knn_index.h"
#include "nphand/index/lsh_index.h"

namespace nphand {

struct IndexOptions {
  std::string backend = "exact";  // exact | lsh
  LshOptions lsh;                 // for lsh

  bool Check(std::string* why) const;
};

// Builds an index of every entry of `db` that shows a hand; a backend that tunes itself
// reports to `progress` if not null.
std::unique_ptr<KnnIndex> BuildIndex(const Database& db, const IndexOptions& options, std::ostream* progress = nullptr);
// Loads an index file for `db`; throws nphand::Error naming the file and the problem (not an
// index, another version, corrupt, truncated, built from another database or descriptor).
std::unique_ptr<KnnIndex> LoadIndex(const std::filesystem::path& path, const Database& db);
// The meta of an index file (checked as LoadIndex does, without a database).
nlohmann::json ReadIndexMeta(const std::filesystem::path& path);

}  // namespace nphand
