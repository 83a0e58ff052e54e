// Smoothing a track's estimates over time: the One Euro filter (Casiez, Roussel and Vogel,
// CHI 2012), the low-pass filter whose cutoff rises with the signal's speed, so that a
// still hand stops shaking and a moving one does not lag. Each group of numbers (the
// keypoints about the wrist, in the camera, in the image; the joint angles; the wrist's
// quaternion) is filtered with one cutoff, from the group's speed in its own scale.
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
