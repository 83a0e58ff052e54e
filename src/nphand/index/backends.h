// Every index backend behind one set of options: build an index of a database, load one.
#pragma once

#include <filesystem>
#include <memory>
#include <ostream>
#include <string>

#include <vector>

#include "nphand/index/ann_options.h"
#include "nphand/index/knn_index.h"
#include "nphand/index/lsh_index.h"

namespace nphand {

// exact, lsh, faiss-hnsw, faiss-ivf, hnswlib, hnswlib-sq8, flann.
const std::vector<std::string>& IndexBackends();

struct IndexOptions {
  // One of IndexBackends(). The default, hnswlib-sq8 with HnswOptions' defaults, is the
  // fastest setting of the nearest-neighbour study (docs/ann_study.md) that keeps recall@500
  // above 0.95 on held-out renders.
  std::string backend = "hnswlib-sq8";
  LshOptions lsh;                 // for lsh
  HnswOptions hnsw;               // for faiss-hnsw, hnswlib and hnswlib-sq8
  IvfOptions ivf;                 // for faiss-ivf
  FlannOptions flann;             // for flann

  bool Check(std::string* why) const;
  // Exhaustive search: the ground truth.
  static IndexOptions Exact();
};

// Builds an index of every entry of `db` that shows a hand; a backend that tunes itself
// reports to `progress` if not null.
std::unique_ptr<KnnIndex> BuildIndex(const Database& db, const IndexOptions& options, std::ostream* progress = nullptr);
// The same over any set of rows (the study indexes fractions of a database).
std::unique_ptr<KnnIndex> BuildIndex(IndexedSet set, const IndexOptions& options, std::ostream* progress = nullptr);
// Loads an index file for `db`; throws nphand::Error naming the file and the problem (not an
// index, another version, corrupt, truncated, built from another database or descriptor).
std::unique_ptr<KnnIndex> LoadIndex(const std::filesystem::path& path, const Database& db);
// The meta of an index file (checked as LoadIndex does, without a database).
nlohmann::json ReadIndexMeta(const std::filesystem::path& path);

}  // namespace nphand
