#include "nphand/scene/viewpoint.h"

#include <numbers>

#include <gtest/gtest.h>

#include "testing/testing.h"

namespace nphand {
namespace {

TEST(ViewpointTest, CameraLooksAtTheHandFromItsDirectionWithFingersUp) {
  Random random(testing::kTestSeed);
  for (int trial = 0; trial < 200; ++trial) {
    Viewpoint view = RandomViewpoint(random);
    view.roll = 0.0;
    const Eigen::Matrix3d r = CameraFromHand(view);
    EXPECT_LT((r.transpose() * r - Eigen::Matrix3d::Identity()).norm(), 1e-12);
    EXPECT_NEAR(r.determinant(), 1.0, 1e-12);
    // The direction towards the camera maps to the camera's -z.
    EXPECT_LT((r * ViewDirection(view) - Eigen::Vector3d(0, 0, -1)).norm(), 1e-12);
    // The fingers (hand +x) point up in the image (camera -y) and not sideways.
    const Eigen::Vector3d fingers = r * Eigen::Vector3d::UnitX();
    if (std::abs(ViewDirection(view).x()) < 0.99) {
      EXPECT_LT(fingers.y(), 0.0);
      EXPECT_NEAR(fingers.x(), 0.0, 1e-12);
    }
  }
}

TEST(ViewpointTest, PalmViewAndRollTurnTheImage) {
  const Eigen::Matrix3d palm = CameraFromHand({0.0, 0.0, 0.0});
  // From the palm side, the back of the hand (+z) faces away from the camera.
  EXPECT_GT((palm * Eigen::Vector3d::UnitZ()).z(), 0.99);
  const Eigen::Matrix3d rolled = CameraFromHand({0.0, 0.0, std::numbers::pi / 2});
  const Eigen::Vector3d fingers = rolled * Eigen::Vector3d::UnitX();
  // A quarter turn counter-clockwise in the image takes "up" to "left".
  EXPECT_NEAR(fingers.x(), -1.0, 1e-12);
}

TEST(ViewpointTest, CentredWristPutsTheCentreOnTheOpticalAxis) {
  const Eigen::Matrix3d r = CameraFromHand({0.3, -0.2, 1.0});
  const Eigen::Vector3d centre(0.08, 0.01, -0.01);
  const Eigen::Vector3d wrist = CenteredWristPosition(r, centre, 0.5);
  EXPECT_LT((wrist + r * centre - Eigen::Vector3d(0, 0, 0.5)).norm(), 1e-12);
}

}  // namespace
}  // namespace nphand

namespace nphand {
namespace {

TEST(ViewSphereTest, DirectionsAreUnitDistinctAndCoverTheSphereEvenly) {
  const std::vector<Eigen::Vector3d> directions = ViewSphereDirections(648);
  ASSERT_EQ(directions.size(), 648u);
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& d : directions) {
    EXPECT_NEAR(d.norm(), 1.0, 1e-12);
    mean += d / 648.0;
  }
  EXPECT_LT(mean.norm(), 1e-3) << "no side of the hand is favoured";
  const ViewSphereCoverage coverage = MeasureCoverage(directions);
  // 648 equal caps of 4 pi / 648 sr have an angular radius of 4.5 degrees; a good lattice
  // leaves no point much further than that from a direction.
  EXPECT_GT(coverage.covering_radius_deg, 4.4);
  EXPECT_LT(coverage.covering_radius_deg, 6.5);
  EXPECT_LT(coverage.max_neighbour_deg, 9.0);
}

// The covering radius by brute force: the largest distance to the nearest direction over
// the circumcentres of every triple (the Voronoi vertices are among them).
double BruteCoveringRadiusDeg(const std::vector<Eigen::Vector3d>& d) {
  double best = 1.0;
  for (size_t a = 0; a < d.size(); ++a) {
    for (size_t b = a + 1; b < d.size(); ++b) {
      for (size_t c = b + 1; c < d.size(); ++c) {
        const Eigen::Vector3d normal = (d[b] - d[a]).cross(d[c] - d[a]).normalized();
        for (const Eigen::Vector3d& centre : {normal, Eigen::Vector3d(-normal)}) {
          double nearest = -1.0;
          for (const Eigen::Vector3d& x : d) nearest = std::max(nearest, centre.dot(x));
          best = std::min(best, nearest);
        }
      }
    }
  }
  return std::acos(best) * 180.0 / std::numbers::pi;
}

TEST(ViewSphereTest, CoverageMatchesBruteForce) {
  for (int n : {3, 4, 12, 40, 100}) {
    const std::vector<Eigen::Vector3d> directions = ViewSphereDirections(n);
    EXPECT_NEAR(MeasureCoverage(directions).covering_radius_deg, BruteCoveringRadiusDeg(directions), 1e-6) << n;
  }
  // Two directions an angle t apart leave the point opposite their middle, 180 - t/2 away;
  // with no Voronoi vertex to find, a probe lattice of 4.5-degree spacing comes near it.
  const std::vector<Eigen::Vector3d> two = ViewSphereDirections(2);
  const double t = std::acos(two[0].dot(two[1])) * 180.0 / std::numbers::pi;
  EXPECT_NEAR(MeasureCoverage(two).covering_radius_deg, 180.0 - t / 2, 3.0);
}

TEST(ViewSphereTest, CoverageOfManyDirectionsIsFast) {
  // 65535 directions (the most a database allows) took minutes when this was quadratic.
  const ViewSphereCoverage coverage = MeasureCoverage(ViewSphereDirections(65535));
  EXPECT_GT(coverage.covering_radius_deg, 0.4);
  EXPECT_LT(coverage.covering_radius_deg, 0.65);
}

TEST(ViewSphereTest, ViewpointFromDirectionInvertsViewDirection) {
  for (const Eigen::Vector3d& d : ViewSphereDirections(100)) {
    const Viewpoint v = ViewpointFromDirection(3.0 * d, 0.4);
    EXPECT_LT((ViewDirection(v) - d).norm(), 1e-12);
    EXPECT_EQ(v.roll, 0.4);
  }
}

}  // namespace
}  // namespace nphand
