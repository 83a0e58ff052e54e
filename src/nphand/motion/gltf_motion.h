// glTF motion: the rigged generic-hand mesh (the WebXR asset, MIT-licensed; its copyright
// and licence are written into the file's asset.copyright) with an estimated track as its
// one animation, "nphand": per frame, every joint node's translation and rotation (linear
// keys at frame / fps seconds). The tip joints' nodes stand at the fingertip keypoints, and
// a node "thumb-base", a child of the wrist's, at the thumb's CMC keypoint (the thumb's base,
// behind the asset's thumb pivot: HandModel::bind_keypoints). The world frame is
// WorldFromCamera()'s, in metres; the skeleton's root node is scaled by the motion's scale.
// Any glTF viewer plays it.
#pragma once

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "nphand/model/hand_model.h"
#include "nphand/motion/motion.h"

namespace nphand {

// The name of the node at the thumb's CMC keypoint.
inline constexpr const char* kGltfThumbBaseNode = "thumb-base";

// The file's bytes: `asset_glb` (the motion's side's .glb, as HandModel::Load reads it) with
// the animation added. `hand` is the model loaded from it. Throws nphand::Error if the
// asset's skeleton is not laid out as the generic hand's (joints under one unposed node).
std::vector<uint8_t> GltfMotionBytes(const HandModel& hand, std::span<const uint8_t> asset_glb, const Motion& motion);
// Writes them atomically.
void WriteGltfMotion(const HandModel& hand, std::span<const uint8_t> asset_glb, const Motion& motion,
                     const std::filesystem::path& path);

// An animated generic hand as read back: its skin's joints and, per key of its first
// animation, every joint's position in the file's world (metres).
struct GltfMotion {
  int joints = 0;
  double fps = 0.0;
  std::vector<JointPositions> frames;
  std::vector<Eigen::Vector3d> thumb_bases;  // per frame, the "thumb-base" node's position (none in other files)
  std::string copyright;
};
// Throws nphand::Error naming `source` for a file that is not a skinned generic hand with an
// animation whose channels all have the same keys.
GltfMotion ReadGltfMotion(std::span<const uint8_t> glb, const std::string& source);

// The 21 keypoints of a frame read back, in the camera frame (metres). Throws nphand::Error
// for a file without the thumb's base.
Keypoints3d GltfKeypoints(const GltfMotion& motion, size_t frame);

}  // namespace nphand
