// A scene: one posed hand and the objects it holds, placed in front of the camera.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "nphand/model/hand_pose.h"
#include "nphand/scene/object.h"

namespace nphand {

// A forearm for frames that mimic a camera's: an elliptic truncated cone from inside the
// wrist along the hand frame's -x, its wrist end sized to the mesh's wrist cross-section
// (the database's hand has none; real frames always do), and optionally the upper arm
// beyond the elbow, held straight, as thick as the elbow end.
struct Forearm {
  double length = 0.24;               // metres, wrist to elbow end
  double elbow_width_scale = 1.35;    // the elbow end's radius across the hand's width over the wrist end's
  double elbow_depth_scale = 1.35;    // the same across the hand's thickness (palm to back)
  double upper_arm_length = 0.0;      // metres beyond the elbow (0: the arm ends there)
  bool Check(std::string* why) const;
  bool operator==(const Forearm&) const = default;

  // An adult's arm. The mesh's wrist is 5.3 x 3.3 cm across (the hand's width by its
  // thickness, 13.6 cm round); a forearm near the elbow is rounder and 24-29 cm round
  // (adult means, the smaller for hands of the mesh's 17.8 cm length), so the elbow end is
  // 8.5 x 6.9 cm (24.3 cm round), and the upper arm goes on 30 cm, so that the arm leaves
  // the frame or recedes as a real one does instead of ending in mid-air.
  static Forearm Adult() { return Forearm{0.24, 1.6, 2.1, 0.3}; }
};

struct Scene {
  HandPose hand;                                            // articulation and camera_from_hand
  Eigen::Vector3d wrist_in_camera = Eigen::Vector3d(0, 0, 0.4);  // metres
  std::vector<SceneObject> objects;                         // placed in the hand frame
  std::optional<Forearm> forearm;                           // none in the database
};

}  // namespace nphand
