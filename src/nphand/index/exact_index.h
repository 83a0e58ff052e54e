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

 protected:
  std::vector<std::pair<float, uint32_t>> SearchRows(std::span<const float> query, int k) const override;
  std::vector<uint8_t> Body() const override { return {}; }
};

// The k rows of `base` nearest to `query` by exhaustive search: (squared distance, row),
// ascending, ties by row.
std::vector<std::pair<float, uint32_t>> NearestRows(const DescriptorMatrix& base, std::span<const float> query, int k);
// The k smallest of (distance, row) pairs, ascending, ties by row.
std::vector<std::pair<float, uint32_t>> SmallestK(std::vector<std::pair<float, uint32_t>> scored, int k);
// Squared L2 distance between two equally long vectors.
float SquaredDistance(std::span<const float> a, std::span<const float> b);

}  // namespace nphand
