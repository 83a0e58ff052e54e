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
  EXPECT_LT(coverage.covering_radius_deg, 6.0);
  EXPECT_LT(coverage.max_neighbour_deg, 9.0);
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
