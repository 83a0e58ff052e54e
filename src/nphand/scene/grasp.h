// The grasp library: the 33 grasp types of the GRASP taxonomy (Feix et al.), each applied
// to an object shape on which it is natural, closed onto the object so that the hand is
// physically consistent with it, and discretised into 5 time steps from pre-shape to grasp.
//
// Physically consistent: the fingers the taxonomy puts in contact touch the object's
// surface (gap under 3 mm) and no part of the hand mesh is inside it by more than 2 mm.
// Nothing is tuned by eye to get there: each grasp gives the object, where it sits relative
// to hand landmarks, a pre-shape and which joints close; MakeGrasp slides the object in
// until it nearly touches the hand, then closes each closing joint, proximal to distal,
// until the skin it moves reaches the object (or the joint its limit).
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "nphand/model/hand_model.h"
#include "nphand/scene/object.h"

namespace nphand {

enum class GraspType : uint8_t { kPower, kIntermediate, kPrecision };
enum class Opposition : uint8_t { kPalm, kPad, kSide };
enum class ThumbPlacement : uint8_t { kAbducted, kAdducted };
enum class Digit : uint8_t { kThumb, kIndex, kMiddle, kRing, kLittle };
std::string ToString(GraspType type);
std::string ToString(Opposition opposition);
std::string ToString(ThumbPlacement thumb);
std::string ToString(Digit digit);

inline constexpr int kNumGrasps = 33;
inline constexpr int kGraspSteps = 5;
using grasp_id_t = uint8_t;  // a hand shape's number: the taxonomy's 1..33, a gesture's after (gesture.h)

// Where the object goes, from landmarks of the pre-shaped hand (hand frame).
enum class Anchor : uint8_t {
  kPalmCentre,        // the middle of the palm: mean of the wrist and the four MCPs
  kProximalPhalanges, // mean of the contact fingers' proximal phalanx midpoints
  kMiddlePhalanges,   // mean of the contact fingers' middle phalanx midpoints
  kPinch,             // midway between the thumb tip and the contact fingers' tips
  kIndexMiddlePhalanx,// the index finger's middle phalanx midpoint
  kBetweenIndexMiddle,// midway between the index and middle fingers' DIP joints
};

// One closing motion: a joint from its pre-shape angle towards `target_rad`, or (dof ==
// kThumbReach) the thumb tip moved straight towards the object's centre by inverse
// kinematics over the five thumb angles.
struct ClosingMove {
  static constexpr int kThumbReach = -1;
  int dof;
  double target_rad;
};

struct GraspDefinition {
  grasp_id_t id = 0;
  std::string name;                   // "Large Diameter"
  GraspType type = GraspType::kPower;
  Opposition opposition = Opposition::kPalm;
  ThumbPlacement thumb = ThumbPlacement::kAbducted;
  std::vector<Digit> contacts;        // digits that must touch the object
  ObjectSpec object;
  Eigen::Matrix3d object_rotation = Eigen::Matrix3d::Identity();  // hand_from_object rotation
  bool align_with_pinch = false;      // turn the object's z onto the thumb-to-fingers line
  Anchor anchor = Anchor::kPalmCentre;
  Eigen::Vector3d anchor_offset = Eigen::Vector3d::Zero();  // metres, hand frame
  // The object slides from far along -approach towards the anchor and stops where the
  // pre-shaped hand is `gap` metres away, or at the anchor, whichever comes first.
  Eigen::Vector3d approach = Eigen::Vector3d::UnitZ();
  double gap = 0.003;
  JointAngles preshape{};
  // Before the object is placed, turn the thumb (inverse kinematics) so that its tip faces
  // the contact fingers' tips across the object: pad and side oppositions.
  bool oppose_thumb = false;
  std::vector<ClosingMove> closing;   // in order
};

// The 33 grasps in the taxonomy's order (index i holds grasp i + 1).
const std::vector<GraspDefinition>& GraspTaxonomy();
// The grasp whose name matches `name` case-insensitively, spaces or underscores alike
// ("large_diameter"); throws nphand::Error listing the names otherwise.
const GraspDefinition& GraspByName(const std::string& name);
// "large_diameter": the name as the CLI and files spell it.
std::string GraspKey(const GraspDefinition& definition);
// A name as the CLI and files spell it: lower case, spaces as underscores ("Thumbs Up" ->
// "thumbs_up").
std::string NameKey(const std::string& name);

struct Grasp {
  grasp_id_t id = 0;
  SceneObject object;                              // placed in the hand frame
  std::array<JointAngles, kGraspSteps> steps;      // pre-shape, ..., final grasp
};

// Places the object and closes the hand onto it (deterministic). steps[0] is the pre-shape
// (with the opposed thumb, if asked for), steps[4] the grasp, the others evenly between.
Grasp MakeGrasp(const HandModel& hand, const GraspDefinition& definition);

struct GraspContact {
  std::array<double, 5> digit_gap{};  // per digit: the nearest skin to the object surface, metres
  double penetration = 0.0;           // the deepest any vertex lies inside the object, metres
};
// How the hand at `angles` meets `object` (exact surface, see SignedDistance).
GraspContact MeasureContact(const HandModel& hand, const JointAngles& angles, const SceneObject& object);

}  // namespace nphand
