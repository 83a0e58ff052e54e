// A scene: one posed hand and the objects it holds, placed in front of the camera.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "nphand/model/hand_pose.h"
#include "nphand/scene/object.h"

namespace nphand {

struct Scene {
  HandPose hand;                                            // articulation and camera_from_hand
  Eigen::Vector3d wrist_in_camera = Eigen::Vector3d(0, 0, 0.4);  // metres
  std::vector<SceneObject> objects;                         // placed in the hand frame
};

}  // namespace nphand
