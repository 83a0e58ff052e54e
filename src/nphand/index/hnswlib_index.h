// hnswlib's HNSW graph behind KnnIndex ("hnswlib"). The graph's nodes hold a pointer to
// nphand's descriptor row rather than a copy; with HnswOptions::pca, to the row's projection
// onto its first principal components, and the candidates are re-ranked exactly. Built single-threaded in row order, so the
// same options give the same graph. The index file holds nphand's own encoding of the
// graph (levels and link lists), checked on load; hnswlib's reader never sees file bytes.
#pragma once

#include <memory>
#include <ostream>
#include <span>
#include <string>
#include <vector>

#include "nphand/index/ann_options.h"
#include "nphand/index/knn_index.h"

namespace nphand {

// "hnswlib-sq8": the nodes hold 8-bit codes of the rows instead (value / step, one step
// for all values: the largest value / 255), searched by the codes' distance; the index
// keeps no float rows (a quarter of their memory). Its body starts with the step; the codes
// are made again from the database on load.
std::unique_ptr<KnnIndex> BuildHnswlibSq8(IndexedSet set, const HnswOptions& options, std::ostream* progress);
std::unique_ptr<KnnIndex> LoadHnswlibSq8(const Database& db, std::vector<entry_id_t> ids, const HnswOptions& options,
                                         std::span<const uint8_t> body, const std::string& source);
std::unique_ptr<KnnIndex> BuildHnswlib(IndexedSet set, const HnswOptions& options, std::ostream* progress);
std::unique_ptr<KnnIndex> LoadHnswlib(IndexedSet set, const HnswOptions& options, std::span<const uint8_t> body,
                                      const std::string& source);

}  // namespace nphand
