// The keypoint measures on cases with known answers: a moved, turned and scaled copy has
// no Procrustes error but a root-relative one, fractions and their area follow the
// distances, and jitter is zero for motion at constant speed.
#include "nphand/eval/measures.h"

#include <cmath>

#include <gtest/gtest.h>

#include "nphand/util/random.h"
#include "testing/testing.h"

namespace nphand {
namespace {

Keypoints3d RandomHand(Random& random) {
  Keypoints3d k;
  for (Eigen::Vector3d& p : k) p = Eigen::Vector3d(random.Uniform(-0.1, 0.1), random.Uniform(-0.1, 0.1), random.Uniform(0.3, 0.5));
  return k;
}

TEST(MeasuresTest, ASimilarCopyHasNoProcrustesErrorButARootRelativeOne) {
  Random random(testing::kTestSeed);
  const Keypoints3d truth = RandomHand(random);
  const Eigen::Matrix3d turn = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  Keypoints3d copy;
  for (int k = 0; k < kNumKeypoints; ++k) copy[k] = 1.2 * (turn * truth[k]) + Eigen::Vector3d(0.3, -0.1, 0.2);
  EXPECT_NEAR(ProcrustesError(copy, truth), 0.0, 1e-9);
  EXPECT_GT(RootRelativeError(copy, truth), 0.01);
  EXPECT_NEAR(RootRelativeError(truth, truth), 0.0, 1e-12);
  // Moved only: the root-relative error ignores it.
  Keypoints3d moved = truth;
  for (Eigen::Vector3d& p : moved) p += Eigen::Vector3d(0.5, 0.5, 0.5);
  EXPECT_NEAR(RootRelativeError(moved, truth), 0.0, 1e-12);
  // One keypoint 1 cm off: a 21st of a centimetre on average, root-relative.
  Keypoints3d off = truth;
  off[8] += Eigen::Vector3d(0.01, 0.0, 0.0);
  EXPECT_NEAR(RootRelativeError(off, truth), 0.01 / kNumKeypoints, 1e-12);
  // Alignment spreads that centimetre over every keypoint (it minimises squares, not the mean).
  EXPECT_GT(ProcrustesError(off, truth), 0.0);
  EXPECT_LT(ProcrustesError(off, truth), 0.01);
}

TEST(MeasuresTest, FractionsAndTheirAreaFollowTheDistances) {
  const std::vector<double> d = {0.0, 0.01, 0.02, 0.03, 0.06};
  EXPECT_DOUBLE_EQ(FractionWithin(d, 0.02), 0.6);
  EXPECT_DOUBLE_EQ(FractionWithin(d, 0.0), 0.2);
  EXPECT_DOUBLE_EQ(AreaUnderCurve(std::vector<double>(10, 0.0), 0.05), 1.0);
  EXPECT_DOUBLE_EQ(AreaUnderCurve(std::vector<double>(10, 0.2), 0.05), 0.0);
  // Distances spread evenly over the range: the curve is the diagonal, its area a half.
  std::vector<double> even;
  for (int i = 0; i < 1000; ++i) even.push_back(0.05 * (i + 0.5) / 1000.0);
  EXPECT_NEAR(AreaUnderCurve(even, 0.05), 0.5, 0.01);
  testing::ExpectError([&] { AreaUnderCurve(d, 0.0); }, "positive range");
  // A distance that is not a number counts as never within.
  const std::vector<double> with_nan = {0.0, std::nan("")};
  EXPECT_DOUBLE_EQ(FractionWithin(with_nan, 1.0), 0.5);
  EXPECT_DOUBLE_EQ(AreaUnderCurve(with_nan, 0.05), 0.5);
}

TEST(MeasuresTest, JitterIsTheMeanSecondDifference) {
  Random random(testing::kTestSeed);
  const Keypoints3d start = RandomHand(random);
  std::vector<Keypoints3d> steady, accelerating;
  for (int t = 0; t < 10; ++t) {
    Keypoints3d s = start, a = start;
    for (int k = 0; k < kNumKeypoints; ++k) {
      s[k] += Eigen::Vector3d(0.002 * t, 0.0, 0.0);
      a[k] += Eigen::Vector3d(0.0, 0.0005 * t * t, 0.0);  // second difference 0.001
    }
    steady.push_back(s);
    accelerating.push_back(a);
  }
  EXPECT_NEAR(Jitter(steady), 0.0, 1e-12);
  EXPECT_NEAR(Jitter(accelerating), 0.001, 1e-12);
  EXPECT_EQ(Jitter(std::vector<Keypoints3d>(2, start)), 0.0);
  // Runs weighted by their second differences: 8 steady and 2 of 0.001; a 2-frame run adds none.
  RunJitter runs;
  EXPECT_TRUE(runs.empty());
  runs.Add(steady);
  runs.Add(std::span(accelerating).first(4));
  runs.Add(std::span(accelerating).first(2));
  EXPECT_FALSE(runs.empty());
  EXPECT_NEAR(runs.mean(), 0.002 / 10.0, 1e-12);
}

// The lag: an estimate that is the truth of two frames before agrees best two frames back;
// frames without an estimate still give their truth; a new sequence does not reach into the
// last one.
TEST(MeasuresTest, TheLagIsTheShiftAtWhichTheTruthAgreesBest) {
  Random random(testing::kTestSeed);
  std::vector<Keypoints3d> truths;
  for (int t = 0; t < 20; ++t) truths.push_back(RandomHand(random));
  LagMeter none, exact, late;
  EXPECT_FALSE(none.Lag().has_value());
  for (int t = 0; t < 20; ++t) {
    none.Add(truths[t], nullptr);
    exact.Add(truths[t], &truths[t]);
    late.Add(truths[t], t >= 2 && t % 5 != 0 ? &truths[t - 2] : nullptr);
  }
  EXPECT_FALSE(none.Lag().has_value());
  EXPECT_EQ(exact.Lag(), 0);
  EXPECT_EQ(late.Lag(), 2);
  // A new sequence whose first estimate is the last sequence's last truth: one frame back
  // it would agree exactly, but that frame is another sequence's.
  LagMeter restarted, ran_on;
  for (LagMeter* m : {&restarted, &ran_on}) {
    for (int t = 0; t < 10; ++t) m->Add(truths[t], nullptr);
  }
  restarted.Restart();
  restarted.Add(truths[10], &truths[9]);
  ran_on.Add(truths[10], &truths[9]);
  EXPECT_EQ(restarted.Lag(), 0);
  EXPECT_EQ(ran_on.Lag(), 1);
}

TEST(MeasuresTest, MedianIsTheUpperMiddleValue) {
  EXPECT_EQ(Median({}), 0.0);
  EXPECT_EQ(Median({3.0, 1.0, 2.0}), 2.0);
  EXPECT_EQ(Median({4.0, 1.0, 3.0, 2.0}), 3.0);
}

}  // namespace
}  // namespace nphand
