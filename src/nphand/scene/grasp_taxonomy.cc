// The data of the 33 grasps: object, placement, pre-shape and closing joints. Sizes follow
// the typical objects of the taxonomy (../shared/GRASPS.md); the hand closes onto the object
// in MakeGrasp, so no final angle is written here.
#include <numbers>

#include <Eigen/Geometry>

#include "nphand/scene/grasp.h"

namespace nphand {
namespace {

using D = Digit;
constexpr double kDeg = std::numbers::pi / 180.0;

// Hand frame axes: x along the fingers, y to the thumb side (right hand), z out of the back.
const Eigen::Vector3d kAlong = Eigen::Vector3d::UnitX();
const Eigen::Vector3d kAcross = Eigen::Vector3d::UnitY();
const Eigen::Vector3d kFromPalm = Eigen::Vector3d::UnitZ();

// A rotation taking the object's z axis onto `direction`.
Eigen::Matrix3d AxisAlong(const Eigen::Vector3d& direction) {
  return Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), direction.normalized()).toRotationMatrix();
}
// `direction` turned in the palm plane by `degrees` (positive towards the fingers' ulnar side).
Eigen::Vector3d Turned(const Eigen::Vector3d& direction, double degrees) {
  return Eigen::AngleAxisd(degrees * kDeg, Eigen::Vector3d::UnitZ()) * direction;
}

int FingerDof(Digit finger, int k) { return 5 + 4 * (static_cast<int>(finger) - 1) + k; }  // k: 0 mcp, 2 pip, 3 dip

