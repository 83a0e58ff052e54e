#include "nphand/scene/viewpoint.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <Eigen/Geometry>

#include "nphand/util/check.h"

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

Viewpoint ViewpointFromDirection(const Eigen::Vector3d& direction, double roll) {
  const Eigen::Vector3d d = direction.normalized();
  return {std::atan2(d.x(), -d.z()), std::asin(std::clamp(d.y(), -1.0, 1.0)), roll};
}

std::vector<Eigen::Vector3d> ViewSphereDirections(int count) {
  NPHAND_THROW_CHECK(count > 0, "the view sphere needs at least one direction");
  const double golden_angle = std::numbers::pi * (3.0 - std::sqrt(5.0));
  std::vector<Eigen::Vector3d> directions(count);
  for (int i = 0; i < count; ++i) {
    const double z = 1.0 - (2.0 * i + 1.0) / count;
    const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    directions[i] = Eigen::Vector3d(r * std::cos(golden_angle * i), r * std::sin(golden_angle * i), z);
  }
  return directions;
}

ViewSphereCoverage MeasureCoverage(const std::vector<Eigen::Vector3d>& directions) {
  NPHAND_THROW_CHECK(directions.size() >= 2, "coverage needs at least two directions");
  const auto angle = [](double cosine) { return std::acos(std::clamp(cosine, -1.0, 1.0)) * 180.0 / std::numbers::pi; };
  ViewSphereCoverage coverage;
  for (size_t i = 0; i < directions.size(); ++i) {
    double nearest = -1.0;
    for (size_t j = 0; j < directions.size(); ++j) {
      if (j != i) nearest = std::max(nearest, directions[i].dot(directions[j]));
    }
    coverage.max_neighbour_deg = std::max(coverage.max_neighbour_deg, angle(nearest));
  }
  for (const Eigen::Vector3d& probe : ViewSphereDirections(static_cast<int>(50 * directions.size()))) {
    double nearest = -1.0;
    for (const Eigen::Vector3d& d : directions) nearest = std::max(nearest, probe.dot(d));
    coverage.covering_radius_deg = std::max(coverage.covering_radius_deg, angle(nearest));
  }
  return coverage;
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
