#include "nphand/scene/grasp.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <numbers>

#include <Eigen/Geometry>

#include "nphand/util/check.h"

namespace nphand {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;
// A closing joint stops when the skin it moves comes this close to the object.
constexpr double kContactDistance = 0.001;
constexpr double kClosingStep = 0.5 * kDeg;
// A contact digit counts as touching below this gap; the object settles at most this often.
constexpr double kTouchingGap = 0.0025;
constexpr int kSettleSteps = 12;
constexpr double kSettlePenetration = 0.001;

// The first joint of each digit whose skin counts as that digit's (thumb: its proximal
// phalanx; fingers: the proximal phalanx).
constexpr std::array<Joint, 5> kDigitRoot = {Joint::kThumbProximal, Joint::kIndexProximal, Joint::kMiddleProximal,
                                            Joint::kRingProximal, Joint::kLittleProximal};
constexpr std::array<Joint, 5> kDigitTip = {Joint::kThumbTip, Joint::kIndexTip, Joint::kMiddleTip, Joint::kRingTip,
                                           Joint::kLittleTip};

int DigitIndex(Digit d) { return static_cast<int>(d); }

double MinDistance(const std::vector<Eigen::Vector3f>& vertices, const std::vector<int>& subset,
                   const SceneObject& object) {
  const Eigen::Isometry3d object_from_hand = object.hand_from_object.inverse();
  double nearest = std::numeric_limits<double>::infinity();
  for (int v : subset) {
    nearest = std::min(nearest, SignedDistance(object.spec, object_from_hand * vertices[v].cast<double>()));
  }
  return nearest;
}

std::vector<int> AllVertices(const HandModel& hand) {
  std::vector<int> all(hand.bind_vertices().size());
  for (size_t v = 0; v < all.size(); ++v) all[v] = static_cast<int>(v);
  return all;
}

HandPose PoseOf(const HandModel& hand, const JointAngles& angles) {
  HandPose pose;
  pose.handedness = hand.handedness();
  pose.angles = angles;
  return pose;
}

Eigen::Vector3d Midpoint(const JointPositions& p, Joint a, Joint b) { return 0.5 * (p[Index(a)] + p[Index(b)]); }

// The mean tip position of the contact fingers (not the thumb).
Eigen::Vector3d FingertipCentroid(const GraspDefinition& g, const JointPositions& joints) {
  Eigen::Vector3d tips = Eigen::Vector3d::Zero();
  int fingers = 0;
  for (Digit d : g.contacts) {
    if (d == Digit::kThumb) continue;
    tips += joints[Index(kDigitTip[DigitIndex(d)])];
    ++fingers;
  }
  NPHAND_THROW_CHECK(fingers > 0, "grasp ", g.name, ": needs a contact finger");
  return tips / fingers;
}

Eigen::Vector3d AnchorPoint(const GraspDefinition& g, const JointPositions& p) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  int count = 0;
  const auto fingers = [&](int from_root) {
    for (Digit d : g.contacts) {
      if (d == Digit::kThumb) continue;
      const int root = Index(kDigitRoot[DigitIndex(d)]);
      sum += Midpoint(p, static_cast<Joint>(root + from_root), static_cast<Joint>(root + from_root + 1));
      ++count;
    }
  };
  switch (g.anchor) {
    case Anchor::kPalmCentre:
      for (Joint j : {Joint::kWrist, Joint::kIndexProximal, Joint::kMiddleProximal, Joint::kRingProximal,
                      Joint::kLittleProximal}) {
        sum += p[Index(j)];
        ++count;
      }
      break;
    case Anchor::kProximalPhalanges: fingers(0); break;
    case Anchor::kMiddlePhalanges: fingers(1); break;
    case Anchor::kPinch:
      sum = 0.5 * (p[Index(Joint::kThumbTip)] + FingertipCentroid(g, p));
      count = 1;
      break;
    case Anchor::kIndexMiddlePhalanx:
      sum = Midpoint(p, Joint::kIndexIntermediate, Joint::kIndexDistal);
      count = 1;
      break;
    case Anchor::kBetweenIndexMiddle:
      sum = Midpoint(p, Joint::kIndexDistal, Joint::kMiddleDistal);
      count = 1;
      break;
  }
  NPHAND_THROW_CHECK(count > 0, "grasp ", g.name, ": the anchor has no landmark");
  return sum / count + g.anchor_offset;
}

