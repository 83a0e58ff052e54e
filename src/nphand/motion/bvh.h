// BVH (Biovision Hierarchy) motion: writing an estimated track, reading any BVH back.
//
// nphand's BVH: the root is the wrist (6 channels: Xposition Yposition Zposition Zrotation
// Xrotation Yrotation), every other joint of the generic hand has 3 rotation channels
// (Zrotation Xrotation Yrotation), the five fingertips are End Sites. A joint "thumb-base",
// a child of the wrist whose rotation channels stay zero, stands at the thumb's CMC keypoint
// (the thumb's base, behind the asset's thumb pivot: HandModel::bind_keypoints), its end
// site at the pivot: 21 joints with channels and 6 end sites. Units are centimetres, the world
// frame is WorldFromCamera()'s.
// In the rest pose (all channels zero) the skeleton is the model's bind pose, an open flat
// hand with its back towards +z, fingers towards +x and (right hand) thumb towards +y,
// scaled by the motion's scale; the root's rotation is the wrist's orientation.
#pragma once

#include <array>
#include <filesystem>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "nphand/model/hand_model.h"
#include "nphand/motion/motion.h"

namespace nphand {

inline constexpr double kBvhUnitsPerMetre = 100.0;
// The name of the joint at the thumb's CMC keypoint.
inline constexpr const char* kBvhThumbBase = "thumb-base";

// Writes `motion` of `hand` (the model of the motion's side) as BVH, atomically.
void WriteBvh(const HandModel& hand, const Motion& motion, const std::filesystem::path& path);
// The same text, for tests and callers that keep it in memory.
std::string BvhText(const HandModel& hand, const Motion& motion);

// A BVH file as read: its joints (end sites included) and its frames of channel values.
struct BvhJoint {
  std::string name;          // an end site is named "<parent name> end"
  int parent = -1;           // index into joints; -1 for a root
  Eigen::Vector3d offset;    // from the parent, in the file's units
  std::vector<std::string> channels;  // "Xposition", ..., "Zrotation"; empty for an end site
  int first_channel = 0;     // where its values start in a frame
  bool end_site = false;
};

struct Bvh {
  std::vector<BvhJoint> joints;
  int channels = 0;
  double frame_time_s = 0.0;
  std::vector<std::vector<double>> frames;  // each `channels` values

  // Index of the joint named `name`; -1 if none.
  int Find(const std::string& name) const;
  // Forward kinematics: every joint's position in frame `frame` (file units, world frame).
  std::vector<Eigen::Vector3d> Positions(size_t frame) const;
};

// Parses BVH text (any channel order); throws nphand::Error naming `source`, the line and
// the problem for a malformed file.
Bvh ParseBvh(const std::string& text, const std::string& source);
Bvh ReadBvh(const std::filesystem::path& path);

// The 21 keypoints of frame `frame` of an nphand BVH, back in the camera frame (metres).
// Throws nphand::Error if a joint of the generic hand is missing.
Keypoints3d BvhKeypoints(const Bvh& bvh, size_t frame);

}  // namespace nphand
