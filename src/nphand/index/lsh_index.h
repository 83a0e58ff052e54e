// Multi-probe LSH for L2 (the paper's Sec. 5.1), written here: L hash tables, each keyed by
// M projections h(v) = floor((a . v) / W + u) with a ~ N(0, I) and u ~ U[0, 1) per hash;
// a query visits its own bucket and then T - 1 more per table in the query-directed
// probing order of Lv et al. (2007): perturbations of the M hash values by -1 or +1,
// in increasing sum of squared distances of the query's projection to the crossed bucket
// boundaries (in units of W). The candidates are re-ranked by exact distance.
//
// An offline tuner picks M and W for a target recall R of the true K nearest on sampled
// database rows, with L and T fixed (the paper: L = 10, T = 50, R = 0.95): for each M it
// finds the smallest W that reaches R, and keeps the (M, W) that gathers the fewest
// candidates. The projections follow from the seed, so the index file stores only the
// parameters; loading rebuilds the tables.
#pragma once

#include <cstdint>
#include <memory>
#include <ostream>
#include <string>
#include <vector>

#include "nphand/index/knn_index.h"

namespace nphand {

// Hashes per table the projections are drawn for; M is at most this.
inline constexpr int kMaxLshHashes = 20;

struct LshOptions {
  int tables = 10;             // L
  int probes = 50;             // T per table, its home bucket included
  int hashes = 0;              // M per table; 0: tuned
  double bucket_width = 0.0;   // W; 0: tuned (with M)
  double target_recall = 0.95; // R, of the true `tune_k` nearest
  int tune_k = 500;            // the K whose recall the tuner measures
  int tune_queries = 200;      // sampled database rows the tuner measures on
  uint64_t seed = 1;           // projections, offsets and the tuner's sample

  bool Check(std::string* why) const;
};

class LshIndex : public KnnIndex {
 public:
  // Builds (and tunes, where `options` leave M or W at 0) over `set`. Reports the tuning to
  // `progress` if not null.
  LshIndex(IndexedSet set, const LshOptions& options, std::ostream* progress);

  std::string Backend() const override { return "lsh"; }
  // tables, probes, hashes, bucket_width, seed, and what tuning measured.
  nlohmann::json Parameters() const override;
  // The options that rebuild this index exactly (M and W fixed), from Parameters().
  static LshOptions OptionsFromParameters(const nlohmann::json& parameters, const std::string& source);
  // The index that Parameters() describe, with what its tuning measured.
  static std::unique_ptr<LshIndex> FromParameters(IndexedSet set, const nlohmann::json& parameters,
                                                  const std::string& source);
  // The recall of the true `tune_k` nearest that tuning measured (0 if M and W were given).
  double tuned_recall() const { return tuned_recall_; }
  size_t MemoryBytes() const override;

 protected:
  std::vector<std::pair<float, uint32_t>> SearchRows(std::span<const float> query, int k) const override;
  std::vector<uint8_t> Body() const override { return {}; }

 private:
  struct Table {
    std::vector<uint64_t> keys;  // sorted bucket keys, one per row
    std::vector<uint32_t> rows;  // the rows, in key order
  };
  // Tunes M and W (those left at 0) on the set's projections; see the file comment.
  void Tune(const std::vector<float>& projected, std::ostream* progress);
  // The tables for options_'s M and W from the set's projections (rows x tables * kMaxHashes).
  std::vector<Table> BuildTables(const std::vector<float>& projected) const;
  // The rows in the probed buckets of every table of `tables` (deduplicated, ascending).
  std::vector<uint32_t> Candidates(const std::vector<Table>& tables, std::span<const float> projected) const;

  LshOptions options_;
  std::vector<float> projections_;  // (tables * kMaxHashes) x dimension, row-major, N(0, 1)
  std::vector<float> offsets_;      // tables * kMaxHashes, in [0, 1)
  std::vector<Table> tables_;
  double tuned_recall_ = 0.0;       // recall the tuner measured (0 if not tuned)
  double tuned_candidates_ = 0.0;   // mean candidates per query it measured
};

}  // namespace nphand