// Slides the object from far along -approach towards `anchor` until the hand is `gap` away.
Eigen::Vector3d PlaceObject(const GraspDefinition& g, const std::vector<Eigen::Vector3f>& vertices,
                            const std::vector<int>& all, const Eigen::Vector3d& anchor, SceneObject* object) {
  const auto distance_at = [&](double s) {
    object->hand_from_object.translation() = anchor - s * g.approach.normalized();
    return MinDistance(vertices, all, *object);
  };
  if (distance_at(0.0) >= g.gap) return anchor;
  double near = 0.0, far = 0.4;
  NPHAND_THROW_CHECK(distance_at(far) > g.gap, "grasp ", g.name, ": the object cannot be moved clear of the hand");
  for (int i = 0; i < 40; ++i) {
    const double mid = 0.5 * (near + far);
    (distance_at(mid) >= g.gap ? far : near) = mid;
  }
  distance_at(far);
  return object->hand_from_object.translation();
}

Eigen::Vector3d ThumbTip(const HandModel& hand, const JointAngles& angles) {
  return hand.JointTransforms(angles)[Index(Joint::kThumbTip)].translation();
}

// One damped least-squares step of the five thumb angles that moves the thumb tip by
// about `delta` (hand frame), within the joint limits.
JointAngles ThumbStep(const HandModel& hand, const JointAngles& angles, const Eigen::Vector3d& delta) {
  constexpr double kH = 1e-5, kDamping = 0.01;
  const Eigen::Vector3d tip = ThumbTip(hand, angles);
  Eigen::Matrix<double, 3, 5> jacobian;
  for (int i = 0; i < 5; ++i) {
    JointAngles moved = angles;
    moved[i] += kH;
    jacobian.col(i) = (ThumbTip(hand, moved) - tip) / kH;
  }
  const Eigen::Matrix3d jjt = jacobian * jacobian.transpose() + kDamping * kDamping * Eigen::Matrix3d::Identity();
  const Eigen::Matrix<double, 5, 1> step = jacobian.transpose() * jjt.ldlt().solve(delta);
  JointAngles next = angles;
  for (int i = 0; i < 5; ++i) next[i] += step[i];
  return ClampToLimits(next);
}

// The thumb turned so that its tip lies `distance` from `fingers` on its own side.
JointAngles OpposeThumb(const HandModel& hand, JointAngles angles, const Eigen::Vector3d& fingers, double distance) {
  for (int i = 0; i < 300; ++i) {
    const Eigen::Vector3d tip = ThumbTip(hand, angles);
    Eigen::Vector3d away = tip - fingers;
    if (away.norm() < 1e-9) away = -Eigen::Vector3d::UnitZ();
    Eigen::Vector3d delta = fingers + distance * away.normalized() - tip;
    if (delta.norm() < 1e-5) break;
    if (delta.norm() > 0.002) delta *= 0.002 / delta.norm();
    angles = ThumbStep(hand, angles, delta);
  }
  return angles;
}

// Moves the thumb tip towards `centre` in 1 mm steps while `clear(angles)` holds; the last
// step that would touch is shortened by bisection. Stops when the thumb can move no further.
template <typename Clear>
JointAngles ReachWithThumb(const HandModel& hand, JointAngles angles, const Eigen::Vector3d& centre, Clear clear) {
  if (!clear(angles)) return angles;
  for (int i = 0; i < 300; ++i) {
    const Eigen::Vector3d tip = ThumbTip(hand, angles);
    const Eigen::Vector3d towards = centre - tip;
    if (towards.norm() < 1e-4) break;
    const Eigen::Vector3d delta = 0.001 * towards.normalized();
    const JointAngles next = ThumbStep(hand, angles, delta);
    if ((ThumbTip(hand, next) - tip).norm() < 1e-5) break;  // at the joint limits
    if (clear(next)) {
      angles = next;
      continue;
    }
    double low = 0.0, high = 1.0;
    for (int k = 0; k < 10; ++k) {
      const double mid = 0.5 * (low + high);
      (clear(ThumbStep(hand, angles, mid * delta)) ? low : high) = mid;
    }
    if (low > 0.0) angles = ThumbStep(hand, angles, low * delta);
    break;
  }
  return angles;
}

// The smallest distance from the object's centre to its surface (0 if the centre is outside).
double Inradius(const ObjectSpec& spec) { return std::max(0.0, -SignedDistance(spec, Eigen::Vector3d::Zero())); }

}  // namespace

