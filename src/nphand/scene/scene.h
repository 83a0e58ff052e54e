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
// (the database's hand has none; real frames always do).
struct Forearm {
  double length = 0.24;       // metres, wrist to elbow end
  double elbow_scale = 1.35;  // the elbow end's radii over the wrist end's
  bool Check(std::string* why) const;
};

struct Scene {
  HandPose hand;                                            // articulation and camera_from_hand
  Eigen::Vector3d wrist_in_camera = Eigen::Vector3d(0, 0, 0.4);  // metres
  std::vector<SceneObject> objects;                         // placed in the hand frame
  std::optional<Forearm> forearm;                           // none in the database
};

}  // namespace nphand
