#include "nphand/model/hand_pose.h"

#include <cmath>
#include <numbers>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "nphand/util/check.h"
#include "testing/testing.h"

namespace nphand {
namespace {

Eigen::Matrix3d RandomRotation(Random& random) {
  Eigen::Quaterniond q(random.Normal(), random.Normal(), random.Normal(), random.Normal());
  return q.normalized().toRotationMatrix();
}

TEST(HandPoseTest, LimitsAreOrderedAndInvertibleThroughSines) {
  EXPECT_GE(kNumDofs, 20);
  for (const DofInfo& dof : Dofs()) {
    EXPECT_LT(dof.min_rad, dof.max_rad) << dof.name;
    EXPECT_LE(dof.min_rad, 0.0) << dof.name << ": the rest pose must be within limits";
    EXPECT_GE(dof.max_rad, 0.0) << dof.name;
    EXPECT_GE(dof.min_rad, -std::numbers::pi / 2) << dof.name;
    EXPECT_LE(dof.max_rad, std::numbers::pi / 2) << dof.name;
    EXPECT_EQ(Dofs()[DofFromString(dof.name)].name, dof.name);
  }
  EXPECT_THROW(DofFromString("elbow"), Error);
}

TEST(HandPoseTest, PoseVectorRoundTripsForAnyValidPose) {
  Random random(testing::kTestSeed);
  for (int trial = 0; trial < 200; ++trial) {
    HandPose pose;
    pose.handedness = trial % 2 ? Handedness::kLeft : Handedness::kRight;
    pose.camera_from_hand = RandomRotation(random);
    pose.angles = RandomArticulation(random);
    ASSERT_TRUE(pose.IsValid());
    const HandPose back = FromPoseVector(ToPoseVector(pose), pose.handedness);
    EXPECT_EQ(back.handedness, pose.handedness);
    EXPECT_LT((back.camera_from_hand - pose.camera_from_hand).norm(), 1e-12);
    for (int i = 0; i < kNumDofs; ++i) EXPECT_NEAR(back.angles[i], pose.angles[i], 1e-9) << Dofs()[i].name;
  }
}

TEST(HandPoseTest, FromPoseVectorProjectsNoisyRotationsAndRejectsNaN) {
  Random random(testing::kTestSeed);
  HandPose pose;
  pose.camera_from_hand = RandomRotation(random);
  PoseVector vector = ToPoseVector(pose);
  for (int i = 0; i < 9; ++i) vector[i] += 0.01 * random.Normal();
  const HandPose back = FromPoseVector(vector, Handedness::kRight);
  EXPECT_TRUE(back.IsValid());
  EXPECT_LT((back.camera_from_hand - pose.camera_from_hand).norm(), 0.05);
  vector[3] = std::nan("");
  EXPECT_THROW(FromPoseVector(vector, Handedness::kRight), Error);
}

TEST(HandPoseTest, ClampMovesAnglesIntoLimitsAndKeepsValidOnes) {
  JointAngles angles;
  angles.fill(10.0);
  JointAngles clamped = ClampToLimits(angles);
  for (int i = 0; i < kNumDofs; ++i) EXPECT_EQ(clamped[i], Dofs()[i].max_rad);
  angles.fill(-10.0);
  clamped = ClampToLimits(angles);
  for (int i = 0; i < kNumDofs; ++i) EXPECT_EQ(clamped[i], Dofs()[i].min_rad);
  Random random(testing::kTestSeed);
  const JointAngles valid = RandomArticulation(random);
  EXPECT_EQ(ClampToLimits(valid), valid);
  HandPose pose;
  pose.angles = angles;
  EXPECT_FALSE(pose.IsValid());
}

TEST(HandPoseTest, NamedArticulationsAreValidAndUnknownNamesAreRefused) {
  for (const std::string& name : NamedArticulations()) {
    HandPose pose;
    pose.angles = NamedArticulation(name);
    EXPECT_TRUE(pose.IsValid()) << name;
  }
  EXPECT_EQ(NamedArticulation("rest"), JointAngles{});
  try {
    NamedArticulation("jazz");
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("fist"), std::string::npos) << "lists the choices";
  }
}

TEST(HandPoseTest, HandednessSpellingRoundTrips) {
  for (Handedness h : {Handedness::kRight, Handedness::kLeft}) EXPECT_EQ(HandednessFromString(ToString(h)), h);
  EXPECT_THROW(HandednessFromString("both"), Error);
}

}  // namespace
}  // namespace nphand