std::string ToString(GraspType type) {
  constexpr std::array<const char*, 3> kNames = {"power", "intermediate", "precision"};
  return kNames[static_cast<int>(type)];
}
std::string ToString(Opposition opposition) {
  constexpr std::array<const char*, 3> kNames = {"palm", "pad", "side"};
  return kNames[static_cast<int>(opposition)];
}
std::string ToString(ThumbPlacement thumb) { return thumb == ThumbPlacement::kAbducted ? "abducted" : "adducted"; }
std::string ToString(Digit digit) {
  constexpr std::array<const char*, 5> kNames = {"thumb", "index", "middle", "ring", "little"};
  return kNames[DigitIndex(digit)];
}

std::string NameKey(const std::string& name) {
  std::string key;
  for (char c : name) key.push_back(c == ' ' ? '_' : static_cast<char>(std::tolower(static_cast<unsigned char>(c))));
  return key;
}

std::string GraspKey(const GraspDefinition& definition) { return NameKey(definition.name); }

const GraspDefinition& GraspByName(const std::string& name) {
  const std::string key = NameKey(name);
  std::string choices;
  for (const GraspDefinition& g : GraspTaxonomy()) {
    if (GraspKey(g) == key) return g;
    choices += (choices.empty() ? "" : ", ") + GraspKey(g);
  }
  NPHAND_THROW("unknown grasp '", name, "' (choices: ", choices, ")");
}

GraspContact MeasureContact(const HandModel& hand, const JointAngles& angles, const SceneObject& object) {
  std::vector<Eigen::Vector3f> vertices;
  hand.Skin(PoseOf(hand, angles), &vertices, nullptr);
  GraspContact contact;
  contact.penetration = std::max(0.0, -MinDistance(vertices, AllVertices(hand), object));
  for (int d = 0; d < 5; ++d) {
    contact.digit_gap[d] = MinDistance(vertices, hand.VerticesMovedBy(Index(kDigitRoot[d])), object);
  }
  return contact;
}

namespace {

// Closes each closing motion in turn, from `preshape`, until the skin it moves reaches the
// object (or the motion ends).
JointAngles CloseHand(const HandModel& hand, const GraspDefinition& g, const JointAngles& preshape,
                      const SceneObject& object) {
  std::vector<Eigen::Vector3f> vertices;
  const auto distance_of = [&](const JointAngles& trial, const std::vector<int>& movers) {
    hand.Skin(PoseOf(hand, trial), &vertices, nullptr);
    return MinDistance(vertices, movers, object);
  };
  // The thumb stops when its phalanges touch; its metacarpal's skin may only graze.
  const std::vector<int> thumb_phalanges = hand.VerticesMovedBy(Index(Joint::kThumbProximal));
  const std::vector<int> thumb_skin = hand.VerticesMovedBy(Index(Joint::kThumbMetacarpal), 0.01f);
  const auto thumb_clear = [&](const JointAngles& trial) {
    return distance_of(trial, thumb_phalanges) > kContactDistance && MinDistance(vertices, thumb_skin, object) > -0.001;
  };

  JointAngles angles = preshape;
  for (const ClosingMove& move : g.closing) {
    if (move.dof == ClosingMove::kThumbReach) {
      angles = ReachWithThumb(hand, angles, object.hand_from_object.translation(), thumb_clear);
      continue;
    }
    const DofInfo& dof = Dofs()[move.dof];
    const std::vector<int> movers = hand.VerticesMovedBy(Index(dof.joint));
    const double target = std::clamp(move.target_rad, dof.min_rad, dof.max_rad);
    const double direction = target >= angles[move.dof] ? 1.0 : -1.0;
    const auto distance_at = [&](double angle) {
      JointAngles trial = angles;
      trial[move.dof] = angle;
      return distance_of(trial, movers);
    };
    double free = angles[move.dof];
    if (distance_at(free) <= kContactDistance) continue;
    while (direction * (target - free) > 0.0) {
      const double next = direction > 0 ? std::min(target, free + kClosingStep) : std::max(target, free - kClosingStep);
      if (distance_at(next) > kContactDistance) {
        free = next;
        continue;
      }
      double blocked = next;
      for (int i = 0; i < 12; ++i) {
        const double mid = 0.5 * (free + blocked);
        (distance_at(mid) > kContactDistance ? free : blocked) = mid;
      }
      break;
    }
    angles[move.dof] = free;
  }
  return angles;
}

// `preshape` with each finger that the object penetrates opened (its flexion angles scaled
// by 0.6, up to four times) until it clears.
JointAngles OpenToAdmit(const HandModel& hand, JointAngles preshape, const SceneObject& object) {
  for (int opening = 0; opening < 4; ++opening) {
    const GraspContact contact = MeasureContact(hand, preshape, object);
    bool opened = false;
    for (int d = 1; d < 5; ++d) {
      if (contact.digit_gap[d] >= -kSettlePenetration) continue;
      for (int k : {0, 2, 3}) preshape[5 + 4 * (d - 1) + k] *= 0.6;
      opened = true;
    }
    if (!opened) break;
  }
  return preshape;
}

}  // namespace

