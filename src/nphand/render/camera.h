// Pinhole camera intrinsics and projection. Camera frame: x right, y down, z forward;
// pixel (0, 0) is the top-left pixel, whose centre is at (0.5, 0.5).
#pragma once

#include <string>

#include <Eigen/Core>

namespace nphand {

struct Intrinsics {
  int width = 128;        // pixels
  int height = 128;
  double fx = 256.0;      // focal lengths in pixels
  double fy = 256.0;
  double cx = 64.0;       // principal point in pixels
  double cy = 64.0;

  // A camera of the given size with the principal point at the image centre and a
  // horizontal field of view of `fov_x_rad`.
  static Intrinsics FromFieldOfView(int width, int height, double fov_x_rad);
  // False (with the reason) for a non-positive size or focal length or a size over 16384.
  bool Check(std::string* why) const;
};

// The pixel position of a point in the camera frame (z > 0).
Eigen::Vector2d Project(const Intrinsics& intrinsics, const Eigen::Vector3d& point_in_camera);

}  // namespace nphand
