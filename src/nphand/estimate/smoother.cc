#include "nphand/estimate/smoother.h"

#include <cmath>
#include <numbers>

#include "nphand/util/check.h"

namespace nphand {
namespace {

// The weight of the new value in an exponential smoother with cutoff `hz`, `dt` apart.
double Alpha(double hz, double dt) {
  const double tau = 1.0 / (2.0 * std::numbers::pi * hz);
  return 1.0 / (1.0 + tau / dt);
}

}  // namespace

bool SmoothOptions::Check(std::string* why) const {
  if (!(min_cutoff_hz > 0.0 && min_cutoff_hz <= 1000.0) || !(derivative_cutoff_hz > 0.0 && derivative_cutoff_hz <= 1000.0)) {
    *why = "the smoothing's cutoffs must be within (0, 1000] Hz";
    return false;
  }
  if (!(beta >= 0.0 && beta <= 1000.0)) {
    *why = "the smoothing's beta must be within [0, 1000]";
    return false;
  }
  if (!(trend >= 0.0 && trend <= 1.0)) {
    *why = "the smoothing's trend must be within [0, 1]";
    return false;
  }
  return true;
}

OneEuroFilter::OneEuroFilter(const SmoothOptions& options) : options_(options) {
  std::string why;
  NPHAND_THROW_CHECK(options.Check(&why), "smoothing: ", why);
}

Eigen::VectorXd OneEuroFilter::Filter(const Eigen::VectorXd& x, double scale, double time_s) {
  NPHAND_THROW_CHECK(scale > 0.0 && std::isfinite(scale), "smoothing: a group's scale must be positive");
  if (!last_.has_value() || last_->x.size() != x.size() || !(time_s > last_->time_s)) {
    last_ = State{x, Eigen::VectorXd::Zero(x.size()), time_s};
    return x;
  }
  const double dt = time_s - last_->time_s;
  const Eigen::VectorXd rate = (x - last_->x) / dt;
  const Eigen::VectorXd smooth_rate = last_->rate + Alpha(options_.derivative_cutoff_hz, dt) * (rate - last_->rate);
  const double speed = x.size() > 0 ? smooth_rate.norm() / std::sqrt(static_cast<double>(x.size())) / scale : 0.0;
  const double cutoff = options_.min_cutoff_hz + options_.beta * speed;
  const Eigen::VectorXd predicted = last_->x + options_.trend * dt * last_->rate;
  const Eigen::VectorXd out = predicted + Alpha(cutoff, dt) * (x - predicted);
  last_ = State{out, smooth_rate, time_s};
  return out;
}

}  // namespace nphand
