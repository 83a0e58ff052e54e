#include "nphand/render/rasterizer.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

#include "nphand/util/check.h"

namespace nphand {
namespace {

constexpr int kSubpixelBits = 8;
constexpr int64_t kOne = int64_t{1} << kSubpixelBits;
constexpr int64_t kHalf = kOne / 2;
// Triangles with a vertex projected beyond this many pixels are not drawn: it keeps the
// edge functions' products (2^31 x 2^31 at most) within int64, and such vertices only come
// from surfaces grazing the camera plane.
constexpr double kMaxCoordinate = double{1 << 22};

struct FixedVertex {
  int64_t x, y;
  float inverse_z;
  float intensity;
};

// Edge function of a -> b at p: twice the signed area of (a, b, p). DrawTriangle orders
// the vertices so that the interior is where all three edge functions are positive.
int64_t Edge(const FixedVertex& a, const FixedVertex& b, int64_t px, int64_t py) {
  return (b.x - a.x) * (py - a.y) - (b.y - a.y) * (px - a.x);
}

// Pixel centres exactly on a top or left edge belong to the triangle; on others they don't.
int64_t FillBias(const FixedVertex& a, const FixedVertex& b) {
  const int64_t dx = b.x - a.x, dy = b.y - a.y;
  return (dy < 0 || (dy == 0 && dx > 0)) ? 0 : -1;
}

template <bool kShading>
void DrawTriangle(FixedVertex v0, FixedVertex v1, FixedVertex v2, uint8_t label, RasterTarget* target) {
  int64_t area = Edge(v0, v1, v2.x, v2.y);
  if (area == 0) return;
  if (area < 0) {
    std::swap(v1, v2);
    area = -area;
  }
  const int64_t min_x = std::min({v0.x, v1.x, v2.x}), max_x = std::max({v0.x, v1.x, v2.x});
  const int64_t min_y = std::min({v0.y, v1.y, v2.y}), max_y = std::max({v0.y, v1.y, v2.y});
  // Pixels whose centre (x + 1/2) may lie inside the bounding box.
  const int64_t x_begin = std::max<int64_t>(0, (min_x - kHalf + kOne - 1) >> kSubpixelBits);
  const int64_t x_end = std::min<int64_t>(target->width - 1, (max_x - kHalf) >> kSubpixelBits);
  const int64_t y_begin = std::max<int64_t>(0, (min_y - kHalf + kOne - 1) >> kSubpixelBits);
  const int64_t y_end = std::min<int64_t>(target->height - 1, (max_y - kHalf) >> kSubpixelBits);
  if (x_begin > x_end || y_begin > y_end) return;

  const int64_t bias0 = FillBias(v1, v2), bias1 = FillBias(v2, v0), bias2 = FillBias(v0, v1);
  const int64_t px0 = x_begin * kOne + kHalf, py0 = y_begin * kOne + kHalf;
  int64_t row0 = Edge(v1, v2, px0, py0) + bias0;
  int64_t row1 = Edge(v2, v0, px0, py0) + bias1;
  int64_t row2 = Edge(v0, v1, px0, py0) + bias2;
  // Steps of each edge function per pixel in x and in y.
  const int64_t step_x0 = -(v2.y - v1.y) * kOne, step_y0 = (v2.x - v1.x) * kOne;
  const int64_t step_x1 = -(v0.y - v2.y) * kOne, step_y1 = (v0.x - v2.x) * kOne;
  const int64_t step_x2 = -(v1.y - v0.y) * kOne, step_y2 = (v1.x - v0.x) * kOne;
  const float inverse_area = 1.0f / static_cast<float>(area);

  for (int64_t y = y_begin; y <= y_end; ++y) {
    int64_t e0 = row0, e1 = row1, e2 = row2;
    const size_t row_offset = static_cast<size_t>(y) * target->width;
    for (int64_t x = x_begin; x <= x_end; ++x) {
      if ((e0 | e1 | e2) >= 0) {
        // Undo the bias for the barycentric weights.
        const float w0 = static_cast<float>(e0 - bias0) * inverse_area;
        const float w1 = static_cast<float>(e1 - bias1) * inverse_area;
        const float w2 = 1.0f - w0 - w1;
        const float inverse_z = w0 * v0.inverse_z + w1 * v1.inverse_z + w2 * v2.inverse_z;
        const size_t i = row_offset + static_cast<size_t>(x);
        if (inverse_z > target->inverse_depth[i]) {
          target->inverse_depth[i] = inverse_z;
          target->label[i] = label;
          if constexpr (kShading) {
            target->shade[i] = w0 * v0.intensity + w1 * v1.intensity + w2 * v2.intensity;
          }
        }
      }
      e0 += step_x0;
      e1 += step_x1;
      e2 += step_x2;
    }
    row0 += step_y0;
    row1 += step_y1;
    row2 += step_y2;
  }
}

}  // namespace

void RasterTarget::Reset(int new_width, int new_height, bool shading) {
  width = new_width;
  height = new_height;
  const size_t n = static_cast<size_t>(width) * height;
  inverse_depth.assign(n, 0.0f);
  label.assign(n, 0);
  if (shading) {
    shade.assign(n, 0.0f);
  } else {
    shade.clear();
  }
}

void RasterizeTriangles(const Intrinsics& k, std::span<const Eigen::Vector3f> vertices,
                        std::span<const Eigen::Vector3i> triangles, std::span<const float> intensity,
                        uint8_t label, Faces faces, RasterTarget* target) {
  NPHAND_CHECK(target->width == k.width && target->height == k.height);
  const bool shading = !intensity.empty();
  NPHAND_CHECK(!shading || (intensity.size() == vertices.size() && target->shade.size() == target->label.size()));

  std::vector<FixedVertex> fixed(vertices.size());
  std::vector<uint8_t> drawable(vertices.size());
  for (size_t v = 0; v < vertices.size(); ++v) {
    const Eigen::Vector3f& p = vertices[v];
    const double x = k.fx * p.x() / p.z() + k.cx, y = k.fy * p.y() / p.z() + k.cy;
    drawable[v] = p.z() >= kNearPlane && std::abs(x) < kMaxCoordinate && std::abs(y) < kMaxCoordinate;
    if (!drawable[v]) continue;
    fixed[v] = {std::llround(x * kOne), std::llround(y * kOne), 1.0f / p.z(), shading ? intensity[v] : 0.0f};
  }
  for (const Eigen::Vector3i& t : triangles) {
    if (!drawable[t[0]] || !drawable[t[1]] || !drawable[t[2]]) continue;
    if (faces == Faces::kFrontOnly) {
      const Eigen::Vector3f& a = vertices[t[0]];
      if ((vertices[t[1]] - a).cross(vertices[t[2]] - a).dot(a) >= 0.0f) continue;
    }
    if (shading) {
      DrawTriangle<true>(fixed[t[0]], fixed[t[1]], fixed[t[2]], label, target);
    } else {
      DrawTriangle<false>(fixed[t[0]], fixed[t[1]], fixed[t[2]], label, target);
    }
  }
}

}  // namespace nphand
