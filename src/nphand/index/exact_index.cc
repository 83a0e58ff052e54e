#include "nphand/index/exact_index.h"

#include <algorithm>

#include <faiss/IndexFlat.h>

namespace nphand {

float SquaredDistance(std::span<const float> a, std::span<const float> b) {
  // Eight independent sums, so that the compiler vectorises the loop.
  float sums[8] = {};
  const size_t n = a.size(), whole = n / 8 * 8;
  for (size_t i = 0; i < whole; i += 8) {
    for (size_t j = 0; j < 8; ++j) {
      const float d = a[i + j] - b[i + j];
      sums[j] += d * d;
    }
  }
  float total = ((sums[0] + sums[1]) + (sums[2] + sums[3])) + ((sums[4] + sums[5]) + (sums[6] + sums[7]));
  for (size_t i = whole; i < n; ++i) total += (a[i] - b[i]) * (a[i] - b[i]);
  return total;
}

void BatchNearestRows(std::span<const float> base, std::span<const float> queries, int dimension, int k,
                      float* distances, int64_t* rows) {
  faiss::IndexFlatL2 index(dimension);
  index.add(static_cast<faiss::Index::idx_t>(base.size() / dimension), base.data());
  index.search(static_cast<faiss::Index::idx_t>(queries.size() / dimension), queries.data(), k, distances, rows);
}

std::vector<std::pair<float, uint32_t>> SmallestK(std::vector<std::pair<float, uint32_t>> scored, int k) {
  const size_t keep = std::min<size_t>(k, scored.size());
  std::partial_sort(scored.begin(), scored.begin() + keep, scored.end());
  scored.resize(keep);
  return scored;
}

std::vector<std::pair<float, uint32_t>> Rerank(const DescriptorMatrix& base, std::span<const float> query,
                                               std::span<const uint32_t> rows, int k) {
  std::vector<std::pair<float, uint32_t>> scored;
  scored.reserve(rows.size());
  for (uint32_t row : rows) scored.emplace_back(SquaredDistance(query, base.Row(row)), row);
  return SmallestK(std::move(scored), k);
}

std::vector<std::pair<float, uint32_t>> ExactIndex::SearchRows(std::span<const float> query, int k) const {
  return NearestRows(set().descriptors, query, k);
}

std::vector<std::pair<float, uint32_t>> NearestRows(const DescriptorMatrix& base, std::span<const float> query, int k) {
  std::vector<std::pair<float, uint32_t>> scored(base.rows());
  for (size_t r = 0; r < base.rows(); ++r) scored[r] = {SquaredDistance(query, base.Row(r)), static_cast<uint32_t>(r)};
  return SmallestK(std::move(scored), k);
}

}  // namespace nphand
