#include "nphand/eval/pose_methods.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>

#include <Eigen/Geometry>
#include <opencv2/imgproc.hpp>

#include "nphand/features/crop.h"
#include "nphand/features/descriptor.h"
#include "nphand/util/check.h"
#include "nphand/util/random.h"

namespace nphand {
namespace {

using Clock = std::chrono::steady_clock;

Eigen::Matrix3d RotationOf(const PoseVector& x) {
  Eigen::Matrix3d r;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) r(i, j) = x[3 * i + j];
  }
  return r;
}

void SetRotation(const Eigen::Matrix3d& r, PoseVector* x) {
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) (*x)[3 * i + j] = r(i, j);
  }
}

// What the mask-reading methods take from a mask: the crop and descriptor the database
// would have made, and the rotation from the camera's axis to the ray through the hand.
struct MaskView {
  HandCrop crop;
  Descriptor descriptor;
  Eigen::Matrix3d towards_ray;
};

std::optional<MaskView> ViewOf(const cv::Mat& mask, const DescriptorConfig& config, const Intrinsics& camera) {
  const cv::Rect box = cv::boundingRect(mask);
  if (box.area() == 0) return std::nullopt;
  const cv::Rect roi = cv::Rect(box.x - 2, box.y - 2, box.width + 4, box.height + 4) & cv::Rect(0, 0, mask.cols, mask.rows);
  const std::optional<HandCrop> crop = CropHand(mask(roi) != 0, config.Crop());
  if (!crop) return std::nullopt;
  MaskView view{*crop, DescribeCrop(*crop, config), Eigen::Matrix3d::Identity()};
  const cv::Moments m = cv::moments(mask, true);
  const Eigen::Vector3d ray =
      Eigen::Vector3d((m.m10 / m.m00 + 0.5 - camera.cx) / camera.fx, (m.m01 / m.m00 + 0.5 - camera.cy) / camera.fy, 1.0)
          .normalized();
  view.towards_ray = Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), ray).toRotationMatrix();
  return view;
}

// A roll-normalised pose vector seen in the frame: turned by `roll` and towards the ray.
HandPose PoseInFrame(const PoseVector& normalised, double roll, const Eigen::Matrix3d& towards_ray) {
  HandPose pose = FromPoseVector(normalised, Handedness::kRight);
  pose.camera_from_hand = towards_ray * AxisAngle(Eigen::Vector3d::UnitZ(), roll) * pose.camera_from_hand;
  return pose;
}

// Every entry with a hand: its pose vector with the rotation roll-normalised
// (Rz(-roll) R, the frame the descriptor was computed in).
struct NormalisedPoses {
  std::vector<entry_id_t> ids;
  Eigen::MatrixXd x;  // kPoseVectorSize x ids.size()
};

NormalisedPoses NormalisedPosesOf(const Database& db) {
  NormalisedPoses out;
  out.ids = DatabaseHandIds(db);
  out.x.resize(kPoseVectorSize, static_cast<Eigen::Index>(out.ids.size()));
  size_t row = 0;
  ScanRecords(db, [&](size_t i) {
    if (row >= out.ids.size() || out.ids[row] != i) return;
    PoseVector x = db.Pose(i);
    SetRotation(AxisAngle(Eigen::Vector3d::UnitZ(), -db.Meta(i).roll) * RotationOf(x), &x);
    out.x.col(static_cast<Eigen::Index>(row++)) = x;
  });
  NPHAND_CHECK(row == out.ids.size(), "database entries changed while read");
  return out;
}

class EstimatorMethod : public PoseMethod {
 public:
  EstimatorMethod(std::string name, const Database& db, const KnnIndex& index, const HandModel& hand,
                  const EstimatorOptions& options, bool from_rgb)
      : name_(std::move(name)), estimator_(db, index, hand, options), from_rgb_(from_rgb), backend_(index.Backend()) {}
  std::string Name() const override { return name_; }
  bool FromRgb() const override { return from_rgb_; }
  void Reset() override { estimator_.Reset(); }
  MethodEstimate Estimate(const StudyFrame& frame, const cv::Mat& mask) override {
    const FrameResult r = from_rgb_ ? estimator_.Process(frame.truth.rgb, frame.truth.time_s)
                                    : estimator_.ProcessMask(mask, frame.truth.time_s);
    MethodEstimate out;
    out.detected = r.detected();
    if (out.detected) {
      out.pose = r.pose;
      out.keypoints_2d = r.keypoints_2d;
      if (r.proportions.has_value()) out.keypoints_hand = r.keypoints_hand;
    }
    return out;
  }
  nlohmann::json Describe() const override {
    const EstimatorOptions& o = estimator_.options();
    return {{"index", backend_},         {"k", o.k},           {"observation", ToString(o.observation)},
            {"sigma_y", o.sigma_y},      {"prior", ToString(o.prior)}, {"sigma_x", o.sigma_x},
            {"carried", o.carried},      {"mode_mean", o.mode_mean},   {"input", from_rgb_ ? "rgb" : "mask"},
            {"refine", RefinementJson(o)},
            {"smooth", SmoothingJson(o)}};
  }

 private:
  std::string name_;
  Estimator estimator_;
  bool from_rgb_;
  std::string backend_;
};

