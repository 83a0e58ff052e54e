// `nphand eval real`: the estimator on labelled real photographs and video (real-dev, or
// any labels.jsonl in its format), scored by real_score.h. Stills are estimated one at a
// time from a fresh estimator (no temporal prior); a video's frames in order, so that the
// prior applies.
#pragma once

#include <filesystem>
#include <ostream>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "nphand/estimate/estimator.h"
#include "nphand/eval/real_score.h"

namespace nphand {

// Checks that every file the labels name is under `root` and readable as what it is (an
// image, or a video for lines with a frame); throws nphand::Error naming the first that is
// not, before any estimation.
void CheckRealFiles(const std::vector<RealLabel>& labels, const std::filesystem::path& root);

// How `EstimateReal` shows the frames to the estimator.
struct RealRunOptions {
  // The hand's place given: each labelled hand is estimated alone, in its found region (its
  // box grown by 25 %, see real_score.h) as the estimator's region of interest, by the
  // estimator of its side (with `left`), and each labelled video frame within its label's
  // region.
  bool given_box = false;
  // Each image and video frame whose longer side exceeds this many pixels is shrunk (area
  // averaging) until it does not, before the estimator sees it: how nphand fares at a
  // webcam's resolution (320: a 320 x 240 camera's frames). The predictions' 2D keypoints
  // are mapped back to the labels' pixels. 0: every frame as it is.
  int max_side = 0;
  // False, with why, for a max_side other than 0 and under 16.
  bool Check(std::string* why) const;
};

// The estimator's predictions for every labelled image and video frame. With `left`, the
// hand's side is the label's ("given"): each side labelled in an image is estimated once,
// by `right` or `left` (estimators over one database, differing in their `hand`), each
// reset first; an image without a labelled side is estimated as a right hand. Without
// `left` (null), `right` chooses the side itself (hand_auto) and each image is estimated
// once. `progress` (if not null) gets a progress line. Throws nphand::Error for `run`
// that fails its Check.
std::vector<RealPrediction> EstimateReal(const std::vector<RealLabel>& labels, const std::filesystem::path& root,
                                         Estimator* right, Estimator* left, const RealRunOptions& run, std::ostream* progress);

// A contact sheet of the stills: each image with its labelled keypoints (green rings; a
// HaGRID box as a green rectangle) and the predicted skeletons, captioned found or missed.
cv::Mat RealContactSheet(const std::vector<RealLabel>& labels, const std::vector<RealPrediction>& predictions,
                         const RealScore& score, const std::filesystem::path& root);

}  // namespace nphand
