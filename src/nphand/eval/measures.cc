#include "nphand/eval/measures.h"

#include <algorithm>
#include <cmath>
#include <iterator>

#include <Eigen/Geometry>

#include "nphand/util/check.h"

namespace nphand {

double Median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  return values[values.size() / 2];
}
namespace {

// The standard keypoints FacingOf reads.
constexpr int kWristKeypoint = 0, kIndexMcpKeypoint = 5, kLittleMcpKeypoint = 17;

Eigen::Matrix3Xd Columns(const Keypoints3d& keypoints) {
  Eigen::Matrix3Xd m(3, kNumKeypoints);
  for (int k = 0; k < kNumKeypoints; ++k) m.col(k) = keypoints[k];
  return m;
}

}  // namespace

std::vector<double> RootRelativeDistances(const Keypoints3d& estimate, const Keypoints3d& truth) {
  std::vector<double> distances(kNumKeypoints);
  for (int k = 0; k < kNumKeypoints; ++k) {
    distances[k] = ((estimate[k] - estimate[0]) - (truth[k] - truth[0])).norm();
  }
  return distances;
}

double RootRelativeError(const Keypoints3d& estimate, const Keypoints3d& truth) {
  const std::vector<double> d = RootRelativeDistances(estimate, truth);
  double sum = 0.0;
  for (double v : d) sum += v;
  return sum / kNumKeypoints;
}

double ProcrustesError(const Keypoints3d& estimate, const Keypoints3d& truth) {
  const Eigen::Matrix3Xd from = Columns(estimate), to = Columns(truth);
  const Eigen::Matrix4d similarity = Eigen::umeyama(from, to, true);
  const Eigen::Matrix3Xd aligned = (similarity.topLeftCorner<3, 3>() * from).colwise() + similarity.topRightCorner<3, 1>();
  return (aligned - to).colwise().norm().mean();
}

double FractionWithin(std::span<const double> distances, double threshold) {
  if (distances.empty()) return 0.0;
  return static_cast<double>(std::count_if(distances.begin(), distances.end(), [&](double d) { return d <= threshold; })) /
         static_cast<double>(distances.size());
}

double AreaUnderCurve(std::span<const double> distances, double max, int steps) {
  NPHAND_THROW_CHECK(max > 0.0 && steps >= 1, "AUC: needs a positive range and at least one step");
  // A distance that is not a number is never within (and must stay out of the sort).
  std::vector<double> sorted;
  std::copy_if(distances.begin(), distances.end(), std::back_inserter(sorted), [](double d) { return !std::isnan(d); });
  std::sort(sorted.begin(), sorted.end());
  auto within = [&](double t) {
    if (distances.empty()) return 0.0;
    return static_cast<double>(std::upper_bound(sorted.begin(), sorted.end(), t) - sorted.begin()) /
           static_cast<double>(distances.size());
  };
  double area = 0.0, previous = within(0.0);
  for (int s = 1; s <= steps; ++s) {
    const double next = within(max * s / steps);
    area += 0.5 * (previous + next) / steps;
    previous = next;
  }
  return area;
}

double Jitter(std::span<const Keypoints3d> frames) {
  if (frames.size() < 3) return 0.0;
  double sum = 0.0;
  for (size_t t = 1; t + 1 < frames.size(); ++t) {
    for (int k = 0; k < kNumKeypoints; ++k) sum += (frames[t + 1][k] - 2.0 * frames[t][k] + frames[t - 1][k]).norm();
  }
  return sum / (static_cast<double>(frames.size() - 2) * kNumKeypoints);
}

void RunJitter::Add(std::span<const Keypoints3d> run) {
  if (run.size() < 3) return;
  const int n = static_cast<int>(run.size()) - 2;
  sum_ += Jitter(run) * n;
  count_ += n;
}

void LagMeter::Add(const Keypoints3d& truth, const Keypoints3d* estimate) {
  truths_.push_front(truth);
  if (truths_.size() > kMaxLag + 1) truths_.pop_back();
  if (estimate == nullptr) return;
  for (size_t lag = 0; lag < truths_.size(); ++lag) {
    error_[lag] += RootRelativeError(*estimate, truths_[lag]);
    ++count_[lag];
  }
}

std::optional<int> LagMeter::Lag() const {
  std::optional<int> best;
  double least = 0.0;
  for (int lag = 0; lag <= kMaxLag; ++lag) {
    if (count_[lag] == 0) continue;
    const double mean = error_[lag] / count_[lag];
    if (!best || mean < least) {
      best = lag;
      least = mean;
    }
  }
  return best;
}

Facing FacingOf(const std::optional<Eigen::Vector2d>& wrist, const std::optional<Eigen::Vector2d>& index_mcp,
                const std::optional<Eigen::Vector2d>& little_mcp, const std::string& hand) {
  if (!wrist || !index_mcp || !little_mcp || (hand != "left" && hand != "right")) return Facing::kUnknown;
  const Eigen::Vector2d a = *index_mcp - *wrist, b = *little_mcp - *wrist;
  const double lengths = a.norm() * b.norm();
  if (lengths <= 0.0) return Facing::kUnknown;
  // Image y points down: a turn that looks counter-clockwise has a negative cross product.
  const double sine = (a.x() * b.y() - a.y() * b.x()) / lengths;
  if (std::abs(sine) < kEdgeOnSine) return Facing::kUnknown;
  return (sine < 0.0) == (hand == "right") ? Facing::kPalm : Facing::kBack;
}

Facing FacingOf(const std::array<std::optional<Eigen::Vector2d>, kNumKeypoints>& keypoints, const std::string& hand) {
  return FacingOf(keypoints[kWristKeypoint], keypoints[kIndexMcpKeypoint], keypoints[kLittleMcpKeypoint], hand);
}

Facing FacingOf(const std::array<Eigen::Vector2d, kNumKeypoints>& keypoints, const std::string& hand) {
  return FacingOf(keypoints[kWristKeypoint], keypoints[kIndexMcpKeypoint], keypoints[kLittleMcpKeypoint], hand);
}

}  // namespace nphand
