// Smoothing a track's estimates over time: the One Euro filter (Casiez, Roussel and Vogel,
// CHI 2012), the low-pass filter whose cutoff rises with the signal's speed, so that a
// still hand stops shaking and a moving one does not lag. Each group of numbers (the
// keypoints about the wrist, in the camera, in the image; the joint angles; the wrist's
// quaternion) is filtered with one cutoff, from the group's speed in its own scale. With a
// trend, each value is first predicted from the filter's smoothed rate (after Holt's double
// exponential smoothing): a steady motion is then followed with less lag at a lower cutoff,
// none with the whole trend, at the price of an overshoot after a step.
#pragma once

#include <optional>
#include <string>

#include <Eigen/Core>

namespace nphand {

// The defaults are the validation sweep's choice (docs/estimator.md).
struct SmoothOptions {
  double min_cutoff_hz = 4.0;  // the cutoff of a still signal
  double beta = 0.5;           // the cutoff's rise per unit of speed (the group's scale per second)
  double derivative_cutoff_hz = 1.0;
  // How far each value is predicted from the last by the smoothed rate before the new one
  // is weighed in: 0 (the One Euro filter as published) to 1 (the whole rate). On a ramp
  // the filter lags by (1 - a)(1 - trend) / (a + (1 - a) trend) frames' motion, a the new
  // value's weight: 0 with trend 1 (the rate is measured against the last filtered value,
  // so it holds the lag too). A step is overshot: at 2 Hz with trend 0.5 and beta 0, by 13 %
  // eight frames after it at 30 frames/s, gone after about 20.
  double trend = 0.0;
  bool Check(std::string* why) const;
};

class OneEuroFilter {
 public:
  explicit OneEuroFilter(const SmoothOptions& options = {});

  // The filtered `x` at `time_s`. `scale` is the group's size (e.g. the hand's length for
  // its keypoints): its speed is the RMS of its numbers' rates over it. The first value, a
  // value of another size, or a time not after the last start afresh and come back as they
  // are. Throws nphand::Error for a scale that is not positive.
  Eigen::VectorXd Filter(const Eigen::VectorXd& x, double scale, double time_s);
  void Reset() { last_.reset(); }
  // The last filtered value, if any since the last start.
  const Eigen::VectorXd* last() const { return last_.has_value() ? &last_->x : nullptr; }

 private:
  struct State {
    Eigen::VectorXd x, rate;
    double time_s;
  };
  SmoothOptions options_;
  std::optional<State> last_;
};

}  // namespace nphand
