// The One Euro filter: a still signal's noise is damped, a moving one is followed with less
// lag the larger beta or the trend, what cannot be filtered starts afresh, bad settings are
// refused.
#include "nphand/estimate/smoother.h"

#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "nphand/util/random.h"
#include "testing/testing.h"

namespace nphand {
namespace {

constexpr double kDt = 1.0 / 30.0;

// The mean absolute error of filtering `truth(t) + noise` at 30 frames/s, after a second.
double FilteredError(const SmoothOptions& options, double noise, double (*truth)(double)) {
  OneEuroFilter filter(options);
  Random random(testing::kTestSeed);
  double error = 0.0;
  int n = 0;
  for (int i = 0; i < 300; ++i) {
    const double t = i * kDt;
    Eigen::VectorXd x(1);
    x[0] = truth(t) + random.Uniform(-noise, noise);
    const double y = filter.Filter(x, 1.0, t)[0];
    if (i >= 30) {
      error += std::abs(y - truth(t));
      ++n;
    }
  }
  return error / n;
}

double Still(double) { return 0.5; }
double Ramp(double t) { return 2.0 * t; }

TEST(OneEuroFilterTest, AStillSignalsNoiseIsDamped) {
  // Uniform noise of +-0.1 errs by 0.05 on average. Filtered with the defaults, measured
  // 0.030 (the noise's own speed raises the cutoff); at 0.5 Hz, 0.019.
  EXPECT_LT(FilteredError({}, 0.1, Still), 0.04);
  SmoothOptions slow;
  slow.min_cutoff_hz = 0.5;
  EXPECT_LT(FilteredError(slow, 0.1, Still), 0.75 * FilteredError({}, 0.1, Still));
}

TEST(OneEuroFilterTest, AMovingSignalLagsLessTheLargerBeta) {
  SmoothOptions none, some;
  none.min_cutoff_hz = some.min_cutoff_hz = 0.5;
  none.beta = 0.0;
  some.beta = 5.0;
  // A ramp of 2 units/s: a 0.5 Hz low-pass lags it by 2 / (2 pi 0.5) = 0.64 units.
  EXPECT_NEAR(FilteredError(none, 0.0, Ramp), 0.64, 0.05);
  EXPECT_LT(FilteredError(some, 0.0, Ramp), 0.2 * FilteredError(none, 0.0, Ramp));
}

TEST(OneEuroFilterTest, ATrendFollowsASteadyMotionWithLessLag) {
  SmoothOptions none, half, whole;
  none.min_cutoff_hz = half.min_cutoff_hz = whole.min_cutoff_hz = 0.5;
  none.beta = half.beta = whole.beta = 0.0;
  half.trend = 0.5;
  whole.trend = 1.0;
  // On the ramp a trend lags by (1 - a)(1 - trend) / (a + (1 - a) trend) frames' motion, a
  // = 0.095 at 0.5 Hz: 0.83 frames (0.055 units) at 0.5, none at 1, against 9.5 frames
  // (0.64 units) without.
  EXPECT_NEAR(FilteredError(half, 0.0, Ramp), 0.055, 0.01);
  EXPECT_LT(FilteredError(whole, 0.0, Ramp), 0.005);
  // A still signal's noise (0.05 on average) is still damped, if less: the noise's own rate
  // is predicted on (measured 0.030 against 0.016 without the trend).
  EXPECT_LT(FilteredError(half, 0.1, Still), 0.04);
  EXPECT_LT(FilteredError(half, 0.1, Still), 2.2 * FilteredError(none, 0.1, Still));
}

TEST(OneEuroFilterTest, WhatCannotBeFilteredStartsAfresh) {
  OneEuroFilter filter;
  Eigen::VectorXd a(2), b(2), c(3);
  a << 1.0, 2.0;
  b << 3.0, 4.0;
  c << 5.0, 6.0, 7.0;
  EXPECT_EQ(filter.Filter(a, 1.0, 0.0), a);                 // the first value
  const Eigen::VectorXd moved = filter.Filter(b, 1.0, kDt);  // pulled towards the last
  EXPECT_GT(moved[0], 1.0);
  EXPECT_LT(moved[0], 3.0);
  EXPECT_EQ(filter.Filter(b, 1.0, kDt), b);       // no time passed
  EXPECT_EQ(filter.Filter(c, 1.0, 2 * kDt), c);   // another size
  filter.Reset();
  EXPECT_EQ(filter.Filter(a, 1.0, 3 * kDt), a);
  testing::ExpectError([&] { filter.Filter(a, 0.0, 4 * kDt); }, "scale must be positive");
  SmoothOptions bad;
  bad.min_cutoff_hz = 0.0;
  testing::ExpectError([&] { OneEuroFilter{bad}; }, "cutoffs must be within");
  bad = SmoothOptions{};
  bad.beta = -1.0;
  testing::ExpectError([&] { OneEuroFilter{bad}; }, "beta must be within");
  bad = SmoothOptions{};
  bad.trend = 1.5;
  testing::ExpectError([&] { OneEuroFilter{bad}; }, "trend must be within");
}

}  // namespace
}  // namespace nphand