class NearestPoseMethod : public PoseMethod {
 public:
  explicit NearestPoseMethod(const Database& db) : config_(db.descriptor()), poses_(NormalisedPosesOf(db)) {}
  std::string Name() const override { return "NN pose"; }
  MethodEstimate Estimate(const StudyFrame& frame, const cv::Mat& mask) override {
    const std::optional<MaskView> view = ViewOf(mask, config_, frame.intrinsics);
    if (!view) return {};
    const PoseVector truth = ToPoseVector(frame.truth.pose);
    // |A N - R| = |N - A^T R| for a rotation A: the truth is brought into each turn's
    // normalised frame once, instead of every entry into the frame.
    double best = std::numeric_limits<double>::infinity();
    PoseVector best_x = PoseVector::Zero();
    double best_roll = 0.0;
    for (double roll : {view->crop.roll, view->crop.roll + std::numbers::pi}) {
      PoseVector target = truth;
      SetRotation((view->towards_ray * AxisAngle(Eigen::Vector3d::UnitZ(), roll)).transpose() * RotationOf(truth), &target);
      Eigen::Index at = 0;
      const double d = (poses_.x.colwise() - target).colwise().squaredNorm().minCoeff(&at);
      if (d < best) {
        best = d;
        best_x = poses_.x.col(at);
        best_roll = roll;
      }
    }
    return {true, PoseInFrame(best_x, best_roll, view->towards_ray), std::nullopt, std::nullopt};
  }

 private:
  DescriptorConfig config_;
  NormalisedPoses poses_;
};

class MeanPoseMethod : public PoseMethod {
 public:
  explicit MeanPoseMethod(const Database& db) : config_(db.descriptor()), mean_(NormalisedPosesOf(db).x.rowwise().mean()) {}
  std::string Name() const override { return "mean pose"; }
  MethodEstimate Estimate(const StudyFrame& frame, const cv::Mat& mask) override {
    const std::optional<MaskView> view = ViewOf(mask, config_, frame.intrinsics);
    if (!view) return {};
    return {true, PoseInFrame(mean_, view->crop.roll, view->towards_ray), std::nullopt, std::nullopt};
  }

 private:
  DescriptorConfig config_;
  PoseVector mean_;
};

class RegressionMethod : public PoseMethod {
 public:
  RegressionMethod(const Database& db, std::unique_ptr<PoseRegressor> regressor, int rows, uint64_t seed,
                   std::ostream* progress)
      : config_(db.descriptor()), regressor_(std::move(regressor)) {
    const NormalisedPoses poses = NormalisedPosesOf(db);
    NPHAND_THROW_CHECK(rows >= 2 && static_cast<size_t>(rows) <= poses.ids.size(), regressor_->Name(),
                       ": the fit needs 2..", poses.ids.size(), " rows, not ", rows);
    // Rows drawn without replacement (a partial Fisher-Yates shuffle), then in file order.
    std::vector<size_t> order(poses.ids.size());
    for (size_t i = 0; i < order.size(); ++i) order[i] = i;
    Random random(seed);
    for (int i = 0; i < rows; ++i) std::swap(order[i], order[i + random.UniformIndex(order.size() - i)]);
    order.resize(rows);
    std::sort(order.begin(), order.end());
    std::vector<entry_id_t> ids;
    for (size_t r : order) ids.push_back(poses.ids[r]);
    const int d = config_.Dimension();
    Eigen::MatrixXd x(rows, d), y(rows, kPoseVectorSize);
    ForEachRow(db, ids, [&](size_t row, std::span<const float> hog) {
      for (int c = 0; c < d; ++c) x(static_cast<Eigen::Index>(row), c) = hog[c];
    });
    for (int r = 0; r < rows; ++r) y.row(r) = poses.x.col(static_cast<Eigen::Index>(order[r])).transpose();
    const Clock::time_point start = Clock::now();
    if (progress != nullptr) *progress << regressor_->Name() << ": fitting on " << rows << " entries\n";
    regressor_->Fit(x, y);
    fit_seconds_ = std::chrono::duration<double>(Clock::now() - start).count();
    rows_ = rows;
  }
  std::string Name() const override { return regressor_->Name(); }
  MethodEstimate Estimate(const StudyFrame& frame, const cv::Mat& mask) override {
    const std::optional<MaskView> view = ViewOf(mask, config_, frame.intrinsics);
    if (!view) return {};
    Eigen::MatrixXd x(1, config_.Dimension());
    for (int c = 0; c < config_.Dimension(); ++c) x(0, c) = view->descriptor.values[c];
    const PoseVector predicted = regressor_->Predict(x).row(0).transpose();
    return {true, PoseInFrame(predicted, view->crop.roll, view->towards_ray), std::nullopt, std::nullopt};
  }
  nlohmann::json Describe() const override {
    const RegressorSummary s = regressor_->Summary();
    return {{"rows", rows_},
            {"fit_s", fit_seconds_},
            {"length_scale", s.length_scale},
            {"noise_sd", s.noise_sd},
            {"log_marginal", s.log_marginal},
            {"basis", s.basis},
            {"iterations", s.iterations}};
  }

 private:
  DescriptorConfig config_;
  std::unique_ptr<PoseRegressor> regressor_;
  int rows_ = 0;
  double fit_seconds_ = 0.0;
};

}  // namespace

std::unique_ptr<PoseMethod> MakeEstimatorMethod(const std::string& name, const Database& db, const KnnIndex& index,
                                                const HandModel& hand, const EstimatorOptions& options, bool from_rgb) {
  return std::make_unique<EstimatorMethod>(name, db, index, hand, options, from_rgb);
}

std::unique_ptr<PoseMethod> MakeNearestPoseMethod(const Database& db) { return std::make_unique<NearestPoseMethod>(db); }

std::unique_ptr<PoseMethod> MakeMeanPoseMethod(const Database& db) { return std::make_unique<MeanPoseMethod>(db); }

std::unique_ptr<PoseMethod> MakeRegressionMethod(const Database& db, std::unique_ptr<PoseRegressor> regressor, int rows,
                                                 uint64_t seed, std::ostream* progress) {
  return std::make_unique<RegressionMethod>(db, std::move(regressor), rows, seed, progress);
}

}  // namespace nphand
