#include "nphand/scene/viewpoint.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <Eigen/Geometry>
#include <flann/flann.hpp>

#include "nphand/util/check.h"

namespace nphand {
namespace {

// Neighbours of each direction among which the Voronoi vertices around it are sought.
constexpr size_t kCoverageNeighbours = 8;
// Probe directions that bound the covering radius where there are too few directions for that.
constexpr int kCoverageProbes = 2000;

}  // namespace


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
  const size_t n = directions.size();
  std::vector<double> points(3 * n);
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d d = directions[i].normalized();
    std::copy(d.data(), d.data() + 3, points.begin() + 3 * i);
  }
  flann::Index<flann::L2_Simple<double>> index(flann::Matrix<double>(points.data(), n, 3),
                                               flann::KDTreeSingleIndexParams(8));
  index.buildIndex();
  const auto point = [&](size_t i) { return Eigen::Vector3d(points[3 * i], points[3 * i + 1], points[3 * i + 2]); };
  const flann::SearchParams exact(flann::FLANN_CHECKS_UNLIMITED, 0.0f, true);

  // Each direction's nearest others (itself comes first).
  const int k = static_cast<int>(std::min<size_t>(kCoverageNeighbours + 1, n));
  std::vector<size_t> neighbours(n * k);
  std::vector<double> squared(n * k);
  flann::Matrix<size_t> neighbour_matrix(neighbours.data(), n, k);
  flann::Matrix<double> squared_matrix(squared.data(), n, k);
  index.knnSearch(flann::Matrix<double>(points.data(), n, 3), neighbour_matrix, squared_matrix, k, exact);

  ViewSphereCoverage coverage;
  for (size_t i = 0; i < n; ++i) {
    const size_t nearest = neighbours[i * k] == i ? neighbours[i * k + 1] : neighbours[i * k];
    coverage.max_neighbour_deg = std::max(coverage.max_neighbour_deg, angle(point(i).dot(point(nearest))));
  }
  // The farthest point of the sphere from every direction is a vertex of their spherical
  // Voronoi diagram: the circumcentre of three directions that are near each other. Each
  // candidate's distance to its nearest direction is a lower bound, exact at the vertex.
  double best_cos = 1.0;
  size_t nearest_index = 0;
  double nearest_squared = 0.0;
  flann::Matrix<size_t> one_index(&nearest_index, 1, 1);
  flann::Matrix<double> one_squared(&nearest_squared, 1, 1);
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d a = point(i);
    for (int u = 1; u < k; ++u) {
      for (int v = u + 1; v < k; ++v) {
        const Eigen::Vector3d b = point(neighbours[i * k + u]), c = point(neighbours[i * k + v]);
        Eigen::Vector3d centre = (b - a).cross(c - a);
        if (centre.norm() < 1e-12) continue;
        centre.normalize();
        if (centre.dot(a) < 0.0) centre = -centre;
        if (centre.dot(a) >= best_cos) continue;  // a is nearer than the farthest point found
        index.knnSearch(flann::Matrix<double>(centre.data(), 1, 3), one_index, one_squared, 1, exact);
        best_cos = std::min(best_cos, centre.dot(point(nearest_index)));
      }
    }
  }
  // A few directions (two, three) have no Voronoi vertices near them: probe a fixed lattice too.
  for (const Eigen::Vector3d& probe : ViewSphereDirections(kCoverageProbes)) {
    index.knnSearch(flann::Matrix<double>(const_cast<double*>(probe.data()), 1, 3), one_index, one_squared, 1, exact);
    best_cos = std::min(best_cos, probe.dot(point(nearest_index)));
  }
  coverage.covering_radius_deg = angle(best_cos);
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
