// Motion out: an estimated track of hand poses as BVH (skeleton and joint angles, for
// animation and robotics tools) and as glTF (the rigged generic-hand mesh with the
// estimated animation).
//
// Both files share one world frame: the camera's turned to y up, z towards the viewer
// (x right, y up, z out of the screen: OpenGL's and most animation tools' convention).
// A point p in the camera frame (x right, y down, z forward) is (p.x, -p.y, -p.z) there.
#pragma once

#include <cstddef>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "nphand/model/hand_model.h"

namespace nphand {

// The world frame of the motion files from the camera's: diag(1, -1, -1).
Eigen::Matrix3d WorldFromCamera();

// One frame of motion: the hand's pose and where its wrist is.
struct MotionFrame {
  HandPose pose;
  Eigen::Vector3d wrist_camera = Eigen::Vector3d::Zero();  // metres, camera frame
};

struct Motion {
  Handedness hand = Handedness::kRight;
  double fps = 30.0;
  // The hand's size over the model's (the estimate's --hand-length over the model's
  // length): bones are this much longer than the mesh's.
  double scale = 1.0;
  std::vector<MotionFrame> frames;
};

// Collects a track frame by frame. A frame without a hand (or with the other hand) holds
// the last pose; frames before the first hand take the first hand's pose, so that the
// motion starts still rather than from a made-up pose.
class MotionRecorder {
 public:
  MotionRecorder(Handedness hand, double fps, double scale);
  // A frame with the hand (`frame` set, of the recorder's side) or without it.
  void Add(const std::optional<MotionFrame>& frame);
  size_t frames() const { return count_; }
  size_t with_hand() const { return with_hand_; }
  // The motion so far; throws nphand::Error when no frame had the hand (there is no pose
  // to show).
  Motion Finish() const;

 private:
  Motion motion_;
  size_t count_ = 0, with_hand_ = 0, leading_ = 0;
};

// The 21 keypoints of a motion's frame in the camera frame (metres): the model's, scaled,
// at the frame's wrist. What the motion files must reproduce.
Keypoints3d MotionKeypoints(const HandModel& hand, const Motion& motion, size_t frame);

}  // namespace nphand
