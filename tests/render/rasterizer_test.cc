#include "nphand/render/rasterizer.h"

#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include "testing/testing.h"

namespace nphand {
namespace {

// Intrinsics that map camera (x, y, 1) to pixel (x, y): triangles at depth 1 are drawn in
// pixel units.
Intrinsics PixelCamera(int width, int height) {
  Intrinsics k;
  k.width = width;
  k.height = height;
  k.fx = k.fy = 1.0;
  k.cx = k.cy = 0.0;
  return k;
}

TEST(RasterizerTest, FanOfTrianglesCoversEachPixelCentreExactlyOnce) {
  Random random(testing::kTestSeed);
  const Intrinsics k = PixelCamera(64, 64);
  for (int trial = 0; trial < 20; ++trial) {
    // A convex polygon with fractional vertices, fanned from an inner point.
    const Eigen::Vector2d centre(32 + random.Uniform(-3, 3), 32 + random.Uniform(-3, 3));
    const int sides = 3 + static_cast<int>(random.UniformIndex(8));
    const double phase = random.Uniform(0, 1);
    std::vector<Eigen::Vector3f> vertices = {Eigen::Vector3f(centre.x(), centre.y(), 1.0f)};
    for (int s = 0; s < sides; ++s) {
      const double a = 2 * std::numbers::pi * (s + phase) / sides;
      vertices.emplace_back(static_cast<float>(centre.x() + 25 * std::cos(a)),
                            static_cast<float>(centre.y() + 25 * std::sin(a)), 1.0f);
    }
    std::vector<int> covered(64 * 64, 0);
    for (int s = 0; s < sides; ++s) {
      // Draw each triangle alone and count, so that the z-buffer cannot hide double cover.
      RasterTarget target;
      target.Reset(64, 64, false);
      const std::vector<Eigen::Vector3i> triangle = {{0, 1 + s, 1 + (s + 1) % sides}};
      RasterizeTriangles(k, vertices, triangle, {}, 1, Faces::kBoth, &target);
      for (int i = 0; i < 64 * 64; ++i) covered[i] += target.label[i];
    }
    int inside = 0;
    for (int y = 0; y < 64; ++y) {
      for (int x = 0; x < 64; ++x) {
        ASSERT_LE(covered[y * 64 + x], 1) << "pixel " << x << "," << y << " drawn twice";
        // Pixel centres well inside the polygon must be covered.
        const Eigen::Vector2d p(x + 0.5, y + 0.5);
        bool well_inside = true;
        for (int s = 0; s < sides; ++s) {
          const Eigen::Vector2d a = vertices[1 + s].head<2>().cast<double>();
          const Eigen::Vector2d b = vertices[1 + (s + 1) % sides].head<2>().cast<double>();
          const Eigen::Vector2d e = b - a, q = p - a;
          well_inside &= (e.x() * q.y() - e.y() * q.x()) / e.norm() > 0.01;
        }
        if (well_inside) {
          ASSERT_EQ(covered[y * 64 + x], 1) << "gap at " << x << "," << y;
          ++inside;
        }
      }
    }
    EXPECT_GT(inside, 500);
  }
}

TEST(RasterizerTest, NearerSurfaceWinsAndDepthIsPerspectiveCorrect) {
  const Intrinsics k = PixelCamera(16, 16);
  RasterTarget target;
  target.Reset(16, 16, false);
  // A far square at z = 2 (drawn first) and a near one at z = 1 over its left half.
  const std::vector<Eigen::Vector3f> far = {{0, 0, 2}, {32, 0, 2}, {32, 32, 2}, {0, 32, 2}};
  const std::vector<Eigen::Vector3f> near = {{0, 0, 1}, {8, 0, 1}, {8, 16, 1}, {0, 16, 1}};
  const std::vector<Eigen::Vector3i> quad = {{0, 1, 2}, {0, 2, 3}};
  RasterizeTriangles(k, far, quad, {}, 1, Faces::kBoth, &target);
  RasterizeTriangles(k, near, quad, {}, 2, Faces::kBoth, &target);
  for (int y = 0; y < 16; ++y) {
    for (int x = 0; x < 16; ++x) {
      const int i = y * 16 + x;
      EXPECT_EQ(target.label[i], x < 8 ? 2 : 1);
      EXPECT_FLOAT_EQ(1.0f / target.inverse_depth[i], x < 8 ? 1.0f : 2.0f);
    }
  }
}

TEST(RasterizerTest, TrianglesBehindTheNearPlaneAreSkipped) {
  const Intrinsics k = PixelCamera(8, 8);
  RasterTarget target;
  target.Reset(8, 8, false);
  const std::vector<Eigen::Vector3f> behind = {{0, 0, -1}, {8, 0, -1}, {0, 8, -1}};
  RasterizeTriangles(k, behind, std::vector<Eigen::Vector3i>{{0, 1, 2}}, {}, 1, Faces::kBoth, &target);
  for (uint8_t l : target.label) EXPECT_EQ(l, 0);
}

}  // namespace
}  // namespace nphand

namespace nphand {
namespace {

TEST(RasterizerTest, BackFacesAreSkippedOnlyWhenAsked) {
  const Intrinsics k = PixelCamera(8, 8);
  // Counter-clockwise seen from the camera means a normal towards it: (b - a) x (c - a)
  // points to -z here.
  const std::vector<Eigen::Vector3f> vertices = {{0, 0, 1}, {8, 0, 1}, {0, 8, 1}};
  const std::vector<Eigen::Vector3i> facing = {{0, 2, 1}}, away = {{0, 1, 2}};
  for (const auto& [triangles, faces, drawn] :
       {std::tuple{facing, Faces::kFrontOnly, true}, std::tuple{away, Faces::kFrontOnly, false},
        std::tuple{away, Faces::kBoth, true}}) {
    RasterTarget target;
    target.Reset(8, 8, false);
    RasterizeTriangles(k, vertices, triangles, {}, 1, faces, &target);
    EXPECT_EQ(target.label[0] == 1, drawn);
  }
}

}  // namespace
}  // namespace nphand
