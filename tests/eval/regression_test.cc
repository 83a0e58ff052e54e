// The regression baselines on small problems with known answers: LSQ recovers a linear
// map, the GP interpolates a smooth function and prefers a longer length scale for a
// smoother one, the RVM fits the noisy sinc with few relevance vectors.
#include "nphand/eval/regression.h"

#include <cmath>

#include <gtest/gtest.h>

#include "nphand/util/random.h"
#include "testing/testing.h"

namespace nphand {
namespace {

Eigen::MatrixXd RandomMatrix(Eigen::Index rows, Eigen::Index cols, Random& random) {
  Eigen::MatrixXd m(rows, cols);
  for (Eigen::Index r = 0; r < rows; ++r) {
    for (Eigen::Index c = 0; c < cols; ++c) m(r, c) = random.Uniform(-1.0, 1.0);
  }
  return m;
}

// n points evenly spread over [low, high] (one column).
Eigen::MatrixXd Line(Eigen::Index n, double low, double high) {
  return Eigen::VectorXd::LinSpaced(n, low, high);
}

double Rms(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return std::sqrt((a - b).squaredNorm() / static_cast<double>(a.size()));
}

TEST(RegressionTest, LeastSquaresRecoversALinearMap) {
  Random random(testing::kTestSeed);
  const Eigen::MatrixXd x = RandomMatrix(200, 10, random), w = RandomMatrix(11, 3, random);
  auto affine = [&](const Eigen::MatrixXd& in) {
    return Eigen::MatrixXd((in * w.topRows(10)).rowwise() + w.row(10));
  };
  const std::unique_ptr<PoseRegressor> lsq = MakeLinearRegressor({.ridge = 0.0});
  lsq->Fit(x, affine(x));
  const Eigen::MatrixXd test = RandomMatrix(50, 10, random);
  EXPECT_LT(Rms(lsq->Predict(test), affine(test)), 1e-9);
  EXPECT_EQ(lsq->Name(), "LSQ");
}

TEST(RegressionTest, GaussianProcessInterpolatesAndChoosesItsScaleByTheEvidence) {
  const Eigen::MatrixXd x = Line(40, 0.0, 2.0 * std::numbers::pi);
  const Eigen::MatrixXd test = Line(57, 0.1, 2.0 * std::numbers::pi - 0.1);
  const std::unique_ptr<PoseRegressor> slow = MakeGaussianProcess(), fast = MakeGaussianProcess();
  slow->Fit(x, x.array().sin().matrix());
  fast->Fit(x, (4.0 * x.array()).sin().matrix());
  EXPECT_LT(Rms(slow->Predict(test), test.array().sin().matrix()), 0.01);
  EXPECT_LT(Rms(fast->Predict(test), (4.0 * test.array()).sin().matrix()), 0.05);
  EXPECT_GT(slow->Summary().length_scale, 2.0 * fast->Summary().length_scale)
      << "the smoother function is more probable under a longer length scale";
  EXPECT_TRUE(std::isfinite(slow->Summary().log_marginal));
}

TEST(RegressionTest, RvmFitsTheNoisySincWithFewRelevanceVectors) {
  Random random(testing::kTestSeed);
  const Eigen::MatrixXd x = Line(100, -10.0, 10.0);
  auto sinc = [](const Eigen::MatrixXd& in) {
    Eigen::MatrixXd out(in.rows(), 1);
    for (Eigen::Index i = 0; i < in.rows(); ++i) out(i, 0) = in(i, 0) == 0.0 ? 1.0 : std::sin(in(i, 0)) / in(i, 0);
    return out;
  };
  Eigen::MatrixXd y = sinc(x);
  for (Eigen::Index i = 0; i < y.rows(); ++i) y(i, 0) += 0.05 * random.Normal();
  const std::unique_ptr<PoseRegressor> rvm = MakeRvm({.length_scale = 0.4});
  rvm->Fit(x, y);
  const Eigen::MatrixXd test = Line(77, -9.5, 9.5);
  EXPECT_LT(Rms(rvm->Predict(test), sinc(test)), 0.05);
  EXPECT_LE(rvm->Summary().basis, 20) << "sparse: most basis functions pruned";
  EXPECT_GE(rvm->Summary().basis, 3);
  EXPECT_NEAR(rvm->Summary().noise_sd, 0.05, 0.03) << "the noise it estimates is the noise added";
}

TEST(RegressionTest, EveryMethodPredictsSeveralOutputs) {
  Random random(testing::kTestSeed);
  const Eigen::MatrixXd x = RandomMatrix(80, 3, random);
  Eigen::MatrixXd y(80, 2);
  y.col(0) = x.col(0) + 0.5 * x.col(1);
  y.col(1) = (x.col(2).array() * 2.0).sin().matrix();
  for (auto& method : {MakeLinearRegressor(), MakeGaussianProcess(), MakeRvm()}) {
    method->Fit(x, y);
    const Eigen::MatrixXd p = method->Predict(x.topRows(5));
    EXPECT_EQ(p.rows(), 5);
    EXPECT_EQ(p.cols(), 2);
    EXPECT_LT(Rms(p.col(0), y.col(0).head(5)), 0.2) << method->Name();
  }
}

TEST(RegressionTest, BadInputIsRefused) {
  const std::unique_ptr<PoseRegressor> gp = MakeGaussianProcess();
  testing::ExpectError([&] { gp->Predict(Eigen::MatrixXd::Zero(1, 3)); }, "predict before fit");
  testing::ExpectError([&] { gp->Fit(Eigen::MatrixXd::Zero(4, 3), Eigen::MatrixXd::Zero(3, 2)); }, "4 descriptors but 3 poses");
  Eigen::MatrixXd x = Eigen::MatrixXd::Random(6, 3);
  gp->Fit(x, x.leftCols(2));
  testing::ExpectError([&] { gp->Predict(Eigen::MatrixXd::Zero(1, 4)); }, "fitted on 3");
  x(0, 0) = std::nan("");
  testing::ExpectError([&] { MakeRvm()->Fit(x, Eigen::MatrixXd::Zero(6, 1)); }, "not a finite number");
  testing::ExpectError([] { MakeRvm({.iterations = 0}); }, "iterations");
  testing::ExpectError([] { MakeGaussianProcess({.length_scales = {}}); }, "length scales");
  testing::ExpectError([] { MakeLinearRegressor({.ridge = -1.0}); }, "ridge");
}

}  // namespace
}  // namespace nphand
