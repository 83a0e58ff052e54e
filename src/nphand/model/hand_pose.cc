#include "nphand/model/hand_pose.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>

#include <Eigen/Geometry>
#include <Eigen/SVD>

#include "nphand/util/check.h"

namespace nphand {
namespace {

constexpr double Deg(double degrees) { return degrees * std::numbers::pi / 180.0; }

const std::array<DofInfo, kNumDofs> kDofs = {{
    {"thumb_cmc_flex", Joint::kThumbMetacarpal, DofAxis::kFlexion, Deg(-20), Deg(60)},
    {"thumb_cmc_abd", Joint::kThumbMetacarpal, DofAxis::kAbduction, Deg(-30), Deg(40)},
    {"thumb_cmc_roll", Joint::kThumbMetacarpal, DofAxis::kRoll, Deg(-20), Deg(60)},
    {"thumb_mcp_flex", Joint::kThumbProximal, DofAxis::kFlexion, Deg(-10), Deg(70)},
    {"thumb_ip_flex", Joint::kThumbDistal, DofAxis::kFlexion, Deg(-15), Deg(85)},
    {"index_mcp_flex", Joint::kIndexProximal, DofAxis::kFlexion, Deg(-20), Deg(90)},
    {"index_mcp_abd", Joint::kIndexProximal, DofAxis::kAbduction, Deg(-20), Deg(20)},
    {"index_pip_flex", Joint::kIndexIntermediate, DofAxis::kFlexion, Deg(0), Deg(90)},
    {"index_dip_flex", Joint::kIndexDistal, DofAxis::kFlexion, Deg(-10), Deg(80)},
    {"middle_mcp_flex", Joint::kMiddleProximal, DofAxis::kFlexion, Deg(-20), Deg(90)},
    {"middle_mcp_abd", Joint::kMiddleProximal, DofAxis::kAbduction, Deg(-15), Deg(15)},
    {"middle_pip_flex", Joint::kMiddleIntermediate, DofAxis::kFlexion, Deg(0), Deg(90)},
    {"middle_dip_flex", Joint::kMiddleDistal, DofAxis::kFlexion, Deg(-10), Deg(80)},
    {"ring_mcp_flex", Joint::kRingProximal, DofAxis::kFlexion, Deg(-20), Deg(90)},
    {"ring_mcp_abd", Joint::kRingProximal, DofAxis::kAbduction, Deg(-15), Deg(15)},
    {"ring_pip_flex", Joint::kRingIntermediate, DofAxis::kFlexion, Deg(0), Deg(90)},
    {"ring_dip_flex", Joint::kRingDistal, DofAxis::kFlexion, Deg(-10), Deg(80)},
    {"little_mcp_flex", Joint::kLittleProximal, DofAxis::kFlexion, Deg(-20), Deg(90)},
    {"little_mcp_abd", Joint::kLittleProximal, DofAxis::kAbduction, Deg(-20), Deg(20)},
    {"little_pip_flex", Joint::kLittleIntermediate, DofAxis::kFlexion, Deg(0), Deg(90)},
    {"little_dip_flex", Joint::kLittleDistal, DofAxis::kFlexion, Deg(-10), Deg(80)},
}};

const std::map<std::string, JointAngles>& Articulations() {
  static const std::map<std::string, JointAngles> kArticulations = {
      {"rest", JointAngles{}},
      {"relaxed", AnglesFromDegrees({15, 10, 15, 15, 15}, {20, 3, 25, 10}, {25, 0, 30, 12},
                              {30, -3, 35, 14}, {35, -6, 40, 15})},
      {"fist", AnglesFromDegrees({30, -20, 50, 30, 20}, {88, 0, 90, 60}, {88, 0, 90, 60},
                           {88, 0, 90, 60}, {88, 0, 90, 60})},
      {"point", AnglesFromDegrees({30, -20, 50, 30, 20}, {0, 0, 0, 0}, {88, 0, 90, 60}, {88, 0, 90, 60},
                            {88, 0, 90, 60})},
      {"pinch", AnglesFromDegrees({35, 20, 50, 20, 25}, {45, 0, 45, 25}, {20, 0, 20, 10},
                            {15, 0, 15, 10}, {10, -5, 10, 5})},
  };
  return kArticulations;
}

}  // namespace

std::string ToString(Handedness handedness) {
  return handedness == Handedness::kRight ? "right" : "left";
}

Handedness HandednessFromString(const std::string& text) {
  if (text == "right") return Handedness::kRight;
  if (text == "left") return Handedness::kLeft;
  NPHAND_THROW("unknown handedness '", text, "' (expected right or left)");
}

const std::array<DofInfo, kNumDofs>& Dofs() { return kDofs; }

int DofFromString(const std::string& name) {
  for (int i = 0; i < kNumDofs; ++i) {
    if (name == kDofs[i].name) return i;
  }
  NPHAND_THROW("unknown joint angle '", name, "'");
}

bool HandPose::IsValid() const {
  for (int i = 0; i < kNumDofs; ++i) {
    if (!(angles[i] >= kDofs[i].min_rad && angles[i] <= kDofs[i].max_rad)) return false;
  }
  const bool orthonormal =
      (camera_from_hand.transpose() * camera_from_hand - Eigen::Matrix3d::Identity()).norm() < 1e-6;
  return orthonormal && camera_from_hand.determinant() > 0.0;
}

JointAngles ClampToLimits(const JointAngles& angles) {
  JointAngles clamped;
  for (int i = 0; i < kNumDofs; ++i) {
    clamped[i] = std::isnan(angles[i]) ? 0.0 : std::clamp(angles[i], kDofs[i].min_rad, kDofs[i].max_rad);
  }
  return clamped;
}

JointAngles AnglesFromDegrees(const std::array<double, 5>& thumb, const std::array<double, 4>& index,
                              const std::array<double, 4>& middle, const std::array<double, 4>& ring,
                              const std::array<double, 4>& little) {
  JointAngles angles{};
  int k = 0;
  for (double v : thumb) angles[k++] = Deg(v);
  for (const auto& finger : {index, middle, ring, little}) {
    for (double v : finger) angles[k++] = Deg(v);
  }
  return angles;
}

JointAngles RandomArticulation(Random& random) {
  JointAngles angles;
  for (int i = 0; i < kNumDofs; ++i) angles[i] = random.Uniform(kDofs[i].min_rad, kDofs[i].max_rad);
  return angles;
}

JointAngles NamedArticulation(const std::string& name) {
  const auto& all = Articulations();
  const auto it = all.find(name);
  if (it == all.end()) {
    std::string choices;
    for (const auto& [key, value] : all) choices += (choices.empty() ? "" : ", ") + key;
    NPHAND_THROW("unknown pose '", name, "' (choices: ", choices, ")");
  }
  return it->second;
}

std::vector<std::string> NamedArticulations() {
  std::vector<std::string> names;
  for (const auto& [key, value] : Articulations()) names.push_back(key);
  return names;
}

PoseVector ToPoseVector(const HandPose& pose) {
  PoseVector vector;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) vector[3 * r + c] = pose.camera_from_hand(r, c);
  }
  for (int i = 0; i < kNumDofs; ++i) vector[9 + i] = std::sin(pose.angles[i]);
  return vector;
}

