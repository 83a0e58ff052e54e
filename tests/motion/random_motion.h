// Random tracks for the motion tests: wrist orientations uniform on the sphere of
// rotations, articulations within the limits, wrists 0.3-0.8 m in front of the camera.
#pragma once

#include <cstdint>

#include <Eigen/Geometry>

#include "nphand/motion/motion.h"
#include "nphand/util/random.h"

namespace nphand::testing {

inline Motion RandomMotion(Handedness side, int frames, double fps, double scale, uint64_t seed) {
  Random random(seed);
  Motion motion;
  motion.hand = side;
  motion.fps = fps;
  motion.scale = scale;
  for (int f = 0; f < frames; ++f) {
    MotionFrame frame;
    frame.pose.handedness = side;
    frame.pose.camera_from_hand = Eigen::Quaterniond(random.Normal(), random.Normal(), random.Normal(), random.Normal())
                                      .normalized()
                                      .toRotationMatrix();
    frame.pose.angles = RandomArticulation(random);
    frame.wrist_camera = Eigen::Vector3d(random.Uniform(-0.2, 0.2), random.Uniform(-0.2, 0.2), random.Uniform(0.3, 0.8));
    motion.frames.push_back(frame);
  }
  return motion;
}

}  // namespace nphand::testing
