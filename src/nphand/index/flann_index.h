// FLANN behind KnnIndex ("flann"): randomised k-d trees or a hierarchical k-means tree over
// nphand's descriptor rows (FLANN keeps pointers, not a copy). FLANN's random choices are
// seeded, so the trees follow from the options: the index file stores only the options and
// loading builds the trees again (FLANN's own reader never sees file bytes).
#pragma once

#include <memory>
#include <ostream>

#include "nphand/index/ann_options.h"
#include "nphand/index/knn_index.h"

namespace nphand {

std::unique_ptr<KnnIndex> BuildFlann(IndexedSet set, const FlannOptions& options, std::ostream* progress);

}  // namespace nphand