HandPose MirrorPose(const HandPose& pose) {
  HandPose mirrored = pose;
  mirrored.handedness = pose.handedness == Handedness::kRight ? Handedness::kLeft : Handedness::kRight;
  const Eigen::Matrix3d s = Eigen::Vector3d(-1.0, 1.0, 1.0).asDiagonal();
  const Eigen::Matrix3d m = Eigen::Vector3d(1.0, -1.0, 1.0).asDiagonal();
  mirrored.camera_from_hand = s * pose.camera_from_hand * m;
  return mirrored;
}

Eigen::Matrix3d NearestRotation(const Eigen::Matrix3d& m) {
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(m, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d d = Eigen::Matrix3d::Identity();
  d(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0 ? -1.0 : 1.0;
  return svd.matrixU() * d * svd.matrixV().transpose();
}

HandPose FromPoseVector(const PoseVector& vector, Handedness handedness) {
  NPHAND_THROW_CHECK(vector.allFinite(), "pose vector has non-finite values");
  Eigen::Matrix3d m;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) m(r, c) = vector[3 * r + c];
  }
  HandPose pose;
  pose.handedness = handedness;
  pose.camera_from_hand = NearestRotation(m);
  for (int i = 0; i < kNumDofs; ++i) pose.angles[i] = std::asin(std::clamp(vector[9 + i], -1.0, 1.0));
  return pose;
}

Eigen::Matrix3d AxisAngle(const Eigen::Vector3d& axis, double angle) {
  return Eigen::AngleAxisd(angle, axis).toRotationMatrix();
}

double RotationAngleDeg(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  const double c = std::clamp(((a.transpose() * b).trace() - 1.0) / 2.0, -1.0, 1.0);
  return std::acos(c) * 180.0 / std::numbers::pi;
}

}  // namespace nphand
