#include "nphand/sequence/sequence.h"

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "nphand/scene/gesture.h"
#include "nphand/scene/viewpoint.h"
#include "testing/testing.h"

namespace nphand {
namespace {

using testing::RightHand;

SequenceOptions Small(uint64_t seed) {
  SequenceOptions options;
  options.frames = 12;
  options.width = 320;
  options.height = 240;
  options.seed = seed;
  return options;
}

double IoU(const cv::Mat& a, const cv::Mat& b) {
  const int both = cv::countNonZero(a & b), either = cv::countNonZero(a | b);
  return either == 0 ? 1.0 : static_cast<double>(both) / either;
}

TEST(SequenceTest, SameOptionsGiveTheSameFrames) {
  Sequence a(RightHand(), Small(testing::kTestSeed));
  Sequence b(RightHand(), Small(testing::kTestSeed));
  for (int i : {0, 7, 11}) {
    const SequenceFrame fa = a.Render(i), fb = b.Render(i);
    EXPECT_EQ(cv::norm(fa.rgb, fb.rgb, cv::NORM_INF), 0.0) << i;
    EXPECT_EQ(cv::norm(fa.labels, fb.labels, cv::NORM_INF), 0.0) << i;
    EXPECT_EQ(FrameTruthJson(fa), FrameTruthJson(fb)) << i;
  }
  EXPECT_EQ(a.Describe(), b.Describe());
}

TEST(SequenceTest, EmptyFramesAreTheViewTheHandWasSeenAgainst) {
  for (Handedness hand : {Handedness::kRight, Handedness::kLeft}) {
    SequenceOptions options = Small(testing::kTestSeed + 3);
    options.face = true;
    options.hand = hand;
    Sequence sequence(RightHand(), options);
    for (int i : {0, 11}) {
      const SequenceFrame frame = sequence.Render(i);
      const cv::Mat empty = sequence.RenderEmpty(i);
      ASSERT_EQ(empty.size(), frame.rgb.size());
      const cv::Mat background = frame.labels == static_cast<int>(PixelLabel::kBackground);
      cv::Mat difference, differs;
      cv::absdiff(empty, frame.rgb, difference);
      cv::cvtColor(difference, differs, cv::COLOR_BGR2GRAY);
      differs = differs != 0;
      EXPECT_EQ(cv::countNonZero(differs & background), 0) << "same background and noise, frame " << i;
      EXPECT_GT(cv::countNonZero(differs), 1000) << "the hand is gone, frame " << i;
    }
  }
  testing::ExpectError([] { Sequence(RightHand(), Small(1)).RenderEmpty(12); }, "frame 12");
}

TEST(SequenceTest, GraspAndObjectAreNotTheDatabases) {
  for (uint64_t seed = 1; seed <= 4; ++seed) {
    Sequence sequence(RightHand(), Small(seed));
    const ObjectSpec& original = GraspTaxonomy()[sequence.grasp() - 1].object;
    EXPECT_FALSE(sequence.object() == original) << "seed " << seed;
    const double ratio = sequence.object().size[0] / original.size[0];
    EXPECT_TRUE(std::abs(ratio - 0.8) < 1e-9 || std::abs(ratio - 1.25) < 1e-9) << ratio;
    // The hand opens past the pre-shape first and ends holding the object.
    EXPECT_LT(sequence.Render(0).step, 0.0);
    EXPECT_DOUBLE_EQ(sequence.Render(sequence.size() - 1).step, 4.0);
  }
}

// A gesture is held without an object: the hand forms it from more open than the
// database's first step and ends past its last (never a database pose), clamped to its limits.
TEST(SequenceTest, AGestureIsFormedAndHeldPastTheDatabasesSteps) {
  SequenceOptions options = Small(testing::kTestSeed);
  options.grasp = GestureByName("peace").id;
  options.object = false;
  Sequence sequence(RightHand(), options);
  EXPECT_EQ(sequence.Describe()["grasp"], (nlohmann::json{{"id", options.grasp}, {"name", "peace"}}));
  EXPECT_TRUE(sequence.Describe()["object"].is_null());
  const SequenceFrame last = sequence.Render(sequence.size() - 1);
  EXPECT_DOUBLE_EQ(last.step, 4.5);
  EXPECT_FALSE(last.object_in_view);
  EXPECT_EQ(cv::countNonZero(last.labels == static_cast<int>(PixelLabel::kObject)), 0);
  const JointAngles held = GestureByName("peace").shape;
  EXPECT_NE(last.pose.angles, held);
  EXPECT_EQ(last.pose.angles, ClampToLimits(last.pose.angles));
  EXPECT_NEAR(last.pose.angles[15], Dofs()[15].max_rad, 1e-9) << "the curled ring finger's PIP: at its limit";
  options.object = true;
  testing::ExpectError([&] { Sequence(RightHand(), options); }, "a gesture (peace) holds no object");
  options.grasp = kNumHandShapes + 1;
  testing::ExpectError([&] { Sequence(RightHand(), options); }, "a gesture's 34..49");
}

TEST(SequenceTest, TruthKeypointsLandOnTheRenderedHand) {
  SequenceOptions options = Small(testing::kTestSeed);
  options.forearm = ForearmKind::kSleeved;
  options.face = true;
  Sequence sequence(RightHand(), options);
  for (int i = 0; i < sequence.size(); i += 3) {
    const SequenceFrame frame = sequence.Render(i);
    cv::Mat covered;
    cv::dilate(frame.labels != 0, covered, cv::Mat::ones(5, 5, CV_8UC1));
    int on = 0;
    for (const Eigen::Vector2d& k : frame.keypoints_2d) {
      const int x = static_cast<int>(k.x()), y = static_cast<int>(k.y());
      on += x >= 0 && y >= 0 && x < covered.cols && y < covered.rows && covered.at<uint8_t>(y, x) != 0;
    }
    EXPECT_GE(on, 19) << "frame " << i;
    EXPECT_GT(cv::countNonZero(frame.labels == static_cast<int>(PixelLabel::kForearm)), 0) << i;
    EXPECT_TRUE(frame.pose.IsValid());
  }
}

TEST(SequenceTest, LeftHandIsTheMirrorImageAndMirrorPoseMatchesTheLeftMesh) {
  SequenceOptions options = Small(testing::kTestSeed);
  options.forearm = ForearmKind::kNone;
  options.object = false;
  Sequence right(RightHand(), options);
  options.hand = Handedness::kLeft;
  Sequence left(RightHand(), options);
  Renderer renderer(testing::LeftHand());
  for (int i : {2, 9}) {
    const SequenceFrame r = right.Render(i), l = left.Render(i);
    cv::Mat flipped;
    cv::flip(r.labels, flipped, 1);
    EXPECT_EQ(cv::norm(flipped, l.labels, cv::NORM_INF), 0.0);
    EXPECT_EQ(l.pose.handedness, Handedness::kLeft);
    // The left mesh posed by the mirrored pose covers the mirrored pixels.
    Scene scene;
    scene.hand = l.pose;
    scene.wrist_in_camera = l.wrist_in_camera;
    cv::Mat labels;
    renderer.RenderLabels(scene, left.intrinsics(), &labels);
    EXPECT_GT(IoU(labels == 1, l.labels == 1), 0.97) << "frame " << i;
    for (int k = 0; k < kNumKeypoints; ++k) {
      EXPECT_NEAR(l.keypoints_2d[k].x(), options.width - r.keypoints_2d[k].x(), 1e-6);
    }
  }
}

TEST(SequenceTest, BackgroundsHaveNoSkinChroma) {
  for (const std::string& kind : BackgroundKindNames()) {
    for (uint64_t seed = 1; seed <= 5; ++seed) {
      const cv::Mat background = MakeBackground(BackgroundKindFromString(kind), cv::Size(160, 120), seed);
      cv::Mat ycrcb, skin;
      cv::cvtColor(background, ycrcb, cv::COLOR_BGR2YCrCb);
      cv::inRange(ycrcb, cv::Scalar(30, 133, 77), cv::Scalar(255, 173, 127), skin);
      EXPECT_EQ(cv::countNonZero(skin), 0) << kind << " seed " << seed;
    }
  }
  // A face is skin.
  cv::Mat canvas = MakeBackground(BackgroundKind::kPlain, cv::Size(160, 120), 1);
  DrawFace(SkinToneByName("brown").bgr, cv::Point(80, 60), 60, &canvas);
  cv::Mat ycrcb, skin;
  cv::cvtColor(canvas, ycrcb, cv::COLOR_BGR2YCrCb);
  cv::inRange(ycrcb, cv::Scalar(30, 133, 77), cv::Scalar(255, 173, 127), skin);
  EXPECT_GT(cv::countNonZero(skin), 1000);
}

// The person behind the hand in a sweater of a skin-like colour: more skin that is not a
// hand, and nothing else changed (the same hand, path and background).
TEST(SequenceTest, ASweaterIsSkinThatIsNotAHandAndChangesNothingElse) {
  auto skin_pixels = [](const cv::Mat& bgr) {
    cv::Mat ycrcb, skin;
    cv::cvtColor(bgr, ycrcb, cv::COLOR_BGR2YCrCb);
    cv::inRange(ycrcb, cv::Scalar(30, 133, 77), cv::Scalar(255, 173, 127), skin);
    return cv::countNonZero(skin);
  };
  for (const cv::Vec3f& wool : {cv::Vec3f(185, 215, 235), cv::Vec3f(105, 150, 195)}) {
    cv::Mat canvas = MakeBackground(BackgroundKind::kPlain, cv::Size(160, 120), 1);
    DrawSweater(wool, cv::Point(80, 40), 40, &canvas);
    EXPECT_GT(skin_pixels(canvas), 3000) << "cream to camel are in the skin box";
  }
  SequenceOptions plain = Small(testing::kTestSeed + 5);
  plain.face = true;
  SequenceOptions dressed = plain;
  dressed.sweater = true;
  Sequence a(RightHand(), plain), b(RightHand(), dressed);
  for (int i : {0, 11}) {
    const SequenceFrame fa = a.Render(i), fb = b.Render(i);
    EXPECT_EQ(FrameTruthJson(fa), FrameTruthJson(fb)) << i;
    EXPECT_EQ(cv::norm(fa.labels, fb.labels, cv::NORM_INF), 0.0) << i;
    EXPECT_GT(skin_pixels(b.RenderEmpty(i)), skin_pixels(a.RenderEmpty(i)) + 2000) << i;
  }
  EXPECT_TRUE(b.Describe()["sweater"].get<bool>());
  dressed.face = false;
  testing::ExpectError([&] { Sequence(RightHand(), dressed); }, "a sweater needs a face");
}

// An adult's arm changes the arm, not the hand's truth: the same truth, more arm pixels.
TEST(SequenceTest, AnAdultsArmIsMoreArmAndKeepsTheTruth) {
  SequenceOptions mesh_sized = Small(testing::kTestSeed + 6);
  SequenceOptions adult = mesh_sized;
  adult.adult_arm = true;
  Sequence a(RightHand(), mesh_sized), b(RightHand(), adult);
  for (int i : {0, 11}) {
    const SequenceFrame fa = a.Render(i), fb = b.Render(i);
    EXPECT_EQ(FrameTruthJson(fa), FrameTruthJson(fb)) << i;
    const int arm_a = cv::countNonZero(fa.labels == static_cast<int>(PixelLabel::kForearm));
    const int arm_b = cv::countNonZero(fb.labels == static_cast<int>(PixelLabel::kForearm));
    EXPECT_GT(arm_b, arm_a) << i;
  }
  EXPECT_FALSE(a.Describe()["adult_arm"].get<bool>());
  EXPECT_TRUE(b.Describe()["adult_arm"].get<bool>());
  adult.forearm = ForearmKind::kNone;
  testing::ExpectError([&] { Sequence(RightHand(), adult); }, "an adult's arm needs a forearm");
}

TEST(SequenceTest, BadOptionsAreRefused) {
  SequenceOptions options = Small(1);
  options.frames = 0;
  testing::ExpectError([&] { Sequence(RightHand(), options); }, "frames");
  options = Small(1);
  options.skin = "green";
  testing::ExpectError([&] { Sequence(RightHand(), options); }, "skin tone");
  options = Small(1);
  options.object_scale = 3.0;
  testing::ExpectError([&] { Sequence(RightHand(), options); }, "object scale");
  Sequence sequence(RightHand(), Small(1));
  testing::ExpectError([&] { sequence.Render(12); }, "frame 12");
  testing::ExpectError([] { BackgroundKindFromString("sky"); }, "plain, texture or clutter");
  testing::ExpectError([] { ForearmKindFromString("long"); }, "none, bare or sleeved");
}

}  // namespace
}  // namespace nphand
