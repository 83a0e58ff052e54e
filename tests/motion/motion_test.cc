#include "nphand/motion/motion.h"

#include <gtest/gtest.h>

#include "nphand/util/check.h"
#include "testing/testing.h"

namespace nphand {
namespace {

MotionFrame FrameAt(double x, Handedness hand = Handedness::kRight) {
  MotionFrame frame;
  frame.pose.handedness = hand;
  frame.wrist_camera = Eigen::Vector3d(x, 0.0, 0.5);
  return frame;
}

TEST(MotionTest, FramesWithoutTheHandHoldTheLastPoseAndLeadingOnesTakeTheFirst) {
  MotionRecorder recorder(Handedness::kRight, 25.0, 1.1);
  recorder.Add(std::nullopt);
  recorder.Add(std::nullopt);
  recorder.Add(FrameAt(1.0));
  recorder.Add(std::nullopt);
  recorder.Add(FrameAt(2.0, Handedness::kLeft));  // the other side: no hand of this track
  recorder.Add(FrameAt(3.0));
  const Motion motion = recorder.Finish();
  EXPECT_EQ(recorder.frames(), 6u);
  EXPECT_EQ(recorder.with_hand(), 2u);
  ASSERT_EQ(motion.frames.size(), 6u);
  const double expected[] = {1.0, 1.0, 1.0, 1.0, 1.0, 3.0};
  for (int f = 0; f < 6; ++f) EXPECT_EQ(motion.frames[f].wrist_camera.x(), expected[f]) << f;
  EXPECT_EQ(motion.fps, 25.0);
  EXPECT_EQ(motion.scale, 1.1);
}

TEST(MotionTest, AMotionWithoutAnyHandIsRefusedByName) {
  MotionRecorder recorder(Handedness::kLeft, 30.0, 1.0);
  recorder.Add(std::nullopt);
  recorder.Add(FrameAt(1.0, Handedness::kRight));
  try {
    recorder.Finish();
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("none of the 2 frames had a left hand"), std::string::npos) << e.what();
  }
  EXPECT_THROW(MotionRecorder(Handedness::kRight, 0.0, 1.0), Error);
  EXPECT_THROW(MotionRecorder(Handedness::kRight, 30.0, -1.0), Error);
}

TEST(MotionTest, KeypointsAreTheModelsScaledAtTheWrist) {
  Motion motion;
  motion.scale = 1.2;
  motion.frames = {FrameAt(0.1)};
  motion.frames[0].pose.angles = NamedArticulation("fist");
  const Keypoints3d model = testing::RightHand().KeypointsOf(motion.frames[0].pose);
  const Keypoints3d keypoints = MotionKeypoints(testing::RightHand(), motion, 0);
  for (int k = 0; k < kNumKeypoints; ++k) {
    EXPECT_LT((keypoints[k] - (motion.frames[0].wrist_camera + 1.2 * model[k])).norm(), 1e-12) << k;
  }
}

}  // namespace
}  // namespace nphand
