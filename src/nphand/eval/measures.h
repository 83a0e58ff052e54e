// Today's hand-pose measures (HO-3D, DexYCB, FreiHAND), on the 21 keypoints in metres:
// MPJPE about the root, PA-MPJPE after a similarity Procrustes alignment, the fraction of
// keypoints within a distance and the area under that curve, jitter, lag; and, from 2D keypoints,
// which side of the hand faces the camera. The paper's own
// measures (pose-vector error, keypoints about the wrist) are in pose_errors.h.
#pragma once

#include <array>
#include <deque>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "nphand/model/hand_model.h"

namespace nphand {

// The upper median of `values` (the element at index n / 2 once sorted), 0 for none: the
// per-frame timings and errors the studies report.
double Median(std::vector<double> values);

// Mean distance between corresponding keypoints once both sets are moved so that their
// roots (keypoint 0, the wrist) meet: root-relative MPJPE, metres.
double RootRelativeError(const Keypoints3d& estimate, const Keypoints3d& truth);

// Mean distance between corresponding keypoints after the estimate is aligned to the truth
// by the rotation, uniform scale and translation that minimise the squared distances
// (Umeyama): PA-MPJPE, metres.
double ProcrustesError(const Keypoints3d& estimate, const Keypoints3d& truth);

// The distances of corresponding keypoints (root-relative, as RootRelativeError), metres.
std::vector<double> RootRelativeDistances(const Keypoints3d& estimate, const Keypoints3d& truth);

// The fraction of `distances` at most `threshold`.
double FractionWithin(std::span<const double> distances, double threshold);

// The area under the curve of FractionWithin over thresholds evenly spaced in [0, max]
// (`steps` + 1 of them, trapezoids), divided by max: 1 when every distance is 0, 0 when
// none is within max. FreiHAND's AUC over 0–50 mm is AreaUnderCurve(d, 0.05).
double AreaUnderCurve(std::span<const double> distances, double max, int steps = 100);

// A wrist this far from the truth (degrees) is turned about 180 degrees: the wrist drawn at
// the fingertips, a silhouette read end for end.
inline constexpr double kTurnedDeg = 135.0;

// Below this sine between the wrist->index MCP and wrist->little MCP rays a hand is edge-on:
// which of its sides faces the camera is not judged.
inline constexpr double kEdgeOnSine = 0.2;
enum class Facing { kUnknown, kPalm, kBack };
// Which side of a hand faces the camera, from three of its 2D keypoints (pixels, y down:
// wrist, index MCP, little MCP; any missing or the hand edge-on: kUnknown) and its side
// ("left" or "right"; anything else: kUnknown). The turn from the wrist->index MCP ray to
// the wrist->little MCP ray looks counter-clockwise for a right palm and for a left back.
Facing FacingOf(const std::optional<Eigen::Vector2d>& wrist, const std::optional<Eigen::Vector2d>& index_mcp,
                const std::optional<Eigen::Vector2d>& little_mcp, const std::string& hand);
// The same from a hand's 21 keypoints in the standard order (a label's, some unlabelled; or
// an estimate's).
Facing FacingOf(const std::array<std::optional<Eigen::Vector2d>, kNumKeypoints>& keypoints, const std::string& hand);
Facing FacingOf(const std::array<Eigen::Vector2d, kNumKeypoints>& keypoints, const std::string& hand);

// Mean over frames and keypoints of the second difference |k(t+1) - 2 k(t) + k(t-1)|:
// acceleration in metres per frame squared (0 for fewer than 3 frames). Compare an
// estimate's with its ground truth's own.
double Jitter(std::span<const Keypoints3d> frames);

// Jitter over several runs of consecutive frames (a track broken where the hand was lost):
// each run's Jitter weighted by its second differences, so that the runs count as one
// sequence of them. A run of fewer than 3 frames adds nothing.
class RunJitter {
 public:
  void Add(std::span<const Keypoints3d> run);
  bool empty() const { return count_ == 0; }
  double mean() const { return count_ > 0 ? sum_ / count_ : 0.0; }  // metres per frame squared

 private:
  double sum_ = 0.0;
  int count_ = 0;  // second differences
};

// An estimate's lag behind its truth: the shift of the truth, 0 to kMaxLag frames back, at
// which the keypoints about the wrist (RootRelativeError) agree best on average, over every
// frame with an estimate (shift s counts only the frames at least s into their sequence).
// A smoother that trails the motion agrees best with an earlier truth.
inline constexpr int kMaxLag = 8;
class LagMeter {
 public:
  // The next frame of the sequence: its truth, and the estimate if there is one.
  void Add(const Keypoints3d& truth, const Keypoints3d* estimate);
  // Before another sequence's first frame.
  void Restart() { truths_.clear(); }
  // The best shift, in frames; none before any estimate.
  std::optional<int> Lag() const;

 private:
  std::deque<Keypoints3d> truths_;  // the sequence's last kMaxLag + 1, the newest first
  std::array<double, kMaxLag + 1> error_{};
  std::array<int, kMaxLag + 1> count_{};
};

}  // namespace nphand