// Each finger curls: MCP, then PIP, then DIP, towards full flexion.
std::vector<ClosingMove> Curl(std::initializer_list<Digit> fingers, bool straight = false) {
  std::vector<ClosingMove> moves;
  for (Digit f : fingers) {
    moves.push_back({FingerDof(f, 0), 90 * kDeg});
    if (!straight) {
      moves.push_back({FingerDof(f, 2), 90 * kDeg});
      moves.push_back({FingerDof(f, 3), 80 * kDeg});
    }
  }
  return moves;
}
// The thumb sweeps across the palm, then curls.
std::vector<ClosingMove> ThumbCurl() { return {{0, 60 * kDeg}, {3, 70 * kDeg}, {4, 85 * kDeg}}; }
// Ring and little finger turn towards the thumb side, as around a disc's rim.
std::vector<ClosingMove> Gather() { return {{FingerDof(D::kRing, 1), 15 * kDeg}, {FingerDof(D::kLittle, 1), 20 * kDeg}}; }
// The thumb tip moves straight towards the object until it touches.
std::vector<ClosingMove> ThumbReach() { return {{ClosingMove::kThumbReach, 0.0}}; }
std::vector<ClosingMove> operator+(std::vector<ClosingMove> a, const std::vector<ClosingMove>& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

// Pre-shapes (degrees): thumb {cmc flex, cmc abd, cmc roll, mcp, ip}, fingers {mcp, abd, pip, dip}.
constexpr std::array<double, 5> kThumbOpen = {0, 35, 40, 0, 0};
constexpr std::array<double, 5> kThumbOpposed = {10, 20, 55, 10, 5};
constexpr std::array<double, 5> kThumbAdducted = {-15, -25, 0, 0, 0};
constexpr std::array<double, 4> kFlat = {0, 0, 0, 0};
constexpr std::array<double, 4> kReady = {25, 0, 20, 10};
constexpr std::array<double, 4> kTucked = {70, 0, 80, 50};
constexpr std::array<double, 4> kCup = {40, 0, 35, 15};

JointAngles Pre(const std::array<double, 5>& thumb, const std::array<double, 4>& index, const std::array<double, 4>& middle,
                const std::array<double, 4>& ring, const std::array<double, 4>& little) {
  return AnglesFromDegrees(thumb, index, middle, ring, little);
}

ObjectSpec Sphere(double r) { return {ObjectShape::kSphere, {r, 0, 0}, 32}; }
ObjectSpec Cylinder(double r, double length) { return {ObjectShape::kCylinder, {r, length, 0}, 32}; }
ObjectSpec Disk(double r, double thickness) { return {ObjectShape::kDisk, {r, thickness, 0}, 32}; }
ObjectSpec Box(double x, double y, double z) { return {ObjectShape::kBox, {x, y, z}, 32}; }
ObjectSpec Stick(double r, double length) { return {ObjectShape::kStick, {r, length, 0}, 32}; }

struct Builder {
  GraspDefinition g;
  Builder(grasp_id_t id, const char* name, GraspType type, Opposition opposition, ThumbPlacement thumb,
          std::vector<Digit> contacts) {
    g.id = id;
    g.name = name;
    g.type = type;
    g.opposition = opposition;
    g.thumb = thumb;
    g.contacts = std::move(contacts);
  }
  Builder& Object(const ObjectSpec& spec, const Eigen::Matrix3d& rotation = Eigen::Matrix3d::Identity()) {
    g.object = spec;
    g.object_rotation = rotation;
    return *this;
  }
  Builder& AlignWithPinch() {
    g.align_with_pinch = true;
    return *this;
  }
  Builder& At(Anchor anchor, const Eigen::Vector3d& offset = Eigen::Vector3d::Zero()) {
    g.anchor = anchor;
    g.anchor_offset = offset;
    return *this;
  }
  Builder& Approach(const Eigen::Vector3d& approach, double gap) {
    g.approach = approach;
    g.gap = gap;
    return *this;
  }
  Builder& Preshape(const JointAngles& angles) {
    g.preshape = angles;
    return *this;
  }
  Builder& Oppose() {
    g.oppose_thumb = true;
    return *this;
  }
  Builder& Close(std::vector<ClosingMove> moves) {
    g.closing = std::move(moves);
    return *this;
  }
};

std::vector<GraspDefinition> Build() {
  using GT = GraspType;
  using O = Opposition;
  using T = ThumbPlacement;
  const auto P = GT::kPower, I = GT::kIntermediate, R = GT::kPrecision;
  const auto all_fingers = {D::kIndex, D::kMiddle, D::kRing, D::kLittle};
  std::vector<Builder> b = {
      Builder(1, "Large Diameter", P, O::kPalm, T::kAbducted, {D::kIndex, D::kMiddle, D::kRing, D::kLittle})
          .Object(Cylinder(0.04, 0.2), AxisAlong(kAcross)).At(Anchor::kProximalPhalanges)
          .Preshape(Pre(kThumbOpen, kFlat, kFlat, kFlat, kFlat)).Close(Curl(all_fingers) + ThumbCurl()),
      Builder(2, "Small Diameter", P, O::kPalm, T::kAbducted, {D::kIndex, D::kMiddle, D::kRing, D::kLittle})
          .Object(Cylinder(0.0125, 0.2), AxisAlong(kAcross)).At(Anchor::kProximalPhalanges)
          .Preshape(Pre(kThumbOpen, kFlat, kFlat, kFlat, kFlat)).Close(Curl(all_fingers) + ThumbCurl()),
      Builder(3, "Medium Wrap", P, O::kPalm, T::kAbducted, {D::kIndex, D::kMiddle, D::kRing, D::kLittle})
          .Object(Cylinder(0.0175, 0.2), AxisAlong(Turned(kAcross, -25))).At(Anchor::kProximalPhalanges)
          .Preshape(Pre(kThumbOpen, kFlat, kFlat, kFlat, kFlat)).Close(Curl(all_fingers) + ThumbCurl()),
      Builder(4, "Adducted Thumb", P, O::kPalm, T::kAdducted, {D::kIndex, D::kMiddle, D::kRing, D::kLittle})
          .Object(Cylinder(0.02, 0.2), AxisAlong(kAcross)).At(Anchor::kProximalPhalanges)
          .Preshape(Pre(kThumbAdducted, kFlat, kFlat, kFlat, kFlat)).Close(Curl(all_fingers)),
      Builder(5, "Light Tool", P, O::kPalm, T::kAdducted, {D::kIndex, D::kMiddle, D::kRing, D::kLittle})
          .Object(Cylinder(0.009, 0.2), AxisAlong(Turned(kAcross, -30))).At(Anchor::kProximalPhalanges)
          .Preshape(Pre(kThumbAdducted, kFlat, kFlat, kFlat, kFlat)).Close(Curl(all_fingers)),
      Builder(6, "Prismatic 4 Finger", R, O::kPad, T::kAbducted, {D::kThumb, D::kIndex, D::kMiddle, D::kRing, D::kLittle})
          .Object(Cylinder(0.006, 0.14), AxisAlong(kAcross)).Oppose().At(Anchor::kPinch).Approach(kFromPalm, 0.003)
          .Preshape(Pre(kThumbOpposed, kReady, kReady, kReady, kReady)).Close(Curl(all_fingers) + ThumbReach()),
      Builder(7, "Prismatic 3 Finger", R, O::kPad, T::kAbducted, {D::kThumb, D::kIndex, D::kMiddle, D::kRing})
          .Object(Cylinder(0.005, 0.12), AxisAlong(kAcross)).Oppose().At(Anchor::kPinch).Approach(kFromPalm, 0.003)
          .Preshape(Pre(kThumbOpposed, kReady, kReady, kReady, kTucked))
          .Close(Curl({D::kIndex, D::kMiddle, D::kRing}) + ThumbReach()),
      Builder(8, "Prismatic 2 Finger", R, O::kPad, T::kAbducted, {D::kThumb, D::kIndex, D::kMiddle})
          .Object(Cylinder(0.004, 0.1), AxisAlong(kAcross)).Oppose().At(Anchor::kPinch).Approach(kFromPalm, 0.003)
          .Preshape(Pre(kThumbOpposed, kReady, kReady, kTucked, kTucked))
          .Close(Curl({D::kIndex, D::kMiddle}) + ThumbReach()),
      Builder(9, "Palmar Pinch", R, O::kPad, T::kAbducted, {D::kThumb, D::kIndex})
          .Object(Box(0.05, 0.03, 0.003)).AlignWithPinch().Oppose().At(Anchor::kPinch).Approach(kFromPalm, 0.003)
          .Preshape(Pre(kThumbOpposed, kReady, kTucked, kTucked, kTucked)).Close(Curl({D::kIndex}) + ThumbReach()),
      Builder(10, "Power Disk", P, O::kPalm, T::kAbducted, {D::kIndex, D::kMiddle, D::kRing, D::kLittle})
          .Object(Disk(0.05, 0.02)).At(Anchor::kPalmCentre)
          .Preshape(Pre(kThumbOpen, kFlat, kFlat, kFlat, kFlat)).Close(Curl(all_fingers) + ThumbCurl()),
      Builder(11, "Power Sphere", P, O::kPalm, T::kAbducted, {D::kIndex, D::kMiddle, D::kRing, D::kLittle})
          .Object(Sphere(0.04)).At(Anchor::kPalmCentre)
          .Preshape(Pre(kThumbOpen, kFlat, kFlat, kFlat, kFlat)).Close(Curl(all_fingers) + ThumbCurl()),
      Builder(12, "Precision Disk", R, O::kPad, T::kAbducted, {D::kThumb, D::kIndex, D::kMiddle, D::kRing, D::kLittle})
          .Object(Disk(0.03, 0.012)).Oppose().At(Anchor::kPalmCentre).Approach(kFromPalm, 0.03)
          .Preshape(Pre(kThumbOpposed, kFlat, kFlat, kFlat, kFlat)).Close(Gather() + Curl(all_fingers) + ThumbReach()),
      Builder(13, "Precision Sphere", R, O::kPad, T::kAbducted, {D::kThumb, D::kIndex, D::kMiddle, D::kRing, D::kLittle})
          .Object(Sphere(0.03)).Oppose().At(Anchor::kPinch).Approach(kFromPalm, 0.003)
          .Preshape(Pre(kThumbOpposed, kCup, kCup, kCup, kCup)).Close(Curl(all_fingers) + ThumbReach()),
      Builder(14, "Tripod", R, O::kPad, T::kAbducted, {D::kThumb, D::kIndex, D::kMiddle})
          .Object(Sphere(0.0125)).Oppose().At(Anchor::kPinch).Approach(kFromPalm, 0.003)
          .Preshape(Pre(kThumbOpposed, kReady, kReady, kTucked, kTucked))
          .Close(Curl({D::kIndex, D::kMiddle}) + ThumbReach()),
      Builder(15, "Fixed Hook", P, O::kPalm, T::kAdducted, {D::kIndex, D::kMiddle, D::kRing, D::kLittle})
          .Object(Cylinder(0.012, 0.2), AxisAlong(kAcross)).At(Anchor::kMiddlePhalanges)
          .Preshape(Pre(kThumbAdducted, kFlat, kFlat, kFlat, kFlat))
          .Close({{FingerDof(D::kIndex, 2), 90 * kDeg}, {FingerDof(D::kIndex, 3), 80 * kDeg},
                  {FingerDof(D::kMiddle, 2), 90 * kDeg}, {FingerDof(D::kMiddle, 3), 80 * kDeg},
                  {FingerDof(D::kRing, 2), 90 * kDeg}, {FingerDof(D::kRing, 3), 80 * kDeg},
                  {FingerDof(D::kLittle, 2), 90 * kDeg}, {FingerDof(D::kLittle, 3), 80 * kDeg}}),
      Builder(16, "Lateral", I, O::kSide, T::kAdducted, {D::kThumb, D::kIndex})
          .Object(Box(0.045, 0.003, 0.022)).Oppose().At(Anchor::kIndexMiddlePhalanx).Approach(-kAcross, 0.001)
          .Preshape(Pre({0, 30, 10, 0, 0}, {45, 0, 60, 30}, kTucked, kTucked, kTucked)).Close(ThumbReach()),
      Builder(17, "Index Finger Extension", P, O::kPalm, T::kAdducted, {D::kMiddle, D::kRing, D::kLittle})
          .Object(Cylinder(0.012, 0.14), AxisAlong(Turned(kAcross, -20))).At(Anchor::kProximalPhalanges)
          .Preshape(Pre(kThumbAdducted, kFlat, kFlat, kFlat, kFlat))
          .Close(Curl({D::kMiddle, D::kRing, D::kLittle})),
      Builder(18, "Extension Type", P, O::kPad, T::kAbducted, {D::kThumb, D::kIndex, D::kMiddle, D::kRing, D::kLittle})
          .Object(Box(0.12, 0.12, 0.025)).Oppose().At(Anchor::kPinch).Approach(kFromPalm, 0.003)
          .Preshape(Pre(kThumbOpposed, kFlat, kFlat, kFlat, kFlat)).Close(Curl(all_fingers, true) + ThumbReach()),
      Builder(19, "Distal Type", P, O::kPad, T::kAbducted, {D::kThumb, D::kIndex, D::kMiddle, D::kRing, D::kLittle})
          .Object(Disk(0.022, 0.008)).Oppose().At(Anchor::kMiddlePhalanges).Approach(kFromPalm, 0.02)
          .Preshape(Pre(kThumbOpposed, kFlat, kFlat, kFlat, kFlat)).Close(Gather() + Curl(all_fingers) + ThumbReach()),
      Builder(20, "Writing Tripod", R, O::kSide, T::kAbducted, {D::kThumb, D::kIndex, D::kMiddle})
          .Object(Stick(0.004, 0.14), AxisAlong(kAlong - kFromPalm)).Oppose().At(Anchor::kPinch).Approach(kFromPalm, 0.002)
          .Preshape(Pre(kThumbOpposed, kReady, kReady, kTucked, kTucked))
          .Close(Curl({D::kIndex, D::kMiddle}) + ThumbReach()),
      Builder(21, "Tripod Variation", I, O::kSide, T::kAbducted, {D::kThumb, D::kMiddle, D::kRing})
          .Object(Stick(0.005, 0.14), AxisAlong(kAlong - kFromPalm)).Oppose().At(Anchor::kPinch).Approach(kFromPalm, 0.002)
          .Preshape(Pre(kThumbOpposed, kTucked, kCup, kCup, kTucked))
          .Close(Curl({D::kMiddle, D::kRing}) + ThumbReach()),
      Builder(22, "Parallel Extension", R, O::kPad, T::kAdducted, {D::kThumb, D::kIndex, D::kMiddle, D::kRing, D::kLittle})
          .Object(Box(0.09, 0.09, 0.006)).Oppose().At(Anchor::kPinch).Approach(kFromPalm, 0.003)
          .Preshape(Pre(kThumbOpposed, kFlat, kFlat, kFlat, kFlat)).Close(Curl(all_fingers, true) + ThumbReach()),
      Builder(23, "Adduction Grip", I, O::kSide, T::kAbducted, {D::kIndex, D::kMiddle})
          .Object(Stick(0.003, 0.08), AxisAlong(kFromPalm)).At(Anchor::kBetweenIndexMiddle)
          .Approach(kFromPalm, -1.0)
          .Preshape(Pre(kThumbOpen, {20, 20, 10, 5}, {20, -15, 10, 5}, kTucked, kTucked))
          .Close({{FingerDof(D::kIndex, 1), -20 * kDeg}, {FingerDof(D::kMiddle, 1), 15 * kDeg}}),
      Builder(24, "Tip Pinch", R, O::kPad, T::kAbducted, {D::kThumb, D::kIndex})
          .Object(Sphere(0.005)).Oppose().At(Anchor::kPinch).Approach(kFromPalm, 0.002)
          .Preshape(Pre(kThumbOpposed, kReady, kTucked, kTucked, kTucked)).Close(Curl({D::kIndex}) + ThumbReach()),
      Builder(25, "Lateral Tripod", I, O::kSide, T::kAdducted, {D::kThumb, D::kMiddle})
          .Object(Box(0.04, 0.012, 0.02)).Oppose().At(Anchor::kPinch).Approach(kFromPalm, 0.002)
          .Preshape(Pre(kThumbOpposed, kReady, kReady, kTucked, kTucked))
          .Close(Curl({D::kMiddle, D::kIndex}) + ThumbReach()),
      Builder(26, "Sphere 4 Finger", P, O::kPad, T::kAbducted, {D::kThumb, D::kIndex, D::kMiddle, D::kRing})
          .Object(Sphere(0.0275)).Oppose().At(Anchor::kPinch).Approach(kFromPalm, 0.003)
          .Preshape(Pre(kThumbOpposed, kCup, kCup, kCup, kTucked))
          .Close(Curl({D::kIndex, D::kMiddle, D::kRing}) + ThumbReach()),
      Builder(27, "Quadpod", R, O::kPad, T::kAbducted, {D::kThumb, D::kIndex, D::kMiddle, D::kRing})
          .Object(Sphere(0.0175)).Oppose().At(Anchor::kPinch).Approach(kFromPalm, 0.003)
          .Preshape(Pre(kThumbOpposed, kCup, kCup, kCup, kTucked))
          .Close(Curl({D::kIndex, D::kMiddle, D::kRing}) + ThumbReach()),
      Builder(28, "Sphere 3 Finger", P, O::kPad, T::kAbducted, {D::kThumb, D::kIndex, D::kMiddle})
          .Object(Sphere(0.0225)).Oppose().At(Anchor::kPinch).Approach(kFromPalm, 0.003)
          .Preshape(Pre(kThumbOpposed, kReady, kReady, kTucked, kTucked))
          .Close(Curl({D::kIndex, D::kMiddle}) + ThumbReach()),
      Builder(29, "Stick", I, O::kSide, T::kAdducted, {D::kThumb, D::kMiddle})
          .Object(Stick(0.003, 0.2), AxisAlong(kAlong - kFromPalm)).Oppose().At(Anchor::kPinch).Approach(kFromPalm, 0.002)
          .Preshape(Pre(kThumbOpposed, kReady, kReady, kTucked, kTucked))
          .Close(Curl({D::kMiddle, D::kIndex}) + ThumbReach()),
      Builder(30, "Palmar", P, O::kPalm, T::kAdducted, {D::kIndex, D::kMiddle, D::kRing, D::kLittle})
          .Object(Box(0.06, 0.1, 0.02)).At(Anchor::kProximalPhalanges)
          .Preshape(Pre(kThumbAdducted, kFlat, kFlat, kFlat, kFlat)).Close(Curl(all_fingers)),
      Builder(31, "Ring", P, O::kPad, T::kAbducted, {D::kThumb, D::kIndex})
          .Object(Cylinder(0.02, 0.15), AxisAlong(kAcross)).Oppose().At(Anchor::kProximalPhalanges)
          .Preshape(Pre(kThumbOpen, kFlat, kTucked, kTucked, kTucked)).Close(Curl({D::kIndex}) + ThumbReach()),
      Builder(32, "Ventral", I, O::kSide, T::kAdducted, {D::kThumb, D::kIndex})
          .Object(Stick(0.004, 0.1), AxisAlong(kAcross)).Oppose().At(Anchor::kPinch).Approach(kFromPalm, 0.002)
          .Preshape(Pre(kThumbOpposed, kReady, kTucked, kTucked, kTucked)).Close(Curl({D::kIndex}) + ThumbReach()),
      Builder(33, "Inferior Pincer", R, O::kPad, T::kAbducted, {D::kThumb, D::kIndex})
          .Object(Sphere(0.0075)).Oppose().At(Anchor::kPinch).Approach(kFromPalm, 0.002)
          .Preshape(Pre(kThumbOpposed, {15, 0, 10, 5}, kTucked, kTucked, kTucked)).Close(Curl({D::kIndex}) + ThumbReach()),
  };
  std::vector<GraspDefinition> grasps;
  for (Builder& builder : b) grasps.push_back(std::move(builder.g));
  return grasps;
}

}  // namespace

const std::vector<GraspDefinition>& GraspTaxonomy() {
  static const std::vector<GraspDefinition> kGrasps = Build();
  return kGrasps;
}

}  // namespace nphand
