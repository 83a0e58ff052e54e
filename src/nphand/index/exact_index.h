// Exhaustive search: every row's squared L2 distance to the query, the k smallest sorted.
// The ground truth of every recall figure.
#pragma once

#include "nphand/index/knn_index.h"

namespace nphand {

class ExactIndex : public KnnIndex {
 public:
  explicit ExactIndex(IndexedSet set) : KnnIndex(std::move(set)) {}
  std::string Backend() const override { return "exact"; }
  nlohmann::json Parameters() const override { return nlohmann::json::object(); }
  size_t MemoryBytes() const override { return 0; }

 protected:
  std::vector<std::pair<float, uint32_t>> SearchRows(std::span<const float> query, int k) const override;
  std::vector<uint8_t> Body() const override { return {}; }
};

// The k rows of `base` nearest to `query` by exhaustive search: (squared distance, row),
// ascending, ties by row.
std::vector<std::pair<float, uint32_t>> NearestRows(const DescriptorMatrix& base, std::span<const float> query, int k);
// The k of `rows` nearest to `query` by exact distance: (squared distance, row), ascending,
// ties by row. How approximate backends give exact, comparable distances.
std::vector<std::pair<float, uint32_t>> Rerank(const DescriptorMatrix& base, std::span<const float> query,
                                               std::span<const uint32_t> rows, int k);
// The k smallest of (distance, row) pairs, ascending, ties by row.
std::vector<std::pair<float, uint32_t>> SmallestK(std::vector<std::pair<float, uint32_t>> scored, int k);
// The k nearest rows of `base` for every row of `queries` (both row-major, `dimension`
// columns) by exhaustive search on all cores (FAISS's BLAS path): for query q, distances[q *
// k + r] and rows[q * k + r], ascending. For features other than a database's descriptor
// (the feature study); k must not exceed base's rows.
void BatchNearestRows(std::span<const float> base, std::span<const float> queries, int dimension, int k,
                      float* distances, int64_t* rows);
// Squared L2 distance between two equally long vectors.
float SquaredDistance(std::span<const float> a, std::span<const float> b);

}  // namespace nphand
