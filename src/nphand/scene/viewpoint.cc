#include "nphand/scene/viewpoint.h"

#include <cmath>
#include <numbers>

#include <Eigen/Geometry>

namespace nphand {

Viewpoint RandomViewpoint(Random& random) {
  const double azimuth = random.Uniform(-std::numbers::pi, std::numbers::pi);
  const double elevation = std::asin(random.Uniform(-1.0, 1.0));
  return {azimuth, elevation, random.Uniform(-std::numbers::pi, std::numbers::pi)};
}

Eigen::Vector3d ViewDirection(const Viewpoint& viewpoint) {
  const double ce = std::cos(viewpoint.elevation);
  return {std::sin(viewpoint.azimuth) * ce, std::sin(viewpoint.elevation), -std::cos(viewpoint.azimuth) * ce};
}

Eigen::Matrix3d CameraFromHand(const Viewpoint& viewpoint) {
  const Eigen::Vector3d forward = -ViewDirection(viewpoint);  // camera z, in the hand frame
  // Image "up" is -y of the camera; aim it along the fingers unless looking along them.
  Eigen::Vector3d up = Eigen::Vector3d::UnitX() - forward * forward.x();
  if (up.norm() < 1e-6) up = Eigen::Vector3d::UnitY() - forward * forward.y();
  up.normalize();
  Eigen::Matrix3d hand_from_camera;
  hand_from_camera.col(1) = -up;
  hand_from_camera.col(2) = forward;
  hand_from_camera.col(0) = hand_from_camera.col(1).cross(hand_from_camera.col(2));
  const Eigen::Matrix3d roll = Eigen::AngleAxisd(viewpoint.roll, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return roll.transpose() * hand_from_camera.transpose();
}

Eigen::Vector3d CenteredWristPosition(const Eigen::Matrix3d& camera_from_hand, const Eigen::Vector3d& centre_in_hand,
                                      double distance) {
  return Eigen::Vector3d(0.0, 0.0, distance) - camera_from_hand * centre_in_hand;
}

}  // namespace nphand
