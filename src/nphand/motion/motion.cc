#include "nphand/motion/motion.h"

#include <cmath>

#include "nphand/util/check.h"

namespace nphand {

Eigen::Matrix3d WorldFromCamera() { return Eigen::Vector3d(1.0, -1.0, -1.0).asDiagonal(); }

MotionRecorder::MotionRecorder(Handedness hand, double fps, double scale) {
  NPHAND_THROW_CHECK(fps > 0.0 && std::isfinite(fps), "motion: the frame rate must be positive, not ", fps);
  NPHAND_THROW_CHECK(scale > 0.0 && std::isfinite(scale), "motion: the hand's scale must be positive, not ", scale);
  motion_.hand = hand;
  motion_.fps = fps;
  motion_.scale = scale;
}

void MotionRecorder::Add(const std::optional<MotionFrame>& frame) {
  ++count_;
  if (!frame.has_value() || frame->pose.handedness != motion_.hand) {
    if (motion_.frames.empty()) {
      ++leading_;
    } else {
      motion_.frames.push_back(motion_.frames.back());
    }
    return;
  }
  if (motion_.frames.empty()) motion_.frames.assign(leading_, *frame);
  motion_.frames.push_back(*frame);
  ++with_hand_;
}

Motion MotionRecorder::Finish() const {
  NPHAND_THROW_CHECK(with_hand_ > 0, "motion: none of the ", count_, " frames had a ", ToString(motion_.hand),
                     " hand, so there is no motion to write");
  return motion_;
}

Keypoints3d MotionKeypoints(const HandModel& hand, const Motion& motion, size_t frame) {
  NPHAND_CHECK(frame < motion.frames.size());
  const MotionFrame& f = motion.frames[frame];
  Keypoints3d keypoints = hand.KeypointsOf(f.pose);
  for (Eigen::Vector3d& k : keypoints) k = f.wrist_camera + motion.scale * k;
  return keypoints;
}

}  // namespace nphand
