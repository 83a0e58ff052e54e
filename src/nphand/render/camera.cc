#include "nphand/render/camera.h"

#include <cmath>

namespace nphand {

Intrinsics Intrinsics::FromFieldOfView(int width, int height, double fov_x_rad) {
  Intrinsics k;
  k.width = width;
  k.height = height;
  k.fx = k.fy = 0.5 * width / std::tan(0.5 * fov_x_rad);
  k.cx = 0.5 * width;
  k.cy = 0.5 * height;
  return k;
}

bool Intrinsics::Check(std::string* why) const {
  if (width <= 0 || height <= 0 || width > 16384 || height > 16384) {
    *why = "image size must be between 1 and 16384 pixels, got " + std::to_string(width) + "x" +
           std::to_string(height);
    return false;
  }
  if (!(fx > 0.0 && fy > 0.0 && std::isfinite(fx) && std::isfinite(fy) && std::isfinite(cx) && std::isfinite(cy))) {
    *why = "focal lengths must be positive and the principal point finite";
    return false;
  }
  return true;
}

Eigen::Vector2d Project(const Intrinsics& k, const Eigen::Vector3d& p) {
  return {k.fx * p.x() / p.z() + k.cx, k.fy * p.y() / p.z() + k.cy};
}

}  // namespace nphand
