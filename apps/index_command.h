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

// Builds the index and writes it; returns its description, the path and the seconds it took.
nlohmann::json RunIndexBuild(const IndexBuildCommandOptions& options);
// The meta of an index file (backend, parameters, descriptor, the database's checksum).
nlohmann::json RunIndexInfo(const std::filesystem::path& path);

}  // namespace nphand
