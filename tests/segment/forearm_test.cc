#include "nphand/segment/forearm.h"

#include <algorithm>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "nphand/features/crop.h"
#include "nphand/segment/regions.h"
#include "nphand/segment/skin.h"
#include "nphand/sequence/sequence.h"
#include "testing/testing.h"

namespace nphand {
namespace {

double IoU(const cv::Mat& a, const cv::Mat& b) {
  const int both = cv::countNonZero(a & b), either = cv::countNonZero(a | b);
  return either == 0 ? 1.0 : static_cast<double>(both) / either;
}

int Border(const cv::Rect& box, const cv::Size& frame) {
  return (box.x == 0 ? 1 : 0) | (box.y == 0 ? 2 : 0) | (box.x + box.width == frame.width ? 4 : 0) |
         (box.y + box.height == frame.height ? 8 : 0);
}

// The segmented hand's crop, after the cut unless `cut` is null (not turned: the cut, not
// the roll, is under test).
cv::Mat CutCrop(const cv::Mat& rgb, bool* cut) {
  SkinOptions options;
  options.face_cascade.clear();
  SkinSegmenter segmenter(options);
  const SkinSegmentation s = segmenter.Segment(rgb);
  if (s.regions.empty()) return {};
  const SkinRegion& region = s.regions[0];
  cv::Mat hand = s.RegionMask(region);
  if (cut != nullptr) {
    const ForearmCut c = CutForearm(hand, Border(region.box, rgb.size()));
    *cut = c.cut;
    hand = c.hand;
  }
  const std::optional<HandCrop> crop = CropHand(hand, {64, 0.1, false});
  return crop.has_value() ? cv::Mat(crop->image > 0.5f) : cv::Mat();
}

double Median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  return values[values.size() / 2];
}

// Crops are harsh judges: a sliver of arm left, or of wrist taken, moves the box and with
// it the whole 64 x 64 crop. The issue asks for IoU >= 0.9: the cut reaches a median of
// 0.91 on these 18 frames (docs/estimator.md; half of them, 0.41-0.88, fall short), against
// about 0.5 uncut.
TEST(ForearmTest, CutArmsGiveTheCropOfTheHandAlone) {
  std::vector<double> ious, uncut;
  int cut_with = 0, cut_without = 0, frames = 0;
  for (uint64_t seed = 1; seed <= 6; ++seed) {
    SequenceOptions options;
    options.frames = 8;
    options.width = 320;
    options.height = 240;
    options.distance_m = 0.4;
    options.seed = testing::kTestSeed + seed;
    options.forearm = ForearmKind::kBare;
    Sequence with_arm(testing::RightHand(), options);
    options.forearm = ForearmKind::kNone;
    Sequence without(testing::RightHand(), options);
    for (int i = 0; i < options.frames; i += 3) {
      bool a = false, b = false;
      const cv::Mat crop_arm = CutCrop(with_arm.Render(i).rgb, &a);
      const cv::Mat crop_hand = CutCrop(without.Render(i).rgb, &b);
      ASSERT_FALSE(crop_arm.empty());
      ASSERT_FALSE(crop_hand.empty());
      ious.push_back(IoU(crop_arm, crop_hand));
      uncut.push_back(IoU(CutCrop(with_arm.Render(i).rgb, nullptr), crop_hand));
      cut_with += a;
      cut_without += b;
      ++frames;
    }
  }
  EXPECT_GE(Median(ious), 0.9);
  EXPECT_LE(Median(uncut), 0.7);
  EXPECT_GE(cut_with, frames * 8 / 10);
  EXPECT_LE(cut_without, frames / 5);
}

TEST(ForearmTest, AnArmLeavingTheFrameObliquelyIsCut) {
  // A rendered frame whose arm enters from the bottom edge at a slant: the slices across the
  // arm's cut end rise unevenly from nothing, and once passed for the arm's own width. The
  // cut is given the rendered silhouette (hand and arm): the rule under test is the cut's,
  // and a 640 x 480 frame's segmentation (at half size) smooths away this wrist's notch.
  SequenceOptions options;
  options.frames = 60;
  options.seed = 21;
  Sequence sequence(testing::RightHand(), options);
  const SequenceFrame frame = sequence.Render(54);
  const cv::Mat body =
      (frame.labels == static_cast<int>(PixelLabel::kHand)) | (frame.labels == static_cast<int>(PixelLabel::kForearm));
  const cv::Rect box = cv::boundingRect(body);
  ASSERT_EQ(Border(box, frame.rgb.size()), 8) << "the arm leaves by the bottom edge";
  const ForearmCut c = CutForearm(body(box), Border(box, frame.rgb.size()));
  ASSERT_TRUE(c.cut);
  // What is left is the hand: most of its pixels, little of the arm's.
  const cv::Mat labels = frame.labels(box);
  EXPECT_GT(cv::countNonZero(c.hand & (labels == static_cast<int>(PixelLabel::kHand))),
            0.9 * cv::countNonZero(labels == static_cast<int>(PixelLabel::kHand)));
  EXPECT_LT(cv::countNonZero(c.hand & (labels == static_cast<int>(PixelLabel::kForearm))),
            0.1 * cv::countNonZero(labels == static_cast<int>(PixelLabel::kForearm)));
}

TEST(ForearmTest, AnArmWideningAlongTheEdgesCutIsReadFromBeyondIt) {
  // An arm that leaves by the bottom edge at a shallow slant, its hand holding a ball: the
  // edge cuts the arm over a long stretch, along which the slices widen from nothing by
  // more than the hand widens the arm, so read from the end the widening is the edge's and
  // the arm no arm. Read from beyond the edge's stretch, the arm is cut at the wrist. The
  // cut is given the skin region, as the estimator gives it.
  SequenceOptions options;
  options.grasp = 11;
  options.face = true;
  options.seed = 7201;
  Sequence sequence(testing::RightHand(), options);
  const SequenceFrame frame = sequence.Render(5);
  SkinSegmenter segmenter;
  const SkinSegmentation s = segmenter.Segment(frame.rgb);
  const cv::Mat hand_label = frame.labels == static_cast<int>(PixelLabel::kHand);
  const cv::Mat arm_label = frame.labels == static_cast<int>(PixelLabel::kForearm);
  const SkinRegion* on_hand = nullptr;
  for (const SkinRegion& region : s.regions) {
    if (cv::countNonZero(hand_label(region.box)) > 0 && (on_hand == nullptr || region.area > on_hand->area)) on_hand = &region;
  }
  ASSERT_NE(on_hand, nullptr);
  ASSERT_EQ(Border(on_hand->box, frame.rgb.size()), 8) << "the arm leaves by the bottom edge";
  const ForearmCut c = CutForearm(s.RegionMask(*on_hand), Border(on_hand->box, frame.rgb.size()));
  ASSERT_TRUE(c.cut);
  const cv::Mat hand = hand_label(on_hand->box), arm = arm_label(on_hand->box);
  EXPECT_GT(cv::countNonZero(c.hand & hand), 0.9 * cv::countNonZero(hand));
  EXPECT_LT(cv::countNonZero(c.hand & arm), 0.1 * cv::countNonZero(arm));
}

TEST(ForearmTest, AnArmWideningTowardsTheHandIsCutNearTheWrist) {
  // An arm seen in perspective, its near end (the wrist) wider than its far, rounded end,
  // which does not reach the frame's edge: its narrowest slices are at the far end, yet
  // the cut belongs near the hand, within 1.5 arm widths of it.
  cv::Mat body = cv::Mat::zeros(260, 520, CV_8UC1);
  const std::vector<cv::Point> arm = {{30, 107}, {300, 105}, {300, 155}, {30, 153}};  // 46 -> 50 px wide
  cv::fillConvexPoly(body, arm, cv::Scalar(255));
  cv::circle(body, {30, 130}, 23, cv::Scalar(255), cv::FILLED);
  cv::ellipse(body, cv::Point(385, 130), cv::Size(90, 65), 0, 0, 360, cv::Scalar(255), cv::FILLED);
  const ForearmCut c = CutForearm(body, 0);
  ASSERT_TRUE(c.cut);
  EXPECT_LT(c.arm_direction.x, -0.9) << "from the wrist towards the far end";
  EXPECT_GT(c.wrist.x, 295 - 1.5 * 48);
  EXPECT_LT(c.wrist.x, 305);
  cv::Mat hand = cv::Mat::zeros(body.size(), CV_8UC1);
  cv::ellipse(hand, cv::Point(385, 130), cv::Size(90, 65), 0, 0, 360, cv::Scalar(255), cv::FILLED);
  EXPECT_EQ(cv::countNonZero(hand & ~c.hand), 0) << "the whole hand is kept";
  EXPECT_EQ(cv::countNonZero(c.hand(cv::Rect(0, 0, 220, 260))), 0) << "the far arm is cut away";
}

// Read from its capped far end, a receding adult's arm widens gradually towards the elbow
// (44 -> 60 px over 160) before it narrows to the wrist (49): more than widen_ratio over the
// narrowest so far, but not within one width, as the hand widens. The cut is at the wrist.
TEST(ForearmTest, AnArmWideningTowardsTheElbowIsCutAtTheWrist) {
  cv::Mat body = cv::Mat::zeros(260, 560, CV_8UC1);
  const std::vector<cv::Point> arm = {{40, 108}, {200, 100}, {330, 106}, {330, 154}, {200, 160}, {40, 152}};
  cv::fillPoly(body, std::vector<std::vector<cv::Point>>{arm}, cv::Scalar(255));
  cv::circle(body, {40, 130}, 22, cv::Scalar(255), cv::FILLED);
  cv::ellipse(body, cv::Point(400, 130), cv::Size(90, 55), 0, 0, 360, cv::Scalar(255), cv::FILLED);  // from x = 310
  const ForearmCut c = CutForearm(body, 0);
  ASSERT_TRUE(c.cut);
  EXPECT_LT(c.arm_direction.x, -0.9) << "from the wrist towards the far end";
  EXPECT_NEAR(c.wrist.x, 320, 12);
  EXPECT_NEAR(c.wrist_width, 50, 4);
}

// Rendered adult arms (Forearm::Adult(): a rounder elbow and the upper arm) given as the
// silhouette of hand and arm: the part kept is the hand. The per-frame IoU with the hand's
// pixels is at or above 0.85 in 18 of these 20 frames (14 with the widening judged against
// the narrowest so far alone, whose misses left the arm on: 0.42-0.61); median 0.96.
TEST(ForearmTest, AdultArmsAreCutAtTheWrist) {
  std::vector<double> ious;
  for (uint64_t seed = 1; seed <= 5; ++seed) {
    SequenceOptions options;
    options.frames = 40;
    options.width = 320;
    options.height = 240;
    options.seed = testing::kTestSeed + seed;
    options.forearm = ForearmKind::kBare;
    options.adult_arm = true;
    Sequence sequence(testing::RightHand(), options);
    for (int i = 0; i < options.frames; i += 10) {
      const SequenceFrame frame = sequence.Render(i);
      const cv::Mat hand = frame.labels == static_cast<int>(PixelLabel::kHand);
      const cv::Mat body = hand | (frame.labels == static_cast<int>(PixelLabel::kForearm));
      const cv::Rect box = cv::boundingRect(body);
      const ForearmCut c = CutForearm(body(box), Border(box, frame.rgb.size()));
      ious.push_back(IoU(c.hand, hand(box)));
    }
  }
  const int good = static_cast<int>(std::count_if(ious.begin(), ious.end(), [](double iou) { return iou >= 0.85; }));
  EXPECT_GE(Median(ious), 0.9);
  EXPECT_GE(good, 17);
}

// A held object splits the hand: the pieces the region had before the cut stay (only the
// crumbs the cut itself makes of a piece go).
TEST(ForearmTest, PiecesAnObjectSplitOffTheHandStay) {
  cv::Mat region = cv::Mat::zeros(300, 200, CV_8UC1);
  cv::ellipse(region, cv::Point(100, 110), cv::Size(60, 70), 0, 0, 360, cv::Scalar(255), cv::FILLED);  // hand
  cv::rectangle(region, cv::Rect(75, 150, 50, 150), cv::Scalar(255), cv::FILLED);                       // arm
  cv::rectangle(region, cv::Rect(0, 60, 200, 12), cv::Scalar(0), cv::FILLED);  // the object's gap...
  const cv::Mat fingers = region(cv::Rect(0, 0, 200, 60)).clone();              // ...leaves fingertips apart
  const ForearmCut c = CutForearm(region, 8);
  ASSERT_TRUE(c.cut);
  ASSERT_GT(cv::countNonZero(fingers), 500);
  EXPECT_EQ(cv::countNonZero(fingers & ~c.hand(cv::Rect(0, 0, 200, 60))), 0) << "the fingertips stay";
  EXPECT_EQ(cv::countNonZero(c.hand(cv::Rect(0, 230, 200, 70))), 0) << "the arm goes";
  cv::Mat labels;
  EXPECT_EQ(LabelRegions(c.hand, &labels).size(), 3u) << "two pieces: palm and fingertips";
}

// A thumb held out sideways makes a few slices far wider than the palm; next to them the arm
// would pass for a finger, and the fingers' end for the arm.
TEST(ForearmTest, AThumbHeldOutDoesNotHideTheArm) {
  cv::Mat region = cv::Mat::zeros(320, 240, CV_8UC1);
  cv::rectangle(region, cv::Rect(98, 0, 44, 160), cv::Scalar(255), cv::FILLED);               // arm, from the top edge
  cv::ellipse(region, cv::Point(120, 200), cv::Size(48, 55), 0, 0, 360, cv::Scalar(255), cv::FILLED);  // palm
  cv::rectangle(region, cv::Rect(10, 185, 220, 12), cv::Scalar(255), cv::FILLED);              // thumb (and a finger) out
  for (int x : {95, 113, 131}) cv::rectangle(region, cv::Rect(x, 250, 12, 60), cv::Scalar(255), cv::FILLED);  // fingers
  const ForearmCut c = CutForearm(region, 2);
  ASSERT_TRUE(c.cut);
  EXPECT_LT(c.arm_direction.y, -0.9) << "the arm is the top end";
  EXPECT_EQ(cv::countNonZero(c.hand(cv::Rect(0, 0, 240, 100))), 0) << "the arm goes";
  EXPECT_EQ(cv::countNonZero(region(cv::Rect(0, 240, 240, 80)) & ~c.hand(cv::Rect(0, 240, 240, 80))), 0)
      << "the fingers stay";
}

// A "call" sign on an arm: the thumb and the little finger held out up and down make the
// slices across them far wider than the palm (their extent, not their skin); next to that
// extent the arm would pass for a finger.
TEST(ForearmTest, FingersSpreadSidewaysDoNotHideTheArm) {
  cv::Mat region = cv::Mat::zeros(320, 420, CV_8UC1);
  cv::rectangle(region, cv::Rect(20, 140, 200, 40), cv::Scalar(255), cv::FILLED);                       // arm
  cv::circle(region, cv::Point(20, 160), 20, cv::Scalar(255), cv::FILLED);                               // its end
  cv::ellipse(region, cv::Point(265, 160), cv::Size(50, 42), 0, 0, 360, cv::Scalar(255), cv::FILLED);  // palm
  cv::line(region, cv::Point(270, 150), cv::Point(330, 20), cv::Scalar(255), 16);                        // thumb
  cv::line(region, cv::Point(270, 170), cv::Point(330, 300), cv::Scalar(255), 14);                       // little finger
  const ForearmCut c = CutForearm(region, 0);
  ASSERT_TRUE(c.cut);
  EXPECT_LT(c.arm_direction.x, -0.9) << "the arm is the left end";
  EXPECT_GT(c.wrist.x, 150);
  EXPECT_LT(c.wrist.x, 225);
  EXPECT_EQ(cv::countNonZero(c.hand(cv::Rect(0, 0, 120, 320))), 0) << "the arm goes";
}

// Two fingers held together before a palm look like an arm before a hand: narrow, then a
// widening. Within the frame an arm must be 1.4 of its widths long; the fingers are 1.3 and
// stay, an arm of 1.6 is cut.
TEST(ForearmTest, ShortFingersWithinTheFrameAreNoArm) {
  auto shape = [](int stretch) {
    cv::Mat region = cv::Mat::zeros(300, 200, CV_8UC1);
    cv::rectangle(region, cv::Rect(80, 240 - stretch, 40, stretch), cv::Scalar(255), cv::FILLED);  // fingers or arm
    cv::rectangle(region, cv::Rect(50, 240, 100, 50), cv::Scalar(255), cv::FILLED);                 // palm
    return region;
  };
  const cv::Mat fingers = shape(52);
  const ForearmCut f = CutForearm(fingers, 0);
  EXPECT_FALSE(f.cut);
  EXPECT_EQ(cv::countNonZero(f.hand != fingers), 0);
  const ForearmCut a = CutForearm(shape(64), 0);
  ASSERT_TRUE(a.cut);
  EXPECT_LT(a.arm_direction.y, -0.9) << "the arm is the top end";
}

TEST(ForearmTest, ARegionWithoutAnArmIsLeftWhole) {
  cv::Mat disc = cv::Mat::zeros(200, 200, CV_8UC1);
  cv::circle(disc, cv::Point(100, 100), 60, cv::Scalar(255), cv::FILLED);
  const ForearmCut c = CutForearm(disc, 0);
  EXPECT_FALSE(c.cut);
  EXPECT_EQ(cv::countNonZero(c.hand != disc), 0);
  // A paddle: a wide blade on a long handle entering from the bottom edge is cut at the neck.
  cv::Mat paddle = cv::Mat::zeros(300, 200, CV_8UC1);
  cv::ellipse(paddle, cv::Point(100, 90), cv::Size(60, 80), 0, 0, 360, cv::Scalar(255), cv::FILLED);
  cv::rectangle(paddle, cv::Rect(75, 150, 50, 150), cv::Scalar(255), cv::FILLED);
  const ForearmCut p = CutForearm(paddle, 8);
  ASSERT_TRUE(p.cut);
  EXPECT_GT(p.wrist.y, 150);
  EXPECT_LT(p.wrist.y, 215);
  EXPECT_NEAR(p.wrist_width, 50, 4);
  EXPECT_GT(p.arm_direction.y, 0.9);
  EXPECT_EQ(cv::countNonZero(p.hand(cv::Rect(0, 230, 200, 70))), 0);
  testing::ExpectError([] { CutForearm(cv::Mat(4, 4, CV_32FC1), 0); }, "8-bit");
}

}  // namespace
}  // namespace nphand
