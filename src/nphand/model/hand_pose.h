// Hand pose parameters: the wrist's orientation relative to the camera plus 21 anatomical
// joint angles with limits, and the paper's pose vector.
//
// Angles are radians. Flexion is positive when it curls towards the palm, abduction is
// positive towards the thumb side, thumb CMC roll is positive when it turns the thumb pad
// towards the fingers (opposition). Left and right hands share these meanings: the same
// angles give mirror-image hands.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "nphand/model/skeleton.h"
#include "nphand/util/random.h"

namespace nphand {

enum class Handedness : uint8_t { kRight, kLeft };
std::string ToString(Handedness handedness);
// Accepts "right" or "left"; throws nphand::Error otherwise.
Handedness HandednessFromString(const std::string& text);

// The rotation axis of a degree of freedom in its joint's anatomical frame.
enum class DofAxis : uint8_t {
  kRoll,       // about the bone (x)
  kFlexion,    // about the flexion axis (y): positive towards the palm
  kAbduction,  // about the dorsal normal (z): positive towards the thumb
};

inline constexpr int kNumDofs = 21;
using JointAngles = std::array<double, kNumDofs>;

struct DofInfo {
  const char* name;  // "index_pip_flex"
  Joint joint;       // the joint it rotates
  DofAxis axis;
  double min_rad;    // anatomical limits, within [-pi/2, pi/2] so the pose vector's sines invert
  double max_rad;
};
// The 21 degrees of freedom: thumb CMC flexion, abduction, roll, MCP flexion, IP flexion;
// then per finger (index, middle, ring, little) MCP flexion, MCP abduction, PIP flexion,
// DIP flexion.
const std::array<DofInfo, kNumDofs>& Dofs();
// Index of the degree of freedom named `name`; throws nphand::Error if there is none.
int DofFromString(const std::string& name);

struct HandPose {
  Handedness handedness = Handedness::kRight;
  // Rotation from the hand frame (origin at the wrist joint, x towards the middle finger's
  // MCP, z out of the back of the hand, y = z × x) into the camera frame (x right, y down,
  // z forward).
  Eigen::Matrix3d camera_from_hand = Eigen::Matrix3d::Identity();
  // All zero is the rest pose: the mesh's bind pose, an open flat hand.
  JointAngles angles{};

  // True when every angle lies within its limits and the rotation is orthonormal.
  bool IsValid() const;
};

// The angles moved into their limits.
JointAngles ClampToLimits(const JointAngles& angles);

// Angles from degrees, per digit: thumb {CMC flexion, CMC abduction, CMC roll, MCP, IP};
// each finger {MCP flexion, MCP abduction, PIP, DIP}.
JointAngles AnglesFromDegrees(const std::array<double, 5>& thumb, const std::array<double, 4>& index,
                              const std::array<double, 4>& middle, const std::array<double, 4>& ring,
                              const std::array<double, 4>& little);

// Angles drawn uniformly within their limits.
JointAngles RandomArticulation(Random& random);

// Named articulations for the CLI and tests: "rest" (open flat hand), "relaxed", "fist",
// "point", "pinch". Throws nphand::Error naming the choices for an unknown name.
JointAngles NamedArticulation(const std::string& name);
std::vector<std::string> NamedArticulations();

// The paper's pose vector x: the 9 entries of camera_from_hand (row-major) followed by
// the sines of the 21 joint angles (30 values).
inline constexpr int kPoseVectorSize = 9 + kNumDofs;
using PoseVector = Eigen::Matrix<double, kPoseVectorSize, 1>;
PoseVector ToPoseVector(const HandPose& pose);
// The rotation nearest `m` in the Frobenius norm (its projection onto SO(3)): of a weighted
// sum of rotations, their chordal mean.
Eigen::Matrix3d NearestRotation(const Eigen::Matrix3d& m);
// Inverse of ToPoseVector: the rotation is projected onto SO(3), each angle is the arcsine
// of its (clamped) sine. Throws nphand::Error for non-finite values.
HandPose FromPoseVector(const PoseVector& vector, Handedness handedness);

// The same hand seen in a mirror that flips the image's x: the other handedness, the same
// angles (they mean the same for both hands), camera_from_hand = S R M with S = diag(-1, 1, 1)
// in the camera and M = diag(1, -1, 1) in the hand frame (whose y points to the thumb on a
// right hand and away from it on a left one).
HandPose MirrorPose(const HandPose& pose);

// The rotation about `axis` (unit) by `angle` radians.
Eigen::Matrix3d AxisAngle(const Eigen::Vector3d& axis, double angle);
// The angle of the rotation between `a` and `b`, in degrees.
double RotationAngleDeg(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b);

}  // namespace nphand
