// The rigged hand: the generic-hand mesh, its skeleton, forward kinematics, linear-blend
// skinning and the 21 keypoints.
//
// Frames: the mesh is moved at load into the hand frame (origin at the wrist joint, x
// towards the middle finger's MCP, z out of the back of the hand). Posed outputs are in
// the camera orientation with the wrist at the origin: p = camera_from_hand * p_hand.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "nphand/model/hand_pose.h"
#include "nphand/model/skeleton.h"

namespace nphand {

// The folder holding right.glb and left.glb: $NPHAND_ASSET_DIR if set, else the first of
// AssetSearchDirs() that holds right.glb, else the first of them (for the error message).
// The build tree's share/nphand/hand links to the cache scripts/setup.sh fills; an install
// puts the meshes in <prefix>/share/nphand/hand.
std::filesystem::path DefaultAssetDir();
// share/nphand/hand in the folder of the binary holding nphand's code (the program, or a
// shared object such as the Python module), then in the folders above it (up to four
// levels), then the same for the running program; last, the configured install prefix's
// (for a program of one's own linked to an install in that prefix).
std::vector<std::filesystem::path> AssetSearchDirs();
// The pinned sha256 of the asset file of a hand (right.glb / left.glb of
// @webxr-input-profiles/assets@1.0.20).
const char* PinnedAssetSha256(Handedness handedness);
// "right.glb" or "left.glb".
std::string AssetFileName(Handedness handedness);

using Keypoints3d = std::array<Eigen::Vector3d, kNumKeypoints>;

// A hand's length from the wrist to the middle fingertip along its bones (keypoints 0, 9,
// 10, 11, 12): the same in every pose, so it gives a hand's size from any of its poses.
double HandLength(const Keypoints3d& keypoints);
// Per finger (index, middle, ring, little): straight, when the MCP-to-tip distance exceeds
// 0.75 of the finger's bone lengths (real-dev's scorer's finger states).
std::array<bool, 4> FingerStates(const Keypoints3d& keypoints);
using JointPositions = std::array<Eigen::Vector3d, kNumJoints>;

class HandModel {
 public:
  // Loads <asset_dir>/<right|left>.glb. Throws nphand::Error if it is missing, its sha256
  // differs from the pinned one, or it is not the expected rigged hand.
  static HandModel Load(Handedness handedness, const std::filesystem::path& asset_dir = DefaultAssetDir());
  // Parses a binary glTF already in memory (no hash check); `source` names it in errors.
  static HandModel FromGlb(std::span<const uint8_t> glb, Handedness handedness, const std::string& source);

  // The same hand with other proportions: the bind pose (mesh and joints) stretched about
  // the wrist by `length` along the hand (wrist towards the middle finger) and by `width`
  // across and through it, the joint frames made afresh. For hands unlike the database's:
  // bones ~10 % longer and narrower. Throws nphand::Error for factors outside [0.5, 2].
  HandModel Reproportioned(double length, double width) const;

  Handedness handedness() const { return handedness_; }
  // The mesh in its bind pose, in the hand frame (metres).
  const std::vector<Eigen::Vector3f>& bind_vertices() const { return bind_vertices_; }
  const std::vector<Eigen::Vector3f>& bind_normals() const { return bind_normals_; }
  const std::vector<Eigen::Vector3i>& triangles() const { return triangles_; }
  // The asset's mesh coordinates into the hand frame (a rigid motion, fixed at load).
  const Eigen::Isometry3d& hand_from_mesh() const { return hand_from_mesh_; }
  // Joint positions of the bind pose in the hand frame.
  const JointPositions& bind_joint_positions() const { return bind_positions_; }
  // The 21 keypoints of the bind pose in the hand frame: the joints', but where labelled
  // hands and other trackers put a keypoint elsewhere than the asset's joint:
  // - each fingertip at the end of its finger. The asset's tip joints lie within the last
  //   bones, 9.6-12.6 mm short of the skin's end (they move no skin); a fingertip is moved
  //   along its last bone to the farthest skin that bone moves.
  // - the thumb's CMC at the thumb's base. The asset's thumb pivot lies 8 mm out along the
  //   metacarpal from it (wrist to CMC 50 mm, CMC to MCP 33; InterHand2.6M's labels 38 and
  //   37); the keypoint is moved back along the metacarpal to the nearest skin the thumb
  //   moves, and it moves with the wrist, not with the thumb.
  const Keypoints3d& bind_keypoints() const { return bind_keypoints_; }
  // The mean of the bind-pose joint positions: a point near the middle of the hand, for
  // centring it in a view.
  Eigen::Vector3d bind_centre() const;
  // The anatomical frame of each joint in the bind pose (columns: bone, flexion axis,
  // dorsal normal), in the hand frame.
  const Eigen::Matrix3d& bind_joint_axes(int joint) const { return bind_axes_[joint]; }

  // The vertices whose skin weights on `joint` and the joints below it sum to at least
  // `min_weight`: the skin that moves with that joint.
  std::vector<int> VerticesMovedBy(int joint, float min_weight = 0.5f) const;

  // Forward kinematics: each joint's posed frame in the hand frame (before camera_from_hand).
  std::array<Eigen::Isometry3d, kNumJoints> JointTransforms(const JointAngles& angles) const;
  // Posed joint positions and keypoints in the camera orientation, wrist at the origin.
  JointPositions JointPositionsOf(const HandPose& pose) const;
  Keypoints3d KeypointsOf(const HandPose& pose) const;
  // Linear-blend skinning: posed vertices (and normals, if not null) in the camera
  // orientation, wrist at the origin. Outputs are resized to the vertex count.
  void Skin(const HandPose& pose, std::vector<Eigen::Vector3f>* vertices,
            std::vector<Eigen::Vector3f>* normals) const;

 private:
  HandModel() = default;
  void CheckHandedness(const HandPose& pose) const;
  // The joints' anatomical frames and the bind transforms, from bind_positions_.
  void SetJointFrames();
  // bind_keypoints_, from the joints and the mesh.
  void SetKeypoints();

  Handedness handedness_ = Handedness::kRight;
  std::vector<Eigen::Vector3f> bind_vertices_;
  std::vector<Eigen::Vector3f> bind_normals_;
  std::vector<Eigen::Vector3i> triangles_;
  std::vector<std::array<uint8_t, 4>> skin_joints_;
  std::vector<Eigen::Vector4f> skin_weights_;
  Eigen::Isometry3d hand_from_mesh_ = Eigen::Isometry3d::Identity();
  JointPositions bind_positions_;
  Keypoints3d bind_keypoints_;
  std::array<Eigen::Matrix3d, kNumJoints> bind_axes_;
  // Bind pose: each joint's frame relative to its parent's, and the inverse of its own.
  std::array<Eigen::Isometry3d, kNumJoints> parent_from_joint_;
  std::array<Eigen::Isometry3d, kNumJoints> joint_from_hand_;
};

}  // namespace nphand
