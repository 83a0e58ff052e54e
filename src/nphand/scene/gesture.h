// Gestures: hand shapes held in the air, with no object: a fist, a pointing finger, a
// victory sign, a thumbs-up, an open palm and the rest of the shapes people show a camera.
// The GRASP taxonomy has none of them (its hands close on objects), so a database of grasps
// alone answers a victory sign with the nearest grasp. The default database holds them
// beside the grasps (`nphand db build --gestures none` leaves them out).
//
// Grasps and gestures share one numbering of hand shapes: 1..33 are the taxonomy's grasps,
// 34.. the gestures in this file's order. A gesture's 5 steps run from 40 % of the way
// from the relaxed hand to the gesture, to the gesture: the hand forming it, never the
// relaxed hand itself, which every gesture would share.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "nphand/model/hand_pose.h"
#include "nphand/scene/grasp.h"

namespace nphand {

inline constexpr int kNumGestures = 16;
inline constexpr int kFirstGestureId = kNumGrasps + 1;
inline constexpr int kNumHandShapes = kNumGrasps + kNumGestures;  // shape numbers 1..kNumHandShapes

struct GestureDefinition {
  int id = 0;                  // kFirstGestureId ..
  std::string name;            // "peace"
  JointAngles shape{};         // the held gesture
  std::array<bool, 4> extended{};  // index, middle, ring, little: straight (true) or curled at the PIP
};

// The gestures in their order (index i holds shape number kFirstGestureId + i).
const std::vector<GestureDefinition>& Gestures();
// Their shape numbers, kFirstGestureId .. kNumHandShapes.
std::vector<int> GestureIds();
// The shape numbers of gestures named as a user names them: names (GestureByName), "all"
// alone (every gesture) or "none" alone (no gesture; so does an empty list). Throws
// nphand::Error, starting with `what`, for "all" or "none" among other names.
std::vector<int> GestureIdsNamed(const std::vector<std::string>& names, const std::string& what);
// The gesture named `name` (case-insensitive, spaces or underscores alike); throws
// nphand::Error listing the names otherwise.
const GestureDefinition& GestureByName(const std::string& name);
bool IsGesture(int shape);
// The gesture's steps: steps[4] the gesture, the others between 40 % of the way from the
// relaxed hand and the gesture.
std::array<JointAngles, kGraspSteps> GestureSteps(const GestureDefinition& gesture);
// "large_diameter" or "peace": a shape number's name as the CLI and files spell it.
std::string HandShapeKey(int shape);

}  // namespace nphand
