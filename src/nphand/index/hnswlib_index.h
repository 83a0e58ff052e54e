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

#include "nphand/index/ann_options.h"
#include "nphand/index/knn_index.h"

namespace nphand {

std::unique_ptr<KnnIndex> BuildHnswlib(IndexedSet set, const HnswOptions& options, std::ostream* progress);
std::unique_ptr<KnnIndex> LoadHnswlib(IndexedSet set, const HnswOptions& options, std::span<const uint8_t> body,
                                      const std::string& source);

}  // namespace nphand
