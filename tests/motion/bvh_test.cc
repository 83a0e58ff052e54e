#include "nphand/motion/bvh.h"

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "nphand/util/check.h"
#include "testing/testing.h"
#include "tests/motion/random_motion.h"

namespace nphand {
namespace {

double MaxKeypointDifference(const Keypoints3d& a, const Keypoints3d& b) {
  double worst = 0.0;
  for (int k = 0; k < kNumKeypoints; ++k) worst = std::max(worst, (a[k] - b[k]).norm());
  return worst;
}

TEST(BvhTest, ReadBackAndRunThroughForwardKinematicsItGivesTheKeypoints) {
  for (const HandModel* hand : {&testing::RightHand(), &testing::LeftHand()}) {
    const Motion motion = testing::RandomMotion(hand->handedness(), 40, 30.0, 1.08, 5);
    const auto path = testing::ScratchDir() / "hand.bvh";
    WriteBvh(*hand, motion, path);
    const Bvh bvh = ReadBvh(path);
    ASSERT_EQ(bvh.frames.size(), 40u);
    EXPECT_NEAR(bvh.frame_time_s, 1.0 / 30.0, 1e-6);
    // 20 with channels, 5 end sites, and the thumb's base and its end site.
    EXPECT_EQ(bvh.joints.size(), static_cast<size_t>(kNumJoints) + 2);
    EXPECT_EQ(bvh.channels, 6 + 20 * 3);
    double worst = 0.0;
    for (size_t f = 0; f < motion.frames.size(); ++f) {
      worst = std::max(worst, MaxKeypointDifference(BvhKeypoints(bvh, f), MotionKeypoints(*hand, motion, f)));
    }
    EXPECT_LT(worst, 1e-5) << ToString(hand->handedness()) << ": metres";
  }
}

TEST(BvhTest, RestPoseIsTheModelsBindPoseInCentimetres) {
  Motion motion;
  motion.frames.resize(1);
  motion.frames[0].pose.camera_from_hand = WorldFromCamera().transpose();  // no turn in the file's world
  const Bvh bvh = ParseBvh(BvhText(testing::RightHand(), motion), "rest.bvh");
  for (double value : bvh.frames[0]) EXPECT_NEAR(value, 0.0, 1e-6);
  const int tip = bvh.Find("middle-finger-phalanx-distal end");
  ASSERT_GE(tip, 0);
  const std::vector<Eigen::Vector3d> positions = bvh.Positions(0);
  // The end site is the fingertip keypoint (keypoint 12), the finger's end.
  const Eigen::Vector3d expected = kBvhUnitsPerMetre * testing::RightHand().bind_keypoints()[12];
  EXPECT_LT((positions[tip] - expected).norm(), 1e-4);
  const int dip = bvh.Find("middle-finger-phalanx-distal");
  ASSERT_GE(dip, 0);
  const Eigen::Vector3d dip_joint =
      kBvhUnitsPerMetre * testing::RightHand().bind_joint_positions()[Index(Joint::kMiddleDistal)];
  EXPECT_LT((positions[dip] - dip_joint).norm(), 1e-4);
  // The thumb's base is keypoint 1, behind the thumb's pivot; its end site is the pivot.
  const int base = bvh.Find(kBvhThumbBase);
  ASSERT_GE(base, 0);
  EXPECT_EQ(bvh.joints[base].parent, bvh.Find("wrist"));
  EXPECT_EQ(bvh.joints[base].channels, (std::vector<std::string>{"Zrotation", "Xrotation", "Yrotation"}));
  EXPECT_LT((positions[base] - kBvhUnitsPerMetre * testing::RightHand().bind_keypoints()[1]).norm(), 1e-4);
  const Eigen::Vector3d pivot =
      kBvhUnitsPerMetre * testing::RightHand().bind_joint_positions()[Index(Joint::kThumbMetacarpal)];
  EXPECT_LT((positions[bvh.Find(std::string(kBvhThumbBase) + " end")] - pivot).norm(), 1e-4);
}

// The thumb's base turns with the wrist only: its channels are zero in every frame. A file
// without it (another tool's, or nphand's before 2026-12-07) is read, but its keypoints are
// refused rather than given with the thumb's pivot for its CMC.
TEST(BvhTest, TheThumbsBaseStaysStillAndKeypointsNeedIt) {
  const Motion motion = testing::RandomMotion(Handedness::kRight, 3, 30.0, 1.0, 9);
  const std::string text = BvhText(testing::RightHand(), motion);
  const Bvh bvh = ParseBvh(text, "hand.bvh");
  const int base = bvh.Find(kBvhThumbBase);
  ASSERT_GE(base, 0);
  for (const std::vector<double>& values : bvh.frames) {
    for (int c = 0; c < 3; ++c) EXPECT_EQ(values[bvh.joints[base].first_channel + c], 0.0);
  }
  std::string renamed = text;
  renamed.replace(renamed.find(kBvhThumbBase), std::string(kBvhThumbBase).size(), "thumb-bose");
  const Bvh older = ParseBvh(renamed, "older.bvh");
  ASSERT_EQ(older.frames.size(), 3u);
  testing::ExpectError([&] { BvhKeypoints(older, 0); }, "no joint 'thumb-base' (the thumb's CMC keypoint");
}

TEST(BvhTest, AnyChannelOrderIsRead) {
  const std::string text =
      "HIERARCHY\nROOT a\n{\n  OFFSET 0 0 0\n  CHANNELS 6 Xposition Yposition Zposition Xrotation Yrotation Zrotation\n"
      "  JOINT b\n  {\n    OFFSET 1 0 0\n    CHANNELS 3 Yrotation Xrotation Zrotation\n"
      "    End Site\n    {\n      OFFSET 0 2 0\n    }\n  }\n}\nMOTION\nFrames: 1\nFrame Time: 0.04\n"
      "1 2 3 0 0 90 0 0 0\n";
  const Bvh bvh = ParseBvh(text, "small.bvh");
  ASSERT_EQ(bvh.joints.size(), 3u);
  const std::vector<Eigen::Vector3d> p = bvh.Positions(0);
  EXPECT_LT((p[1] - Eigen::Vector3d(1.0, 3.0, 3.0)).norm(), 1e-12);  // turned 90 degrees about z
  EXPECT_LT((p[2] - Eigen::Vector3d(-1.0, 3.0, 3.0)).norm(), 1e-12);
}

TEST(BvhTest, MalformedFilesAreRefusedWithTheLine) {
  const std::string head = "HIERARCHY\nROOT a\n{\n  OFFSET 0 0 0\n  CHANNELS 3 Xrotation Yrotation Zrotation\n}\n";
  const struct {
    std::string text, message;
  } cases[] = {
      {"", "expected 'HIERARCHY'"},
      {"HIERARCHY\nROOT a\n{\n  OFFSET 0 x 0\n", "small.bvh:4: 'x' is not a number (an offset)"},
      {"HIERARCHY\nROOT a\n{\n  OFFSET 0 0 0\n  CHANNELS 1 Wrotation\n}\n", "unknown channel 'Wrotation'"},
      {head, "no MOTION section"},
      {head + "MOTION\nFrames: 2\nFrame Time: 0.04\n1 2 3\n4 5\n", "the file ends where a channel value should be"},
      {head + "MOTION\nFrames: 1\nFrame Time: 0.04\n1 2 3 4\n", "more values than 1 frames hold"},
      {head + "MOTION\nFrames: 1\nFrame Time: 0\n1 2 3\n", "the frame time must be positive"},
      {"HIERARCHY\nJOINT a\n", "JOINT outside any joint"},
      {"HIERARCHY\nROOT a\n{\n  OFFSET 0 0 0\n  CHANNELS 0\n}\nMOTION\nFrames: 9999999\nFrame Time: 0.04\n",
       "no channels"},
  };
  for (const auto& c : cases) {
    try {
      ParseBvh(c.text, "small.bvh");
      ADD_FAILURE() << "accepted: " << c.text;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(c.message), std::string::npos) << e.what();
    }
  }
  // A hierarchy that is not the generic hand's has no keypoints.
  const Bvh other = ParseBvh(head + "MOTION\nFrames: 1\nFrame Time: 0.04\n1 2 3\n", "other.bvh");
  EXPECT_THROW(BvhKeypoints(other, 0), Error);
}

}  // namespace
}  // namespace nphand
