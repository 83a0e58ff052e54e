// The hand skeleton: the 25 joints of the generic-hand mesh (WebXR hand joint names) and
// the 21 standard keypoints (MediaPipe / OpenPose order) taken from them.
#pragma once

#include <array>
#include <cstdint>
#include <string>

namespace nphand {

// Joints in the order of the mesh's skin; each joint's node sits at its bone's head.
enum class Joint : uint8_t {
  kWrist,
  kThumbMetacarpal, kThumbProximal, kThumbDistal, kThumbTip,
  kIndexMetacarpal, kIndexProximal, kIndexIntermediate, kIndexDistal, kIndexTip,
  kMiddleMetacarpal, kMiddleProximal, kMiddleIntermediate, kMiddleDistal, kMiddleTip,
  kRingMetacarpal, kRingProximal, kRingIntermediate, kRingDistal, kRingTip,
  kLittleMetacarpal, kLittleProximal, kLittleIntermediate, kLittleDistal, kLittleTip,
};
inline constexpr int kNumJoints = 25;
inline constexpr int Index(Joint j) { return static_cast<int>(j); }

// The WebXR name of a joint ("index-finger-phalanx-proximal"), as the mesh's nodes are named.
const char* JointName(Joint joint);
// The joint's parent in the kinematic tree; the wrist is the root and has none (returns -1).
int JointParent(int joint);
// True for the five tip joints (each finger's last, beyond its last bone's joint).
bool IsTipJoint(int joint);
// True when `joint` is `ancestor` or lies below it in the tree.
bool IsInSubtree(int joint, int ancestor);

// The 21 standard keypoints: wrist; thumb CMC, MCP, IP, tip; then for index, middle, ring
// and little finger: MCP, PIP, DIP, tip.
inline constexpr int kNumKeypoints = 21;
// The joint whose position is keypoint k, or that it stands for: a fingertip is the finger's
// end, past its tip joint and moving with it; the thumb's CMC (kThumbBaseKeypoint) is the
// thumb's base, behind the thumb-metacarpal joint and moving with the wrist
// (HandModel::bind_keypoints).
Joint KeypointJoint(int keypoint);
// The thumb's CMC keypoint.
inline constexpr int kThumbBaseKeypoint = 1;
// The keypoint of `joint` (-1 for the four finger metacarpals, which have none).
int JointKeypoint(int joint);
// A short name of keypoint k ("index_pip").
const char* KeypointName(int keypoint);
// The keypoint that keypoint k connects to towards the wrist (-1 for the wrist), for drawing.
int KeypointParent(int keypoint);

}  // namespace nphand
