// Every method of the paper's comparison (Figs. 6, 7) behind one interface: the estimator
// (on masks or RGB, with any index), the NN-pose bound, the mean pose and the regressions.
//
// Methods see what the paper's experiments gave them: the hand's mask (the object leaves
// its hole; no forearm), noisy or clean. Every method answers in the frame's camera: a
// method that predicts a roll-normalised pose is turned back by the mask's roll and by the
// ray to the hand, as the estimator turns its neighbours.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <ostream>
#include <string>

#include <Eigen/Core>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "nphand/db/database.h"
#include "nphand/estimate/estimator.h"
#include "nphand/eval/pose_study.h"
#include "nphand/eval/regression.h"
#include "nphand/index/knn_index.h"
#include "nphand/model/hand_model.h"

namespace nphand {

struct MethodEstimate {
  bool detected = false;
  HandPose pose;  // in the frame's camera
  std::optional<std::array<Eigen::Vector2d, kNumKeypoints>> keypoints_2d;  // methods that place the hand
  // The method's own 3D keypoints (hand-centred, camera orientation, for a hand of the
  // database hand's length) where they are not the database hand's in `pose`: a hand of
  // estimated proportions.
  std::optional<Keypoints3d> keypoints_hand;
};

// One interface for every method of the comparison. Estimate sees the frame (for the
// methods that read RGB, and for the NN-pose bound, which reads the truth) and the mask
// to use (noisy or clean).
class PoseMethod {
 public:
  virtual ~PoseMethod() = default;
  virtual std::string Name() const = 0;
  // True when the method reads the RGB frame rather than the mask (noise does not apply).
  virtual bool FromRgb() const { return false; }
  // A new sequence.
  virtual void Reset() {}
  virtual MethodEstimate Estimate(const StudyFrame& frame, const cv::Mat& mask) = 0;
  // What was fitted or chosen, for reports.
  virtual nlohmann::json Describe() const { return nlohmann::json::object(); }
};

// The estimator (ProcessMask, or Process on the RGB frame with `from_rgb`). With
// options.prior kNone it is the paper's "NN feature".
std::unique_ptr<PoseMethod> MakeEstimatorMethod(const std::string& name, const Database& db, const KnnIndex& index,
                                                const HandModel& hand, const EstimatorOptions& options, bool from_rgb);
// The database entry nearest to the truth in pose space, turned by the mask's roll (either
// way round) and the ray to the hand: the lower bound of any method that answers with
// database entries (the database's resolution).
std::unique_ptr<PoseMethod> MakeNearestPoseMethod(const Database& db);
// The mean of the database's roll-normalised pose vectors, turned as above.
std::unique_ptr<PoseMethod> MakeMeanPoseMethod(const Database& db);
// A regressor from the descriptor to the roll-normalised pose vector, fitted on `rows`
// database entries with a hand drawn by `seed`, turned as above.
std::unique_ptr<PoseMethod> MakeRegressionMethod(const Database& db, std::unique_ptr<PoseRegressor> regressor, int rows,
                                                 uint64_t seed, std::ostream* progress);

}  // namespace nphand
