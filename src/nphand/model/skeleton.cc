#include "nphand/model/skeleton.h"

#include <algorithm>

#include "nphand/util/check.h"

namespace nphand {
namespace {

constexpr std::array<const char*, kNumJoints> kJointNames = {
    "wrist",
    "thumb-metacarpal", "thumb-phalanx-proximal", "thumb-phalanx-distal", "thumb-tip",
    "index-finger-metacarpal", "index-finger-phalanx-proximal", "index-finger-phalanx-intermediate",
    "index-finger-phalanx-distal", "index-finger-tip",
    "middle-finger-metacarpal", "middle-finger-phalanx-proximal", "middle-finger-phalanx-intermediate",
    "middle-finger-phalanx-distal", "middle-finger-tip",
    "ring-finger-metacarpal", "ring-finger-phalanx-proximal", "ring-finger-phalanx-intermediate",
    "ring-finger-phalanx-distal", "ring-finger-tip",
    "pinky-finger-metacarpal", "pinky-finger-phalanx-proximal", "pinky-finger-phalanx-intermediate",
    "pinky-finger-phalanx-distal", "pinky-finger-tip",
};

constexpr std::array<int, kNumKeypoints> kKeypointJoints = {
    0, 1, 2, 3, 4, 6, 7, 8, 9, 11, 12, 13, 14, 16, 17, 18, 19, 21, 22, 23, 24};

constexpr std::array<const char*, kNumKeypoints> kKeypointNames = {
    "wrist",     "thumb_cmc",  "thumb_mcp",  "thumb_ip",   "thumb_tip",  "index_mcp",  "index_pip",
    "index_dip", "index_tip",  "middle_mcp", "middle_pip", "middle_dip", "middle_tip", "ring_mcp",
    "ring_pip",  "ring_dip",   "ring_tip",   "little_mcp", "little_pip", "little_dip", "little_tip"};

}  // namespace

const char* JointName(Joint joint) { return kJointNames[Index(joint)]; }

int JointParent(int joint) {
  NPHAND_CHECK(joint >= 0 && joint < kNumJoints);
  if (joint == 0) return -1;
  // Metacarpals (first joint of each chain: 1, 5, 10, 15, 20) hang off the wrist.
  if (joint == 1 || (joint >= 5 && (joint - 5) % 5 == 0)) return 0;
  return joint - 1;
}

bool IsTipJoint(int joint) { return joint == Index(Joint::kThumbTip) || (joint >= 9 && (joint - 9) % 5 == 0); }

bool IsInSubtree(int joint, int ancestor) {
  for (int j = joint; j >= 0; j = JointParent(j)) {
    if (j == ancestor) return true;
  }
  return false;
}

Joint KeypointJoint(int keypoint) {
  NPHAND_CHECK(keypoint >= 0 && keypoint < kNumKeypoints);
  return static_cast<Joint>(kKeypointJoints[keypoint]);
}

int JointKeypoint(int joint) {
  NPHAND_CHECK(joint >= 0 && joint < kNumJoints);
  const auto at = std::find(kKeypointJoints.begin(), kKeypointJoints.end(), joint);
  return at == kKeypointJoints.end() ? -1 : static_cast<int>(at - kKeypointJoints.begin());
}

const char* KeypointName(int keypoint) {
  NPHAND_CHECK(keypoint >= 0 && keypoint < kNumKeypoints);
  return kKeypointNames[keypoint];
}

int KeypointParent(int keypoint) {
  NPHAND_CHECK(keypoint >= 0 && keypoint < kNumKeypoints);
  if (keypoint == 0) return -1;
  return (keypoint - 1) % 4 == 0 ? 0 : keypoint - 1;
}

}  // namespace nphand
