// Cutting a skin region at the wrist: real hands come with a bare forearm that the
// database's mesh lacks, and an arm in the crop changes its scale and shape. The region's
// principal axis runs along the arm; its width profile along that axis is the arm's from
// the elbow to the wrist and widens at the hand, so the cut goes through the narrowest point
// just before the widening, across the axis (an arm seen in perspective tapers, so the
// narrowest point of the whole arm may be its far end). An arm that leaves the frame at a
// slant is cut by the frame's edge over a stretch whose slices widen from nothing: where
// reading from its end finds no wrist, the profile is read again from beyond that stretch.
// An adult's arm read from its capped far end widens towards the elbow by more than the
// hand's widening ratio, but gradually: where the widening against the narrowest width so
// far leaves no arm before it, the profile is read again with the widening judged within
// one width, as a hand widens.
// A region without a forearm has no narrow stretch before a widening and is left whole.
#pragma once

#include <string>

#include <opencv2/core.hpp>

namespace nphand {

struct ForearmCutOptions {
  // The hand starts where the width first exceeds this many times the narrowest width
  // seen so far, walking from the arm's end.
  double widen_ratio = 1.3;
  // Where that leaves no arm before the widening, the profile is read again with the
  // narrowest taken over the last stretch only, this many narrowest widths long: a hand
  // widens within its own width, while an adult's arm widens gradually towards the elbow,
  // and read from its capped far end that widening passes for the hand's (docs/estimator.md).
  double widen_within = 1.0;
  // An arm is at least this wide relative to the widest part (fingers are narrower): the
  // 90th percentile of the slices' skin along the axis (their pixels, not their extent), as
  // fingers held out sideways make slices far wider than the palm.
  double min_arm_width = 0.3;
  // ...and at least this long, in arm widths, before the cut (shorter: no forearm); a
  // group of fingers can pass for an arm, but not for a long one. On rendered sequences
  // the arms not entering from the frame's edge ran 3.0 widths (median; 10th percentile
  // 1.7) and the fingers taken for one 1.4 (10th percentile 1.2): docs/estimator.md.
  double min_arm_length = 1.4;
  // The same for an end that enters from the frame's edge, as an arm does.
  double min_arm_length_at_edge = 0.3;
  // The wrist is sought within this many arm widths (the arm's median width) before the
  // hand's widening.
  double wrist_reach = 1.5;
  bool Check(std::string* why) const;
};

struct ForearmCut {
  cv::Mat hand;                 // CV_8UC1, the region without its forearm (255 = hand)
  bool cut = false;             // a forearm was found and removed
  cv::Point2d wrist;            // the cut's centre (pixels of the mask), if cut
  cv::Point2d arm_direction;    // unit, from the wrist towards the elbow, if cut
  double wrist_width = 0.0;     // pixels across the cut, if cut
};

// The hand part of `region` (CV_8UC1, non-zero = one skin region). `border` says which
// sides of the mask touch the frame's edge (an arm usually comes in from one): bit 0 left,
// 1 top, 2 right, 3 bottom. Throws nphand::Error for another type or invalid options.
ForearmCut CutForearm(const cv::Mat& region, int border, const ForearmCutOptions& options = {});

}  // namespace nphand
