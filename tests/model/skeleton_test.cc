#include "nphand/model/skeleton.h"

#include <set>
#include <string>

#include <gtest/gtest.h>

namespace nphand {
namespace {

TEST(SkeletonTest, TreeIsRootedAtTheWristWithFiveChains) {
  EXPECT_EQ(JointParent(0), -1);
  int children_of_wrist = 0;
  for (int j = 1; j < kNumJoints; ++j) {
    ASSERT_LT(JointParent(j), j) << "parents come first";
    children_of_wrist += JointParent(j) == 0;
    EXPECT_TRUE(IsInSubtree(j, 0));
  }
  EXPECT_EQ(children_of_wrist, 5);
  EXPECT_TRUE(IsInSubtree(Index(Joint::kIndexTip), Index(Joint::kIndexProximal)));
  EXPECT_FALSE(IsInSubtree(Index(Joint::kIndexTip), Index(Joint::kMiddleProximal)));
}

TEST(SkeletonTest, KeypointsFollowTheMediaPipeOrder) {
  EXPECT_EQ(KeypointJoint(0), Joint::kWrist);
  EXPECT_EQ(KeypointJoint(1), Joint::kThumbMetacarpal);
  EXPECT_EQ(KeypointJoint(4), Joint::kThumbTip);
  EXPECT_EQ(KeypointJoint(5), Joint::kIndexProximal);
  EXPECT_EQ(KeypointJoint(8), Joint::kIndexTip);
  EXPECT_EQ(KeypointJoint(17), Joint::kLittleProximal);
  EXPECT_EQ(KeypointJoint(20), Joint::kLittleTip);
  std::set<std::string> names;
  for (int k = 0; k < kNumKeypoints; ++k) {
    names.insert(KeypointName(k));
    const int parent = KeypointParent(k);
    if (k > 0) {
      EXPECT_TRUE(IsInSubtree(Index(KeypointJoint(k)), Index(KeypointJoint(parent))));
    }
  }
  EXPECT_EQ(names.size(), static_cast<size_t>(kNumKeypoints));
}

}  // namespace
}  // namespace nphand
