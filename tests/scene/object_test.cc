#include "nphand/scene/object.h"

#include <map>
#include <numbers>

#include <gtest/gtest.h>

#include "nphand/util/check.h"

namespace nphand {
namespace {

struct ShapeCase {
  ObjectSpec spec;
  Eigen::Vector3f half_extent;  // expected bounding box half-size
};

std::vector<ShapeCase> Cases() {
  return {
      {{ObjectShape::kSphere, {0.04, 0, 0}, 32}, {0.04f, 0.04f, 0.04f}},
      {{ObjectShape::kCylinder, {0.02, 0.12, 0}, 32}, {0.02f, 0.02f, 0.06f}},
      {{ObjectShape::kBox, {0.1, 0.06, 0.02}, 32}, {0.05f, 0.03f, 0.01f}},
      {{ObjectShape::kDisk, {0.05, 0.01, 0}, 32}, {0.05f, 0.05f, 0.005f}},
      {{ObjectShape::kTorus, {0.04, 0.01, 0}, 32}, {0.05f, 0.05f, 0.01f}},
      {{ObjectShape::kStick, {0.005, 0.2, 0}, 32}, {0.005f, 0.005f, 0.1f}},
  };
}

TEST(ObjectTest, MeshesHaveTheirSizeAndUnitOutwardNormals) {
  for (const ShapeCase& c : Cases()) {
    const TriangleMesh mesh = MakeObjectMesh(c.spec);
    ASSERT_EQ(mesh.vertices.size(), mesh.normals.size());
    Eigen::Vector3f low = mesh.vertices[0], high = mesh.vertices[0];
    for (size_t v = 0; v < mesh.vertices.size(); ++v) {
      low = low.cwiseMin(mesh.vertices[v]);
      high = high.cwiseMax(mesh.vertices[v]);
      EXPECT_NEAR(mesh.normals[v].norm(), 1.0f, 1e-5f);
    }
    EXPECT_LT((high - c.half_extent).norm(), 1e-6f) << ToString(c.spec.shape);
    EXPECT_LT((low + c.half_extent).norm(), 1e-6f) << ToString(c.spec.shape);
    for (const Eigen::Vector3i& t : mesh.triangles) {
      for (int k = 0; k < 3; ++k) ASSERT_LT(t[k], static_cast<int>(mesh.vertices.size()));
      // Outward: the face normal agrees with its vertices' normals.
      const Eigen::Vector3f n = (mesh.vertices[t[1]] - mesh.vertices[t[0]]).cross(mesh.vertices[t[2]] - mesh.vertices[t[0]]);
      const Eigen::Vector3f vn = mesh.normals[t[0]] + mesh.normals[t[1]] + mesh.normals[t[2]];
      EXPECT_GT(n.dot(vn), 0.0f) << ToString(c.spec.shape);
    }
  }
}

TEST(ObjectTest, MeshesAreClosed) {
  // Every edge between two distinct positions is shared by exactly two triangles, in
  // opposite directions.
  for (const ShapeCase& c : Cases()) {
    const TriangleMesh mesh = MakeObjectMesh(c.spec);
    auto key = [&](int v) {
      const Eigen::Vector3f& p = mesh.vertices[v];
      return std::array<long, 3>{std::lround(p.x() * 1e6), std::lround(p.y() * 1e6), std::lround(p.z() * 1e6)};
    };
    std::map<std::pair<std::array<long, 3>, std::array<long, 3>>, int> directed;
    for (const Eigen::Vector3i& t : mesh.triangles) {
      for (int k = 0; k < 3; ++k) {
        const auto a = key(t[k]), b = key(t[(k + 1) % 3]);
        if (a != b) ++directed[{a, b}];
      }
    }
    for (const auto& [edge, count] : directed) {
      ASSERT_EQ(count, 1) << ToString(c.spec.shape);
      const auto reverse = directed.find({edge.second, edge.first});
      ASSERT_TRUE(reverse != directed.end()) << ToString(c.spec.shape) << " has an open edge";
    }
  }
}

TEST(ObjectTest, InvalidSpecsAreRefusedWithAReason) {
  std::string why;
  ObjectSpec spec{ObjectShape::kCylinder, {0.02, -1.0, 0}, 32};
  EXPECT_FALSE(spec.Check(&why));
  EXPECT_NE(why.find("radius,length"), std::string::npos) << why;
  EXPECT_THROW(MakeObjectMesh(spec), Error);
  EXPECT_FALSE((ObjectSpec{ObjectShape::kTorus, {0.01, 0.02, 0}, 32}).Check(&why));
  EXPECT_FALSE((ObjectSpec{ObjectShape::kStick, {0.02, 0.03, 0}, 32}).Check(&why));
  EXPECT_FALSE((ObjectSpec{ObjectShape::kSphere, {0.02, 0, 0}, 2}).Check(&why));
  EXPECT_TRUE((ObjectSpec{ObjectShape::kSphere, {0.02, 0, 0}, 8}).Check(&why));
}

TEST(ObjectTest, ShapeNamesRoundTrip) {
  for (int s = 0; s < 6; ++s) {
    const auto shape = static_cast<ObjectShape>(s);
    EXPECT_EQ(ObjectShapeFromString(ToString(shape)), shape);
  }
  EXPECT_THROW(ObjectShapeFromString("cone"), Error);
}

}  // namespace
}  // namespace nphand

namespace nphand {
namespace {

TEST(ObjectTest, SignedDistanceIsZeroOnTheSurfaceAndNegativeInside) {
  for (const ShapeCase& c : Cases()) {
    ObjectSpec fine = c.spec;
    fine.segments = 256;
    // Every vertex of a fine mesh lies on the exact surface.
    for (const Eigen::Vector3f& v : MakeObjectMesh(fine).vertices) {
      ASSERT_NEAR(SignedDistance(c.spec, v.cast<double>()), 0.0, 1e-6) << ToString(c.spec.shape);
    }
    // Moving out along the normal by d gives distance d; moving in gives -d on smooth
    // shapes (at a sharp edge the nearest surface is another face).
    const bool smooth = c.spec.shape == ObjectShape::kSphere || c.spec.shape == ObjectShape::kTorus ||
                        c.spec.shape == ObjectShape::kStick;
    const TriangleMesh mesh = MakeObjectMesh(fine);
    for (size_t v = 0; v < mesh.vertices.size(); v += 37) {
      const Eigen::Vector3d p = mesh.vertices[v].cast<double>(), n = mesh.normals[v].cast<double>();
      EXPECT_NEAR(SignedDistance(c.spec, p + 0.001 * n), 0.001, 2e-5) << ToString(c.spec.shape);
      if (smooth) {
        EXPECT_NEAR(SignedDistance(c.spec, p - 0.0005 * n), -0.0005, 2e-5) << ToString(c.spec.shape);
      }
    }
    // The centre is inside every shape but the torus, whose hole it is.
    EXPECT_EQ(SignedDistance(c.spec, Eigen::Vector3d::Zero()) < 0.0, c.spec.shape != ObjectShape::kTorus);
  }
  EXPECT_DOUBLE_EQ(SignedDistance({ObjectShape::kSphere, {0.04, 0, 0}, 32}, Eigen::Vector3d(0.1, 0, 0)), 0.06);
}

}  // namespace
}  // namespace nphand
