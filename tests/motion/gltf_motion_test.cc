#include "nphand/motion/gltf_motion.h"

#include <algorithm>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "nphand/util/check.h"
#include "nphand/util/io.h"
#include "testing/testing.h"
#include "tests/motion/random_motion.h"

namespace nphand {
namespace {

std::vector<uint8_t> AssetBytes(Handedness side) { return ReadFileBytes(DefaultAssetDir() / AssetFileName(side)); }

TEST(GltfMotionTest, TheAnimatedHandLoadsBackWithItsJointsFramesAndKeypoints) {
  for (const HandModel* hand : {&testing::RightHand(), &testing::LeftHand()}) {
    for (double scale : {1.0, 0.9}) {
      const Motion motion = testing::RandomMotion(hand->handedness(), 30, 25.0, scale, 11);
      const auto path = testing::ScratchDir() / "hand.glb";
      WriteGltfMotion(*hand, AssetBytes(hand->handedness()), motion, path);
      const std::vector<uint8_t> bytes = ReadFileBytes(path);

      // The project's own mesh reader takes it: the same rigged hand.
      const HandModel loaded = HandModel::FromGlb(bytes, hand->handedness(), path.string());
      EXPECT_EQ(loaded.bind_vertices().size(), hand->bind_vertices().size());
      // Its tip joints stand at the fingertip keypoints, by its inverse bind matrices as by
      // its nodes, and its keypoints are the model's.
      for (int k : {4, 8, 12, 16, 20}) {
        EXPECT_LT((loaded.bind_joint_positions()[Index(KeypointJoint(k))] - hand->bind_keypoints()[k]).norm(), 1e-6)
            << KeypointName(k);
      }
      for (int k = 0; k < kNumKeypoints; ++k) {
        EXPECT_LT((loaded.bind_keypoints()[k] - hand->bind_keypoints()[k]).norm(), 1e-6) << KeypointName(k);
      }

      const GltfMotion read = ReadGltfMotion(bytes, path.string());
      EXPECT_EQ(read.joints, kNumJoints);
      ASSERT_EQ(read.frames.size(), motion.frames.size());
      EXPECT_NEAR(read.fps, 25.0, 1e-3);
      EXPECT_NE(read.copyright.find("MIT License"), std::string::npos);
      double worst = 0.0;
      for (size_t f = 0; f < motion.frames.size(); ++f) {
        const Keypoints3d a = GltfKeypoints(read, f), b = MotionKeypoints(*hand, motion, f);
        for (int k = 0; k < kNumKeypoints; ++k) worst = std::max(worst, (a[k] - b[k]).norm());
      }
      EXPECT_LT(worst, 1e-4) << ToString(hand->handedness()) << " scale " << scale << ": metres";
    }
  }
}

// A file without the thumb's base (another tool's, or nphand's before 2026-12-07) is read,
// but its keypoints are refused rather than given with the thumb's pivot for its CMC.
TEST(GltfMotionTest, KeypointsNeedTheThumbsBase) {
  const Motion motion = testing::RandomMotion(Handedness::kRight, 2, 25.0, 1.0, 5);
  std::vector<uint8_t> bytes = GltfMotionBytes(testing::RightHand(), AssetBytes(Handedness::kRight), motion);
  const std::string name = kGltfThumbBaseNode;
  const auto at = std::search(bytes.begin(), bytes.end(), name.begin(), name.end());
  ASSERT_NE(at, bytes.end());
  *(at + 7) = 'o';  // "thumb-bose": the same length, so the file stays whole
  const GltfMotion read = ReadGltfMotion(bytes, "renamed.glb");
  EXPECT_EQ(read.frames.size(), 2u);
  EXPECT_TRUE(read.thumb_bases.empty());
  testing::ExpectError([&] { GltfKeypoints(read, 0); }, "no node 'thumb-base'");
}

TEST(GltfMotionTest, TheSkinnedMeshFollowsTheJoints) {
  // Skinning the written file's mesh the glTF way (node transforms times inverse bind
  // matrices) puts the fingertip's vertices where the model's own skinning puts them.
  const Motion motion = testing::RandomMotion(Handedness::kRight, 1, 25.0, 1.0, 3);
  const std::vector<uint8_t> bytes = GltfMotionBytes(testing::RightHand(), AssetBytes(Handedness::kRight), motion);
  const GltfMotion read = ReadGltfMotion(bytes, "hand.glb");
  std::vector<Eigen::Vector3f> vertices;
  testing::RightHand().Skin(motion.frames[0].pose, &vertices, nullptr);
  const Keypoints3d keypoints = GltfKeypoints(read, 0);
  // The closest skinned vertex to the index fingertip (keypoint 8, the finger's end) lies
  // within a few millimetres.
  const Eigen::Vector3d tip = keypoints[8] - motion.frames[0].wrist_camera;
  double nearest = 1.0;
  for (const Eigen::Vector3f& v : vertices) nearest = std::min(nearest, (v.cast<double>() - tip).norm());
  EXPECT_LT(nearest, 0.01);
}

TEST(GltfMotionTest, WrongInputsAreRefusedByName) {
  const Motion motion = testing::RandomMotion(Handedness::kLeft, 2, 25.0, 1.0, 1);
  EXPECT_THROW(GltfMotionBytes(testing::RightHand(), AssetBytes(Handedness::kRight), motion), Error);
  const std::vector<uint8_t> garbage(100, 3);
  try {
    ReadGltfMotion(garbage, "garbage.glb");
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("garbage.glb: not a readable binary glTF"), std::string::npos) << e.what();
  }
  try {
    ReadGltfMotion(AssetBytes(Handedness::kRight), "right.glb");
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("right.glb: no animation"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace nphand
