#include "nphand/scene/object.h"
#include "nphand/scene/scene.h"

#include <cmath>
#include <numbers>

#include "nphand/util/check.h"

namespace nphand {
namespace {

constexpr std::array<const char*, 6> kShapeNames = {"sphere", "cylinder", "box", "disk", "torus", "stick"};
constexpr std::array<const char*, 6> kSizeMeanings = {"radius",         "radius,length",        "x,y,z",
                                                      "radius,thickness", "major_radius,minor_radius",
                                                      "radius,length"};
constexpr std::array<int, 6> kSizeCounts = {1, 2, 3, 2, 2, 2};
constexpr double kPi = std::numbers::pi;
constexpr double kPoleRadius = 1e-12;

// Appends a surface of revolution about z: a profile of (radius, z, normal_r, normal_z)
// points, ordered from top to bottom on the outside so that faces wind outward, swept
// around `segments` times and joined ring to ring.
struct ProfilePoint {
  double radius, z, normal_r, normal_z;
};

void AddRevolution(const std::vector<ProfilePoint>& profile, int segments, TriangleMesh* mesh) {
  const int base = static_cast<int>(mesh->vertices.size());
  for (const ProfilePoint& p : profile) {
    for (int s = 0; s < segments; ++s) {
      const double a = 2.0 * kPi * s / segments;
      const double c = std::cos(a), si = std::sin(a);
      mesh->vertices.emplace_back(static_cast<float>(p.radius * c), static_cast<float>(p.radius * si),
                                  static_cast<float>(p.z));
      mesh->normals.push_back(Eigen::Vector3f(static_cast<float>(p.normal_r * c),
                                              static_cast<float>(p.normal_r * si),
                                              static_cast<float>(p.normal_z))
                                  .normalized());
    }
  }
  for (int r = 0; r + 1 < static_cast<int>(profile.size()); ++r) {
    for (int s = 0; s < segments; ++s) {
      const int a = base + r * segments + s;
      const int b = base + r * segments + (s + 1) % segments;
      const int c = a + segments, d = b + segments;
      // A ring of radius zero is a pole: one triangle per quad there.
      if (profile[r].radius > kPoleRadius) mesh->triangles.emplace_back(a, c, b);
      if (profile[r + 1].radius > kPoleRadius) mesh->triangles.emplace_back(b, c, d);
    }
  }
}

// Profile of a sphere cap from polar angle `from` to `to` (radians from +z), centred at z0.
void AddArc(double radius, double z0, double from, double to, int steps, std::vector<ProfilePoint>* profile) {
  for (int i = 0; i <= steps; ++i) {
    const double t = from + (to - from) * i / steps;
    profile->push_back({radius * std::sin(t), z0 + radius * std::cos(t), std::sin(t), std::cos(t)});
  }
}

// A capped cylinder of `radius` from z = -half to +half, with flat caps (sharp normals).
void AddCappedCylinder(double radius, double half, int segments, TriangleMesh* mesh) {
  AddRevolution({{0, half, 0, 1}, {radius, half, 0, 1}}, segments, mesh);
  AddRevolution({{radius, half, 1, 0}, {radius, -half, 1, 0}}, segments, mesh);
  AddRevolution({{radius, -half, 0, -1}, {0, -half, 0, -1}}, segments, mesh);
}

void AddBox(const Eigen::Vector3d& size, TriangleMesh* mesh) {
  const Eigen::Vector3d h = size / 2.0;
  for (int axis = 0; axis < 3; ++axis) {
    for (double sign : {-1.0, 1.0}) {
      Eigen::Vector3d n = Eigen::Vector3d::Zero();
      n[axis] = sign;
      const Eigen::Vector3d u = Eigen::Vector3d::Unit((axis + 1) % 3), v = Eigen::Vector3d::Unit((axis + 2) % 3);
      const int base = static_cast<int>(mesh->vertices.size());
      for (double su : {-1.0, 1.0}) {
        for (double sv : {-1.0, 1.0}) {
          const Eigen::Vector3d p = n.cwiseProduct(h) + su * u.cwiseProduct(h) + sv * v.cwiseProduct(h);
          mesh->vertices.push_back(p.cast<float>());
          mesh->normals.push_back(n.cast<float>());
        }
      }
      // Corners: 0 (-u,-v), 1 (-u,+v), 2 (+u,-v), 3 (+u,+v); wind outward.
      if (sign > 0) {
        mesh->triangles.emplace_back(base, base + 2, base + 3);
        mesh->triangles.emplace_back(base, base + 3, base + 1);
      } else {
        mesh->triangles.emplace_back(base, base + 3, base + 2);
        mesh->triangles.emplace_back(base, base + 1, base + 3);
      }
    }
  }
}

}  // namespace

std::string ToString(ObjectShape shape) { return kShapeNames[static_cast<int>(shape)]; }

ObjectShape ObjectShapeFromString(const std::string& text) {
  for (size_t i = 0; i < kShapeNames.size(); ++i) {
    if (text == kShapeNames[i]) return static_cast<ObjectShape>(i);
  }
  NPHAND_THROW("unknown object shape '", text, "' (choices: sphere, cylinder, box, disk, torus, stick)");
}

const char* ObjectSizeMeaning(ObjectShape shape) { return kSizeMeanings[static_cast<int>(shape)]; }
int ObjectSizeCount(ObjectShape shape) { return kSizeCounts[static_cast<int>(shape)]; }

bool ObjectSpec::Check(std::string* why) const {
  const int count = ObjectSizeCount(shape);
  for (int i = 0; i < count; ++i) {
    if (!(std::isfinite(size[i]) && size[i] > 0.0)) {
      *why = ToString(shape) + " size (" + ObjectSizeMeaning(shape) + ") must be positive, got " +
             std::to_string(size[i]) + " at position " + std::to_string(i + 1);
      return false;
    }
  }
  if (shape == ObjectShape::kTorus && size[1] >= size[0]) {
    *why = "torus minor radius must be smaller than its major radius";
    return false;
  }
  if (shape == ObjectShape::kStick && size[1] < 2.0 * size[0]) {
    *why = "stick length must be at least its diameter";
    return false;
  }
  if (segments < 3 || segments > 4096) {
    *why = "object segments must be between 3 and 4096";
    return false;
  }
  return true;
}

TriangleMesh MakeObjectMesh(const ObjectSpec& spec) {
  std::string why;
  NPHAND_THROW_CHECK(spec.Check(&why), why);
  TriangleMesh mesh;
  const int segments = spec.segments;
  const int rings = std::max(2, segments / 2);
  switch (spec.shape) {
    case ObjectShape::kSphere: {
      std::vector<ProfilePoint> profile;
      AddArc(spec.size[0], 0.0, 0.0, kPi, rings, &profile);
      AddRevolution(profile, segments, &mesh);
      break;
    }
    case ObjectShape::kCylinder:
    case ObjectShape::kDisk:
      AddCappedCylinder(spec.size[0], spec.size[1] / 2.0, segments, &mesh);
      break;
    case ObjectShape::kBox:
      AddBox(Eigen::Vector3d(spec.size[0], spec.size[1], spec.size[2]), &mesh);
      break;
    case ObjectShape::kTorus: {
      const double major = spec.size[0], minor = spec.size[1];
      std::vector<ProfilePoint> profile;
      for (int i = 0; i <= segments; ++i) {
        const double t = -2.0 * kPi * i / segments;  // down the outside first
        profile.push_back({major + minor * std::cos(t), minor * std::sin(t), std::cos(t), std::sin(t)});
      }
      AddRevolution(profile, segments, &mesh);
      break;
    }
    case ObjectShape::kStick: {
      const double radius = spec.size[0], half = spec.size[1] / 2.0 - radius;
      std::vector<ProfilePoint> profile;
      AddArc(radius, half, 0.0, kPi / 2.0, rings / 2 + 1, &profile);
      AddArc(radius, -half, kPi / 2.0, kPi, rings / 2 + 1, &profile);
      AddRevolution(profile, segments, &mesh);
      break;
    }
  }
  return mesh;
}

double SignedDistance(const ObjectSpec& spec, const Eigen::Vector3d& p) {
  // A capped cylinder of radius r and half height h about z.
  const auto cylinder = [&p](double r, double h) {
    const Eigen::Vector2d d(p.head<2>().norm() - r, std::abs(p.z()) - h);
    return std::min(d.maxCoeff(), 0.0) + d.cwiseMax(0.0).norm();
  };
  switch (spec.shape) {
    case ObjectShape::kSphere:
      return p.norm() - spec.size[0];
    case ObjectShape::kCylinder:
    case ObjectShape::kDisk:
      return cylinder(spec.size[0], spec.size[1] / 2.0);
    case ObjectShape::kBox: {
      const Eigen::Vector3d q = p.cwiseAbs() - Eigen::Vector3d(spec.size[0], spec.size[1], spec.size[2]) / 2.0;
      return std::min(q.maxCoeff(), 0.0) + q.cwiseMax(0.0).norm();
    }
    case ObjectShape::kTorus:
      return Eigen::Vector2d(p.head<2>().norm() - spec.size[0], p.z()).norm() - spec.size[1];
    case ObjectShape::kStick: {
      const double half = spec.size[1] / 2.0 - spec.size[0];
      return Eigen::Vector3d(p.x(), p.y(), p.z() - std::clamp(p.z(), -half, half)).norm() - spec.size[0];
    }
  }
  NPHAND_CHECK(false, "unknown object shape");
  return 0.0;
}

}  // namespace nphand

namespace nphand {

bool Forearm::Check(std::string* why) const {
  if (!(length > 0.0 && length <= 1.0) || !(elbow_width_scale >= 0.5 && elbow_width_scale <= 3.0) ||
      !(elbow_depth_scale >= 0.5 && elbow_depth_scale <= 3.0) || !(upper_arm_length >= 0.0 && upper_arm_length <= 1.0)) {
    *why = "a forearm's length must be within (0, 1] metres, its elbow scales within [0.5, 3] and its upper arm's "
           "length within [0, 1] metres";
    return false;
  }
  return true;
}

}  // namespace nphand
