// FLANN behind KnnIndex ("flann"): randomised k-d trees or a hierarchical k-means tree over
// nphand's descriptor rows (FLANN keeps pointers, not a copy). The index file stores only
// the options and loading builds the trees again (FLANN's own reader never sees file
// bytes). Debian's FLANN 1.9.2 seeds its shuffles from std::random_device, so each build
// grows other trees: the same recall, not the same answers.
#pragma once

#include <memory>
#include <ostream>

#include "nphand/index/ann_options.h"
#include "nphand/index/knn_index.h"

namespace nphand {

std::unique_ptr<KnnIndex> BuildFlann(IndexedSet set, const FlannOptions& options, std::ostream* progress);

}  // namespace nphand