Grasp MakeGrasp(const HandModel& hand, const GraspDefinition& g) {
  std::string why;
  NPHAND_THROW_CHECK(g.object.Check(&why), g.name, ": ", why);
  Grasp grasp;
  grasp.id = g.id;
  grasp.object.spec = g.object;
  JointAngles preshape = ClampToLimits(g.preshape);
  if (g.oppose_thumb) {
    const Eigen::Vector3d tips = FingertipCentroid(g, hand.JointPositionsOf(PoseOf(hand, preshape)));
    preshape = OpposeThumb(hand, preshape, tips, 2.0 * Inradius(g.object) + 0.02);
  }
  const JointPositions landmarks = hand.JointPositionsOf(PoseOf(hand, preshape));

  Eigen::Matrix3d rotation = g.object_rotation;
  if (g.align_with_pinch) {
    const Eigen::Vector3d line = FingertipCentroid(g, landmarks) - landmarks[Index(Joint::kThumbTip)];
    rotation = Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), line.normalized()).toRotationMatrix() *
               g.object_rotation;
  }
  grasp.object.hand_from_object.linear() = rotation;

  std::vector<Eigen::Vector3f> vertices;
  hand.Skin(PoseOf(hand, preshape), &vertices, nullptr);
  PlaceObject(g, vertices, AllVertices(hand), AnchorPoint(g, landmarks), &grasp.object);

  // Close; then, while a contact digit misses the object, let the object settle towards
  // the digits that miss it and close again from the pre-shape.
  JointAngles angles = CloseHand(hand, g, preshape, grasp.object);
  for (int settle = 0; settle < kSettleSteps; ++settle) {
    const GraspContact contact = MeasureContact(hand, angles, grasp.object);
    const JointPositions joints = hand.JointPositionsOf(PoseOf(hand, angles));
    Eigen::Vector3d shift = Eigen::Vector3d::Zero();
    for (Digit d : g.contacts) {
      const double gap = contact.digit_gap[DigitIndex(d)];
      if (gap < kTouchingGap) continue;
      const Eigen::Vector3d towards = joints[Index(kDigitTip[DigitIndex(d)])] - grasp.object.hand_from_object.translation();
      shift += std::min(gap, 0.004) * towards.normalized();
    }
    if (shift.isZero()) break;
    // Settle no further than the hand allows: fingers in the object's new way open their
    // pre-shape (flexion scaled down) to admit it; otherwise halve the shift while it would
    // push the object into the pre-shaped or the closed hand.
    bool moved = false;
    for (int halving = 0; halving < 5 && !moved; ++halving, shift /= 2.0) {
      SceneObject trial = grasp.object;
      trial.hand_from_object.translation() += shift;
      const JointAngles opened = OpenToAdmit(hand, preshape, trial);
      if (MeasureContact(hand, opened, trial).penetration > kSettlePenetration) continue;
      const JointAngles closed = CloseHand(hand, g, opened, trial);
      if (MeasureContact(hand, closed, trial).penetration > kSettlePenetration) continue;
      grasp.object = trial;
      preshape = opened;
      angles = closed;
      moved = true;
    }
    if (!moved) break;
  }

  for (int k = 0; k < kGraspSteps; ++k) {
    const double t = static_cast<double>(k) / (kGraspSteps - 1);
    for (int i = 0; i < kNumDofs; ++i) grasp.steps[k][i] = preshape[i] + t * (angles[i] - preshape[i]);
  }
  return grasp;
}

}  // namespace nphand
