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
