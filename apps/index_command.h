// `nphand index build | info`: the search index of a database.
#pragma once

#include <filesystem>

#include <nlohmann/json.hpp>

#include "nphand/index/backends.h"

namespace nphand {

struct IndexBuildCommandOptions {
  std::filesystem::path db = "out/nphand.db";
  std::filesystem::path out;  // default: the database's path with ".idx" appended
  IndexOptions index;
  bool reuse = false;  // keep an existing `out` that loads for this database with the same backend
};

// Where a command finds (or index build writes) a database's index: `index` when given,
// else the database's path with ".idx" appended.
std::filesystem::path IndexPathOf(const std::filesystem::path& db, const std::filesystem::path& index);

// Builds the index and writes it; returns its description, the path and the seconds it took.
nlohmann::json RunIndexBuild(const IndexBuildCommandOptions& options);
// The meta of an index file (backend, parameters, descriptor, the database's checksum).
nlohmann::json RunIndexInfo(const std::filesystem::path& path);

}  // namespace nphand
