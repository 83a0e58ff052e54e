// Procedural object meshes for the grasps: sphere, cylinder, box, disk, torus and stick,
// with sizes in metres. Each mesh is centred on its object frame's origin; shapes with an
// axis (cylinder, disk, torus, stick) have it along z.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace nphand {

enum class ObjectShape : uint8_t { kSphere, kCylinder, kBox, kDisk, kTorus, kStick };
std::string ToString(ObjectShape shape);
// Accepts the names ToString gives; throws nphand::Error naming the choices otherwise.
ObjectShape ObjectShapeFromString(const std::string& text);
// What the size values of a shape mean, e.g. "radius,length" for a cylinder.
const char* ObjectSizeMeaning(ObjectShape shape);
// How many size values a shape takes (1 to 3).
int ObjectSizeCount(ObjectShape shape);

struct ObjectSpec {
  ObjectShape shape = ObjectShape::kSphere;
  // Metres, by shape: sphere {radius}; cylinder {radius, length}; box {x, y, z};
  // disk {radius, thickness}; torus {major radius, minor radius}; stick {radius, length},
  // a cylinder with hemispherical ends, length end to end. Unused values are ignored.
  std::array<double, 3> size = {0.04, 0.0, 0.0};
  // Segments around a circle; rings follow from it. More gives a truer silhouette.
  int segments = 32;

  // False (with the reason) if a size is not positive and finite, a torus's minor radius
  // is not below its major radius, a stick is shorter than its diameter, or segments < 3.
  bool Check(std::string* why) const;
  bool operator==(const ObjectSpec&) const = default;
};

struct TriangleMesh {
  std::vector<Eigen::Vector3f> vertices;
  std::vector<Eigen::Vector3f> normals;  // unit, outward, one per vertex
  std::vector<Eigen::Vector3i> triangles;
};

// The closed triangle mesh of an object in its own frame. Throws nphand::Error if the spec
// fails Check.
TriangleMesh MakeObjectMesh(const ObjectSpec& spec);

// The signed distance (metres) from `point_in_object` to the object's exact surface:
// negative inside. Analytic, so it does not depend on the mesh's tessellation (whose
// flat faces lie inside the true surface by at most r (1 - cos(pi / segments))).
double SignedDistance(const ObjectSpec& spec, const Eigen::Vector3d& point_in_object);

// An object placed in the hand frame, so that it moves with the hand.
struct SceneObject {
  ObjectSpec spec;
  Eigen::Isometry3d hand_from_object = Eigen::Isometry3d::Identity();
};

}  // namespace nphand
