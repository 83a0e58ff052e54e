// FAISS backends behind KnnIndex: "faiss-hnsw" (FAISS's HNSW graph over nphand's own
// descriptor rows, no second copy) and "faiss-ivf" (an inverted file over k-means cells,
// flat or 8-bit scalar-quantised). Every build is single-threaded in a fixed order, so the
// same options give the same index bytes. The index file holds nphand's own encoding of
// the graph or of the centroids and cell of every row, checked on load; FAISS's reader
// never sees file bytes. Results carry exact distances.
#pragma once

#include <memory>
#include <ostream>
#include <span>
#include <string>

#include "nphand/index/ann_options.h"
#include "nphand/index/knn_index.h"

namespace nphand {

std::unique_ptr<KnnIndex> BuildFaissHnsw(IndexedSet set, const HnswOptions& options, std::ostream* progress);
std::unique_ptr<KnnIndex> LoadFaissHnsw(IndexedSet set, const HnswOptions& options, std::span<const uint8_t> body,
                                        const std::string& source);

std::unique_ptr<KnnIndex> BuildFaissIvf(IndexedSet set, const IvfOptions& options, std::ostream* progress);
std::unique_ptr<KnnIndex> LoadFaissIvf(IndexedSet set, const IvfOptions& options, std::span<const uint8_t> body,
                                       const std::string& source);

}  // namespace nphand
