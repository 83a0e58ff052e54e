#include "nphand/segment/skin.h"

#include <cmath>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "nphand/scene/gesture.h"
#include "nphand/sequence/sequence.h"
#include "testing/testing.h"

namespace nphand {
namespace {

double IoU(const cv::Mat& a, const cv::Mat& b) {
  const int both = cv::countNonZero(a & b), either = cv::countNonZero(a | b);
  return either == 0 ? 1.0 : static_cast<double>(both) / either;
}

// Every skin region as a frame-sized mask (an object can split the hand into pieces).
cv::Mat Regions(const SkinSegmentation& segmentation) {
  std::vector<int> labels;
  for (const SkinRegion& region : segmentation.regions) labels.push_back(region.label);
  return segmentation.Mask(labels, cv::Rect(cv::Point(0, 0), segmentation.frame));
}

// The cascade looks at the first frame, then only when something calls for it.
SkinOptions LookingAtFirst() {
  SkinOptions options;
  options.face_interval = 1000;
  return options;
}

// `wall` with a face of `tone` at `centre`, `height` pixels tall.
cv::Mat WithFace(const cv::Mat& wall, const char* tone, cv::Point centre, int height) {
  cv::Mat frame = wall.clone();
  DrawFace(SkinToneByName(tone).bgr, centre, height, &frame);
  return frame;
}

SkinOptions NoFaces() {
  SkinOptions options;
  options.face_cascade.clear();
  return options;
}

TEST(SkinTest, RenderedHandsOfEveryToneOnEveryBackgroundMatchTheirLabels) {
  SkinSegmenter segmenter(NoFaces());
  int frames = 0;
  for (const SkinTone& tone : SkinTones()) {
    for (const std::string& background : BackgroundKindNames()) {
      SequenceOptions options;
      options.frames = 10;
      options.width = 320;
      options.height = 240;
      options.skin = tone.name;
      options.background = BackgroundKindFromString(background);
      options.forearm = ForearmKind::kNone;
      options.distance_m = 0.3;
      options.seed = testing::kTestSeed + frames;
      Sequence sequence(testing::RightHand(), options);
      for (int i : {1, 8}) {
        const SequenceFrame frame = sequence.Render(i);
        const cv::Mat truth = frame.labels == static_cast<int>(PixelLabel::kHand);
        const double iou = IoU(Regions(segmenter.Segment(frame.rgb)), truth);
        EXPECT_GE(iou, 0.95) << tone.name << " on " << background << ", frame " << i << ", grasp " << sequence.grasp();
        ++frames;
      }
    }
  }
}

// A 640 x 480 frame is segmented at 320 x 240; its regions come back at the frame's size,
// matching the labels as well as a segmentation at full size does, and agreeing with it.
TEST(SkinTest, WideFramesAreSegmentedAtHalfSizeAndComeBackWhole) {
  SkinOptions full = NoFaces();
  full.work_width = 0;
  SkinSegmenter half_size(NoFaces()), full_size(full);
  int frames = 0;
  for (const char* tone : {"light", "brown", "dark"}) {
    for (BackgroundKind background : {BackgroundKind::kPlain, BackgroundKind::kTexture, BackgroundKind::kClutter}) {
      SequenceOptions options;
      options.frames = 10;
      options.skin = tone;
      options.background = background;
      options.forearm = ForearmKind::kNone;
      options.distance_m = 0.3;
      options.seed = testing::kTestSeed + 100 + frames++;
      Sequence sequence(testing::RightHand(), options);
      const SequenceFrame frame = sequence.Render(4);
      const SkinSegmentation half = half_size.Segment(frame.rgb), whole = full_size.Segment(frame.rgb);
      EXPECT_EQ(half.scale, 2);
      EXPECT_EQ(half.skin.size(), cv::Size(320, 240));
      EXPECT_EQ(whole.scale, 1);
      const cv::Mat truth = frame.labels == static_cast<int>(PixelLabel::kHand);
      EXPECT_GE(IoU(Regions(half), truth), 0.95) << tone << ", frame " << frames;
      EXPECT_GE(IoU(Regions(half), Regions(whole)), 0.97) << tone << ", frame " << frames;
      ASSERT_FALSE(half.regions.empty());
      // The largest region's box, area and centroid are its pixels' at the frame's size.
      const cv::Mat region = half.RegionMask(half.regions[0]);
      EXPECT_EQ(region.size(), half.regions[0].box.size());
      EXPECT_NEAR(cv::countNonZero(region), half.regions[0].area, 0.05 * half.regions[0].area);
      const cv::Moments m = cv::moments(region, true);
      EXPECT_NEAR(half.regions[0].box.x + m.m10 / m.m00, half.regions[0].centroid.x, 1.0);
      EXPECT_NEAR(half.regions[0].box.y + m.m01 / m.m00, half.regions[0].centroid.y, 1.0);
    }
  }
}

TEST(SkinTest, AdaptationFindsAHandTheFixedModelMisses) {
  // A reddish tone under warm light: its chroma lies outside the fixed box (Cr > 173).
  SequenceOptions options;
  options.frames = 10;
  options.width = 320;
  options.height = 240;
  options.forearm = ForearmKind::kNone;
  options.distance_m = 0.3;
  options.seed = testing::kTestSeed;
  Sequence sequence(testing::RightHand(), options);
  SequenceFrame frame = sequence.Render(3);
  const cv::Mat truth = frame.labels == static_cast<int>(PixelLabel::kHand);
  // Recolour the hand's pixels: keep the shading, move the chroma.
  cv::Mat ycrcb;
  cv::cvtColor(frame.rgb, ycrcb, cv::COLOR_BGR2YCrCb);
  for (int y = 0; y < ycrcb.rows; ++y) {
    for (int x = 0; x < ycrcb.cols; ++x) {
      if (truth.at<uint8_t>(y, x) != 0) ycrcb.at<cv::Vec3b>(y, x) = cv::Vec3b(ycrcb.at<cv::Vec3b>(y, x)[0], 182, 112);
    }
  }
  cv::cvtColor(ycrcb, frame.rgb, cv::COLOR_YCrCb2BGR);
  SkinSegmenter segmenter(NoFaces());
  EXPECT_LT(IoU(Regions(segmenter.Segment(frame.rgb)), truth), 0.5);
  segmenter.Learn(frame.rgb, truth);
  EXPECT_TRUE(segmenter.adapted());
  EXPECT_GE(IoU(Regions(segmenter.Segment(frame.rgb)), truth), 0.95);
  segmenter.Reset();
  EXPECT_FALSE(segmenter.adapted());
}

TEST(SkinTest, AFrameWithoutSkinHasNoRegionAndAFaceIsMarked) {
  SkinSegmenter segmenter(NoFaces());
  const cv::Mat wall = MakeBackground(BackgroundKind::kClutter, cv::Size(320, 240), 7);
  EXPECT_TRUE(segmenter.Segment(wall).regions.empty());

  cv::Mat with_face = wall.clone();
  DrawFace(SkinToneByName("medium").bgr, cv::Point(160, 120), 150, &with_face);
  const SkinSegmentation found = segmenter.Segment(with_face);
  ASSERT_EQ(found.regions.size(), 1u);
  EXPECT_GT(found.regions[0].area, 10000);
}

// A frame without colour (greyscale, an infrared camera's) says so; a colour frame does not.
TEST(SkinTest, AGreyscaleFrameIsColourless) {
  SequenceOptions options;
  options.frames = 4;
  options.width = 320;
  options.height = 240;
  options.seed = testing::kTestSeed;
  Sequence sequence(testing::RightHand(), options);
  const cv::Mat colour = sequence.Render(1).rgb;
  SkinSegmenter segmenter(NoFaces());
  const SkinSegmentation in_colour = segmenter.Segment(colour);
  EXPECT_FALSE(in_colour.colourless);
  EXPECT_FALSE(in_colour.regions.empty());
  const SkinSegmentation in_grey = segmenter.Segment(testing::Greyscale(colour));
  EXPECT_TRUE(in_grey.colourless);
  EXPECT_TRUE(in_grey.regions.empty());
}

// The cascade runs every face_interval frames, and on the frame after a region that could
// hold a face came into view; a region that moves or grows within its box is not new.
TEST(SkinTest, TheFaceCascadeLooksWhenSomeoneComesIntoView) {
  SkinOptions options;
  options.face_interval = 1000;
  SkinSegmenter segmenter(options);
  const cv::Mat wall = MakeBackground(BackgroundKind::kClutter, cv::Size(320, 240), 7);
  const cv::Vec3f skin = SkinToneByName("medium").bgr;
  auto blob_at = [&](int x) {
    cv::Mat frame = wall.clone();
    cv::ellipse(frame, cv::Point(x, 180), cv::Size(40, 25), 0, 0, 360, cv::Scalar(skin[0], skin[1], skin[2]), cv::FILLED);
    return frame;
  };
  std::vector<bool> looked;
  for (int x : {60, 70, 80}) looked.push_back(segmenter.Segment(blob_at(x)).faces_looked);
  // An object splits the blob in two: more regions, but none new.
  cv::Mat split = blob_at(80);
  cv::rectangle(split, cv::Rect(74, 140, 12, 80), cv::Scalar(40, 160, 60), cv::FILLED);
  for (int i = 0; i < 2; ++i) {
    const SkinSegmentation s = segmenter.Segment(split);
    EXPECT_EQ(s.regions.size(), 2u);
    looked.push_back(s.faces_looked);
  }
  // The first frame, then a moving blob and its two pieces.
  EXPECT_EQ(looked, std::vector<bool>({true, false, false, false, false}));

  cv::Mat with_face = split.clone();
  DrawFace(skin, cv::Point(220, 90), 120, &with_face);
  const SkinSegmentation came = segmenter.Segment(with_face);
  EXPECT_FALSE(came.faces_looked);
  EXPECT_TRUE(came.faces.empty());
  const SkinSegmentation next = segmenter.Segment(with_face);
  EXPECT_TRUE(next.faces_looked);
  ASSERT_EQ(next.faces.size(), 1u);
  EXPECT_GT(next.face_pixels, 0);
  EXPECT_EQ(next.regions.size(), 2u);  // the face is set aside; the pieces stay
  const SkinSegmentation after = segmenter.Segment(with_face);
  EXPECT_FALSE(after.faces_looked);
  EXPECT_EQ(after.faces, next.faces);
}

// The cascade takes a fist for a face at times. A look that a newcomer fired ignores a face
// found where the hand just was (the newcomer was the hand's own region changing shape); a
// look of every face_interval frames believes the cascade, so that a track that took a face
// for the hand lets go of it.
TEST(SkinTest, ANewcomersLookIgnoresAFaceWhereTheHandWas) {
  const SkinOptions options = LookingAtFirst();
  const cv::Mat wall = MakeBackground(BackgroundKind::kClutter, cv::Size(320, 240), 7);
  const cv::Mat with_face = WithFace(wall, "medium", cv::Point(220, 90), 120);
  // The wall, then someone comes into view: the frame after, a newcomer's look.
  auto newcomers_look = [&](cv::Rect hand) {
    SkinSegmenter segmenter(options);
    segmenter.Segment(wall, hand);
    segmenter.Segment(with_face, hand);
    const SkinSegmentation look = segmenter.Segment(with_face, hand);
    EXPECT_TRUE(look.faces_looked);
    return look;
  };
  const SkinSegmentation elsewhere = newcomers_look(cv::Rect(10, 150, 60, 80));
  ASSERT_EQ(elsewhere.faces.size(), 1u);
  EXPECT_GT(elsewhere.face_pixels, 0);
  const cv::Rect face = elsewhere.faces[0];
  // A hand's box a little off the face's: most of each within the other.
  const cv::Rect hand(face.x + face.width / 8, face.y + face.height / 8, face.width, face.height * 5 / 4);
  const SkinSegmentation where_the_hand_was = newcomers_look(hand);
  EXPECT_TRUE(where_the_hand_was.faces.empty());
  EXPECT_EQ(where_the_hand_was.face_pixels, 0);
  ASSERT_FALSE(where_the_hand_was.regions.empty());
  EXPECT_TRUE((where_the_hand_was.regions[0].box & face).area() > face.area() / 2);
  // A box holding the face and much more (a track on a face and its neck) is no fist.
  const cv::Rect face_and_body(face.x - face.width, face.y, face.width * 3, 240 - face.y);
  EXPECT_EQ(newcomers_look(face_and_body).faces.size(), 1u);
  // The first frame's look is a periodic one.
  SkinSegmenter first(options);
  EXPECT_EQ(first.Segment(with_face, hand).faces.size(), 1u);
}

// Between the cascade's looks a face found is followed as the camera moves; a face that is
// gone keeps its place until the next look.
TEST(SkinTest, AFaceFoundIsFollowedBetweenLooks) {
  SkinOptions options;
  options.face_interval = 1000;
  SkinSegmenter segmenter(options);
  const cv::Mat wall = MakeBackground(BackgroundKind::kClutter, cv::Size(640, 480), 3);
  const cv::Vec3f skin = SkinToneByName("olive").bgr;
  auto face_at = [&](int x, int y) {
    cv::Mat frame = wall.clone();
    DrawFace(skin, cv::Point(x, y), 180, &frame);
    return frame;
  };
  const SkinSegmentation first = segmenter.Segment(face_at(300, 220));
  ASSERT_TRUE(first.faces_looked);
  ASSERT_EQ(first.faces.size(), 1u);
  cv::Rect at = first.faces[0];
  for (int step = 1; step <= 4; ++step) {
    const SkinSegmentation next = segmenter.Segment(face_at(300 + 12 * step, 220 - 6 * step));
    EXPECT_FALSE(next.faces_looked);
    ASSERT_EQ(next.faces.size(), 1u);
    EXPECT_NEAR(next.faces[0].x - at.x, 12, 3) << step;
    EXPECT_NEAR(next.faces[0].y - at.y, -6, 3) << step;
    EXPECT_EQ(next.faces[0].size(), at.size());
    EXPECT_TRUE(next.regions.empty());  // the whole face set aside
    at = next.faces[0];
  }
  const SkinSegmentation gone = segmenter.Segment(wall);
  ASSERT_EQ(gone.faces.size(), 1u);
  EXPECT_EQ(gone.faces[0], at);
}

// A face drifting by less than half a pixel of its followed look each frame (a pixel of
// the look is about 8 of the frame's here) is followed all the same, neither left behind
// nor run ahead of: its place is kept to a fraction of a pixel. Measured: within 6 of the
// frame's pixels (1.4 on average) over 30 frames at each speed; a look taken afresh at
// each move ran up to 30 ahead, one taken at each match left the face where it was.
TEST(SkinTest, AFaceDriftingSlowlyIsFollowed) {
  const cv::Mat wall = MakeBackground(BackgroundKind::kClutter, cv::Size(640, 480), 3);
  const cv::Vec3f skin = SkinToneByName("olive").bgr;
  auto face_at = [&](cv::Point2d centre) {
    cv::Mat frame = wall.clone();
    DrawFace(skin, cv::Point(static_cast<int>(std::lround(centre.x)), static_cast<int>(std::lround(centre.y))), 180, &frame);
    return frame;
  };
  for (const cv::Point2d step : {cv::Point2d(1.0, 0.0), cv::Point2d(2.0, 0.0), cv::Point2d(3.0, -1.0), cv::Point2d(-2.0, 1.5)}) {
    SkinSegmenter segmenter(LookingAtFirst());
    const cv::Point2d start(300.0, 220.0);
    const SkinSegmentation first = segmenter.Segment(face_at(start));
    ASSERT_TRUE(first.faces_looked);
    ASSERT_EQ(first.faces.size(), 1u);
    for (int frame = 1; frame <= 30; ++frame) {
      const SkinSegmentation next = segmenter.Segment(face_at(start + frame * step));
      EXPECT_FALSE(next.faces_looked);
      ASSERT_EQ(next.faces.size(), 1u);
      EXPECT_NEAR(next.faces[0].x - first.faces[0].x, frame * step.x, 8.0) << step << " frame " << frame;
      EXPECT_NEAR(next.faces[0].y - first.faces[0].y, frame * step.y, 8.0) << step << " frame " << frame;
    }
  }
}

// A face that comes nearer as it drifts (here 1.5 % larger and 2 pixels across a frame)
// matches its look less well each frame; below kRefreshScore the look is taken afresh where
// it matched, and the face is followed on.
TEST(SkinTest, AFaceComingNearerIsFollowedOn) {
  SkinSegmenter segmenter(LookingAtFirst());
  const cv::Mat wall = MakeBackground(BackgroundKind::kClutter, cv::Size(640, 480), 3);
  const cv::Vec3f skin = SkinToneByName("olive").bgr;
  auto face = [&](int frame) {
    cv::Mat image = wall.clone();
    DrawFace(skin, cv::Point(260 + 2 * frame, 220), static_cast<int>(std::lround(150 * std::pow(1.015, frame))), &image);
    return image;
  };
  const SkinSegmentation first = segmenter.Segment(face(0));
  ASSERT_EQ(first.faces.size(), 1u);
  const int width = first.faces[0].width;
  for (int frame = 1; frame <= 30; ++frame) {
    const SkinSegmentation next = segmenter.Segment(face(frame));
    EXPECT_FALSE(next.faces_looked);
    ASSERT_EQ(next.faces.size(), 1u);
    const double centre = next.faces[0].x + width / 2.0 - (first.faces[0].x + width / 2.0);
    EXPECT_NEAR(centre, 2.0 * frame, 10.0) << frame;
  }
}

// A face the cascade misses at a look, because a hand covers its eyes, is kept while its
// look still matches where it was; one that is gone is dropped at the look.
TEST(SkinTest, AFaceCoveredAtALookIsKeptWhileItStillMatches) {
  SkinOptions options;
  options.face_interval = 2;
  SkinSegmenter segmenter(options);
  const cv::Mat wall = MakeBackground(BackgroundKind::kClutter, cv::Size(640, 480), 3);
  cv::Mat face = wall.clone();
  DrawFace(SkinToneByName("olive").bgr, cv::Point(300, 220), 180, &face);
  const SkinSegmentation first = segmenter.Segment(face);
  ASSERT_TRUE(first.faces_looked);
  ASSERT_EQ(first.faces.size(), 1u);
  const cv::Rect at = first.faces[0];
  EXPECT_FALSE(segmenter.Segment(face).faces_looked);
  cv::Mat covered = face.clone();
  const cv::Vec3f hand = SkinToneByName("brown").bgr;
  cv::rectangle(covered, cv::Rect(at.x - 40, at.y + at.height / 5, at.width + 80, at.height * 2 / 5),
                cv::Scalar(hand[0], hand[1], hand[2]), cv::FILLED);
  SkinSegmenter fresh(options);
  EXPECT_TRUE(fresh.Segment(covered).faces.empty()) << "the cascade alone misses the covered face";
  const SkinSegmentation look = segmenter.Segment(covered);
  EXPECT_TRUE(look.faces_looked);
  ASSERT_EQ(look.faces.size(), 1u);
  EXPECT_LE(std::abs(look.faces[0].x - at.x) + std::abs(look.faces[0].y - at.y), 4);
  EXPECT_GT(look.face_pixels, 0);
  segmenter.Segment(wall);
  const SkinSegmentation gone = segmenter.Segment(wall);
  EXPECT_TRUE(gone.faces_looked);
  EXPECT_TRUE(gone.faces.empty());
}

// A face's box, found before a hand came over it, is looked for again every face_relook
// frames while the hand found last lies half or more within it; elsewhere the hand leaves
// the looks to face_interval.
TEST(SkinTest, AFaceIsLookedForAgainWhileTheHandIsOverIt) {
  const cv::Mat frame = WithFace(MakeBackground(BackgroundKind::kClutter, cv::Size(640, 480), 3), "olive", cv::Point(300, 220), 180);
  auto looks = [&](bool over_face) {
    SkinSegmenter segmenter(LookingAtFirst());
    const SkinSegmentation first = segmenter.Segment(frame);
    EXPECT_TRUE(first.faces_looked);
    EXPECT_EQ(first.faces.size(), 1u);
    const cv::Rect face = first.faces.empty() ? cv::Rect() : first.faces[0];
    // Over the face: its box a little off the face's, most of it within; or far from it.
    const cv::Rect hand = over_face ? cv::Rect(face.x + face.width / 3, face.y, face.width, face.height) : cv::Rect(10, 10, 60, 80);
    std::vector<int> looked;
    for (int f = 1; f <= 11; ++f) {
      const SkinSegmentation s = segmenter.Segment(frame, hand);
      EXPECT_EQ(s.faces.size(), 1u) << f;
      if (s.faces_looked) looked.push_back(f);
    }
    return looked;
  };
  EXPECT_EQ(looks(true), std::vector<int>({5, 10}));
  EXPECT_TRUE(looks(false).empty());
}

// Between full looks (every kFullLooks-th periodic one), a look seeks faces about as wide as
// a face followed in the region it looks at: it finds that face again, box and all, as it
// comes nearer, but a small face in the same region waits for the full look.
TEST(SkinTest, ALookBetweenFullOnesSeeksFacesOfTheFollowedOnesSize) {
  SkinOptions options;
  options.face_interval = 2;  // looks at frames 0, 2, 4, 6 and 8; full at 0 and 8
  SkinSegmenter segmenter(options);
  const cv::Mat wall = MakeBackground(BackgroundKind::kClutter, cv::Size(640, 480), 3);
  const cv::Vec3f skin = SkinToneByName("olive").bgr;
  // The large face, `height` pixels tall; with `child`, a small face joined to its region by
  // a skin-coloured shoulder.
  auto scene = [&](int height, bool child) {
    cv::Mat frame = wall.clone();
    if (child) {
      cv::rectangle(frame, cv::Rect(300, 330, 260, 150), cv::Scalar(skin[0], skin[1], skin[2]), cv::FILLED);
      DrawFace(skin, cv::Point(500, 280), 90, &frame);
    }
    DrawFace(skin, cv::Point(260, 220), height, &frame);
    return frame;
  };
  // The two faces' skin is one region (what the looks search around).
  SkinSegmenter faceless(NoFaces());
  const SkinSegmentation joined = faceless.Segment(scene(200, true));
  ASSERT_FALSE(joined.regions.empty());
  EXPECT_TRUE(joined.regions[0].box.contains(cv::Point(260, 220)) && joined.regions[0].box.contains(cv::Point(500, 280)));
  const SkinSegmentation first = segmenter.Segment(scene(180, false));
  ASSERT_TRUE(first.faces_looked);
  ASSERT_EQ(first.faces.size(), 1u);
  segmenter.Segment(scene(200, true));
  // Frame 2: the large face, nearer, found again with its new size; the small one not.
  const SkinSegmentation banded = segmenter.Segment(scene(200, true));
  ASSERT_TRUE(banded.faces_looked);
  ASSERT_EQ(banded.faces.size(), 1u);
  EXPECT_GT(banded.faces[0].width, first.faces[0].width * 21 / 20);
  // A fresh segmenter's first look is full and finds both.
  SkinSegmenter fresh(options);
  EXPECT_EQ(fresh.Segment(scene(200, true)).faces.size(), 2u);
  for (int f = 3; f < 8; ++f) EXPECT_EQ(segmenter.Segment(scene(200, true)).faces.size(), 1u) << f;
  const SkinSegmentation full = segmenter.Segment(scene(200, true));
  ASSERT_TRUE(full.faces_looked);
  EXPECT_EQ(full.faces.size(), 2u);
  // A face followed while it grew past the band (1.5 times as wide over 8 frames) is not
  // found at its old size at the next look: its region is then searched at every size.
  SkinOptions every_eight = options;
  every_eight.face_interval = 8;  // looks at frames 0 (full) and 8
  SkinSegmenter grown(every_eight);
  const SkinSegmentation small = grown.Segment(scene(140, false));
  ASSERT_EQ(small.faces.size(), 1u);
  for (int f = 1; f < 8; ++f) {
    const SkinSegmentation s = grown.Segment(scene(static_cast<int>(std::lround(140 * std::pow(1.052, f))), false));
    ASSERT_EQ(s.faces.size(), 1u) << f;
    EXPECT_EQ(s.faces[0].width, small.faces[0].width) << f;  // a follow keeps the size
  }
  const SkinSegmentation again = grown.Segment(scene(210, false));
  ASSERT_TRUE(again.faces_looked);
  ASSERT_EQ(again.faces.size(), 1u);
  EXPECT_GT(again.faces[0].width, small.faces[0].width * 13 / 10);
}

// What the set-aside head leaves beside a face is a sliver (a cheek, the edge of a neck); a
// region of a hand's size there (kInFrontShare of the face's box) stays a region. Here a
// hand of the face's colour lies against its cheek, with no outline between them: the part
// within the head's ellipse (0.7 of the face's width each way) goes with the face, the rest
// lies within a fifth of a face's width past it.
TEST(SkinTest, AHandBesideAFaceIsNoLeftoverOfIt) {
  const cv::Vec3f skin = SkinToneByName("light").bgr;
  const cv::Mat face_only = WithFace(MakeBackground(BackgroundKind::kClutter, cv::Size(640, 480), 3), "light", cv::Point(300, 220), 200);
  SkinSegmenter finder(LookingAtFirst());
  const SkinSegmentation found = finder.Segment(face_only);
  ASSERT_EQ(found.faces.size(), 1u);
  ASSERT_TRUE(found.regions.empty());
  const cv::Rect face = found.faces[0];
  const cv::Point centre(face.x + face.width / 2, face.y + face.height / 2);
  const int w = face.width;
  // The regions left with a band against the cheek from 0.3 to 0.85 of the face's width
  // right of its centre, `half` of it high each way; and its pixels outside the head.
  auto with_band = [&](int half, int* outside) {
    cv::Mat frame = face_only.clone();
    const cv::Rect band(centre.x + w * 3 / 10, centre.y - half, w * 55 / 100, 2 * half);
    frame(band).setTo(cv::Scalar(skin[0], skin[1], skin[2]));
    cv::Mat head = cv::Mat::zeros(frame.size(), CV_8UC1);
    cv::ellipse(head, centre, cv::Size(w * 7 / 10, face.height * 9 / 10), 0, 0, 360, cv::Scalar(255), cv::FILLED);
    *outside = band.area() - cv::countNonZero(head(band));
    // The face found before the hand came, and followed.
    SkinSegmenter segmenter(LookingAtFirst());
    segmenter.Segment(face_only);
    const SkinSegmentation s = segmenter.Segment(frame);
    EXPECT_FALSE(s.faces_looked);
    EXPECT_EQ(s.faces.size(), 1u);
    for (const cv::Rect& f : s.faces) EXPECT_LE(std::abs(f.x - face.x) + std::abs(f.y - face.y), 4);
    return s.regions.size();
  };
  int hand = 0, sliver = 0;
  EXPECT_EQ(with_band(w * 7 / 10, &hand), 1u);
  EXPECT_EQ(with_band(w / 5, &sliver), 0u);
  EXPECT_GT(hand, 0.15 * face.area());
  EXPECT_LT(sliver, 0.15 * face.area());
}

// A hand held in front of a face, its forearm coming in from the frame's edge (the demo's
// opening frames): the head's skin that the hand's outline parts from the face stays skin, in
// one region with the fingers and the arm; the face's own skin is set aside all the same.
TEST(SkinTest, AHandInFrontOfAFaceKeepsWhatItsOutlinePartsFromTheFace) {
  Sequence sequence(testing::RightHand(), testing::DemoSequence(11));
  const SequenceFrame frame = sequence.Render(2);
  const cv::Mat body = (frame.labels == static_cast<int>(PixelLabel::kHand)) |
                       (frame.labels == static_cast<int>(PixelLabel::kForearm));
  // The share of the hand's and arm's pixels in the region holding most of them.
  auto covered = [&](bool part_faces) {
    SkinOptions skin;
    skin.part_faces = part_faces;
    SkinSegmenter segmenter(skin);
    const SkinSegmentation s = segmenter.Segment(frame.rgb);
    EXPECT_EQ(s.faces.size(), 1u);
    double best = 0.0;
    for (const SkinRegion& region : s.regions) {
      const cv::Mat mask = s.Mask({region.label}, cv::Rect(cv::Point(0, 0), s.frame));
      best = std::max(best, static_cast<double>(cv::countNonZero(mask & body)) / cv::countNonZero(body));
      // No region holds the face's middle.
      if (!s.faces.empty()) {
        const cv::Rect face = s.faces[0];
        const cv::Rect middle(face.x + face.width / 4, face.y + face.height / 4, face.width / 2, face.height / 2);
        const cv::Mat in_middle = mask(middle) & ~body(middle);
        EXPECT_LT(cv::countNonZero(in_middle), 0.05 * middle.area()) << part_faces;
      }
    }
    return best;
  };
  const double parted = covered(true), whole = covered(false);
  // 0.67 while the kept pieces grew back only by the opening's width: the fingers over the
  // chin, thinner than the opening and creased by their texture's edges, stayed the face's.
  EXPECT_GE(parted, 0.75);
  EXPECT_LT(whole, 0.1);
  // The fingers the outline and the object split from it, beside the face, are no face
  // remnants: of the hand's skin, next to none is left out of the regions.
  SkinSegmenter segmenter;
  const SkinSegmentation s = segmenter.Segment(frame.rgb);
  cv::Mat skin;
  cv::resize(s.skin, skin, s.frame, 0.0, 0.0, cv::INTER_NEAREST);
  const cv::Mat hand = frame.labels == static_cast<int>(PixelLabel::kHand);
  EXPECT_LT(cv::countNonZero(skin & hand & ~Regions(s)), 0.03 * cv::countNonZero(hand));
}

// A hand pointing in front of a face and its neck, its fingers across the mouth: its own
// creases and shading part it into pieces too small to be kept one by one, but it goes on
// outside the face as an arm, and is kept whole.
TEST(SkinTest, AHandCreasedIntoPiecesInFrontOfAFaceIsKeptWhole) {
  SequenceOptions options;
  options.grasp = GestureByName("point").id;
  options.object = false;
  options.background = BackgroundKind::kClutter;
  options.face = true;
  options.seed = 7503;
  Sequence sequence(testing::RightHand(), options);
  for (const int i : {5, 20}) {
    const SequenceFrame frame = sequence.Render(i);
    const cv::Mat hand = frame.labels == static_cast<int>(PixelLabel::kHand);
    SkinSegmenter segmenter;
    const SkinSegmentation s = segmenter.Segment(frame.rgb);
    ASSERT_EQ(s.faces.size(), 1u) << i;
    const cv::Rect face = s.faces[0];
    ASSERT_GT(cv::countNonZero(hand(face)), 0.2 * cv::countNonZero(hand)) << i << ": the hand is over the face";
    // The share of the hand's pixels in the region holding most of them.
    double best = 0.0;
    for (const SkinRegion& region : s.regions) {
      const cv::Mat mask = s.Mask({region.label}, cv::Rect(cv::Point(0, 0), s.frame));
      best = std::max(best, static_cast<double>(cv::countNonZero(mask & hand)) / cv::countNonZero(hand));
      const cv::Rect middle(face.x + face.width / 4, face.y + face.height / 4, face.width / 2, face.height / 2);
      EXPECT_LT(cv::countNonZero(mask(middle) & ~hand(middle)), 0.1 * middle.area()) << i << ": the face stays set aside";
    }
    // 0.80 and 0.95; 0.32 and 0.46 while the pieces were judged one by one.
    EXPECT_GT(best, 0.7) << i;
  }
}

// An arm passing beside a face, apart from its skin but within its head's ellipse in a
// sliver (the demo's frames 27-29: a face's box followed from earlier looks is a little
// larger than the face): the sliver goes on outside the head, so it is no face remnant and
// the arm stays whole.
TEST(SkinTest, AnArmPassingBesideAFaceStaysWhole) {
  cv::Mat frame = MakeBackground(BackgroundKind::kClutter, cv::Size(640, 480), testing::kTestSeed);
  const cv::Vec3f skin = SkinToneByName("light").bgr;
  DrawFace(skin, cv::Point(300, 220), 200, &frame);
  cv::Mat arm = cv::Mat::zeros(frame.size(), CV_8UC1);
  cv::line(arm, cv::Point(420, 0), cv::Point(450, 479), cv::Scalar(255), 50);
  frame.setTo(cv::Scalar(skin[0], skin[1], skin[2]), arm);
  // The share of the arm's pixels in the region holding most of them.
  auto most = [&](const SkinSegmentation& s) {
    double best = 0.0;
    for (const SkinRegion& region : s.regions) {
      const cv::Mat mask = s.Mask({region.label}, cv::Rect(cv::Point(0, 0), s.frame));
      best = std::max(best, static_cast<double>(cv::countNonZero(mask & arm)) / cv::countNonZero(arm));
      for (const cv::Rect& face : s.faces) {
        const cv::Rect middle(face.x + face.width / 4, face.y + face.height / 4, face.width / 2, face.height / 2);
        EXPECT_EQ(cv::countNonZero(mask(middle)), 0) << "the face is set aside";
      }
    }
    return best;
  };
  SkinSegmenter segmenter;
  const SkinSegmentation s = segmenter.Segment(frame);
  ASSERT_EQ(s.faces.size(), 1u);
  const cv::Rect face = s.faces[0];
  ASSERT_EQ(cv::countNonZero(arm(face & cv::Rect(cv::Point(0, 0), arm.size()))), 0) << "the arm lies beside the face's box";
  ASSERT_GT(face.x + face.width / 2 + 7 * face.width / 10, 420) << "and within its head's ellipse";
  SkinSegmenter without_faces(NoFaces());
  const double alone = most(without_faces.Segment(frame));
  EXPECT_GT(alone, 0.95);
  // Before the sliver counted as going on, 0.86 of the arm; the ends of the sliver, where the
  // ellipse crosses the arm's outline, are too thin to survive the opening (1 %).
  EXPECT_GT(most(s), alone - 0.02);
}

// A person in a skin-coloured sweater behind the hand: the body below the face is set
// aside, the hand and its arm stay regions.
TEST(SkinTest, ABodyInASkinColouredSweaterIsSetAsideAndTheHandStays) {
  for (const auto& [seed, at] : {std::pair{12u, 0}, std::pair{13u, 60}}) {
    SequenceOptions options = testing::DemoSequence(seed);
    options.sweater = true;
    Sequence sequence(testing::RightHand(), options);
    const SequenceFrame frame = sequence.Render(at);
    cv::Mat arm = (frame.labels == static_cast<int>(PixelLabel::kHand)) | (frame.labels == static_cast<int>(PixelLabel::kForearm));
    const cv::Mat hand = frame.labels == static_cast<int>(PixelLabel::kHand);
    cv::dilate(arm, arm, cv::Mat(), cv::Point(-1, -1), 4);
    // Of the regions' pixels, those away from the hand and arm; and the share of the hand's
    // pixels in the regions.
    auto segment = [&](bool set_aside_bodies, int* body_pixels) {
      SkinOptions skin;
      skin.set_aside_bodies = set_aside_bodies;
      skin.face_chroma = 0.0;  // which shuts out the lighter sweaters on its own
      SkinSegmenter segmenter(skin);
      const SkinSegmentation s = segmenter.Segment(frame.rgb);
      EXPECT_EQ(s.faces.size(), 1u) << seed;
      *body_pixels = s.body_pixels;
      const cv::Mat regions = Regions(s);
      return std::pair{cv::countNonZero(regions & ~arm), static_cast<double>(cv::countNonZero(regions & hand)) / cv::countNonZero(hand)};
    };
    int body = 0, kept_body = 0;
    const auto [astray, hand_share] = segment(true, &body);
    const auto [astray_kept, hand_share_kept] = segment(false, &kept_body);
    EXPECT_GT(body, 10000) << seed;
    EXPECT_EQ(kept_body, 0) << seed;
    EXPECT_GT(astray_kept, 10000) << seed << ": the sweater is skin-coloured";
    EXPECT_LT(astray, 0.05 * astray_kept) << seed;
    EXPECT_NEAR(hand_share, hand_share_kept, 1e-9) << seed;
    EXPECT_GT(hand_share, 0.8) << seed;
  }
}

// Two arms raised from the frame's bottom below a face, as far apart as shoulders, are no
// body: each is taller than wide.
TEST(SkinTest, ArmsRaisedBelowAFaceAreNoBody) {
  cv::Mat frame = MakeBackground(BackgroundKind::kClutter, cv::Size(640, 480), testing::kTestSeed);
  const cv::Vec3f skin = SkinToneByName("light").bgr;
  DrawFace(skin, cv::Point(320, 140), 200, &frame);
  const cv::Scalar colour(skin[0], skin[1], skin[2]);
  for (int x : {140, 500}) {
    cv::rectangle(frame, cv::Rect(x - 30, 300, 60, 180), colour, cv::FILLED);
    cv::ellipse(frame, cv::Point(x, 290), cv::Size(45, 60), 0.0, 0.0, 360.0, colour, cv::FILLED);
  }
  SkinSegmenter segmenter;
  const SkinSegmentation s = segmenter.Segment(frame);
  ASSERT_EQ(s.faces.size(), 1u);
  EXPECT_EQ(s.body_pixels, 0);
  for (const cv::Point arm : {cv::Point(140, 400), cv::Point(500, 400)}) {
    EXPECT_TRUE(std::any_of(s.regions.begin(), s.regions.end(), [&](const SkinRegion& r) { return r.box.contains(arm); })) << arm;
  }
}

// Flushed fingertips and knuckles lie beyond the skin box (Cr 171-183 on a real hand under
// warm light): such chroma is skin in a small piece that meets skin, not in a piece on its
// own nor in a large one (a warm wall beside the hand).
TEST(SkinTest, FlushedFingertipsJoinTheirHand) {
  const cv::Vec3f tone = SkinToneByName("medium").bgr;
  const cv::Scalar skin(tone[0], tone[1], tone[2]);
  const cv::Scalar flushed(71, 83, 185);  // Y 112, Cr 180, Cb 105: a fingertip of real-dev's
  cv::Mat frame(240, 320, CV_8UC3, cv::Scalar(200, 200, 200));
  cv::rectangle(frame, cv::Rect(60, 100, 70, 120), skin, cv::FILLED);
  const cv::Rect tip(80, 70, 16, 30), apart(200, 20, 16, 30), wall(130, 100, 120, 120);
  cv::rectangle(frame, tip, flushed, cv::FILLED);
  cv::rectangle(frame, apart, flushed, cv::FILLED);
  cv::rectangle(frame, wall, flushed, cv::FILLED);
  auto skin_in = [](const SkinSegmentation& s, cv::Rect r) {
    return static_cast<double>(cv::countNonZero(Regions(s)(r))) / r.area();
  };
  SkinOptions options = NoFaces();
  ASSERT_LT(tip.area(), options.rim_area * frame.total());
  ASSERT_GT(wall.area(), options.rim_area * frame.total());
  SkinSegmenter with_rim(options);
  SkinSegmentation s = with_rim.Segment(frame);
  EXPECT_GT(skin_in(s, tip), 0.9);
  EXPECT_LT(skin_in(s, apart), 0.01);
  EXPECT_LT(skin_in(s, wall), 0.01);
  options.rim_area = 0.0;
  SkinSegmenter without(options);
  s = without.Segment(frame);
  EXPECT_LT(skin_in(s, tip), 0.01);
}

// A wall behind the person of a colour the fixed model takes for skin but far from the
// face's own (a cream wall behind medium skin, a wooden one behind light skin): with a face in
// view, the wall is no skin and the hand, shaded as it is, stays.
TEST(SkinTest, AFacesOwnSkinShutsOutAWarmWallAndKeepsTheHand) {
  for (const auto& [tone, wall_bgr] : {std::pair{"medium", cv::Scalar(175, 205, 225)}, std::pair{"light", cv::Scalar(60, 110, 170)}}) {
    SequenceOptions options = testing::DemoSequence(12);
    options.skin = tone;
    Sequence sequence(testing::RightHand(), options);
    const SequenceFrame frame = sequence.Render(60);
    const cv::Mat hand = frame.labels == static_cast<int>(PixelLabel::kHand);
    cv::Mat arm = hand | (frame.labels == static_cast<int>(PixelLabel::kForearm));
    cv::dilate(arm, arm, cv::Mat(), cv::Point(-1, -1), 4);
    SkinSegmenter looker;
    const std::vector<cv::Rect> faces = looker.Segment(frame.rgb).faces;
    ASSERT_EQ(faces.size(), 1u) << tone;
    // The wall: the background of the upper three fifths of the frame's half away from the
    // face (where the hand moves), a little noisy.
    const cv::Rect face = faces[0];
    const int half = frame.rgb.cols / 2;
    cv::Mat wall = cv::Mat::zeros(frame.rgb.size(), CV_8UC1);
    wall(cv::Rect(face.x + face.width / 2 < half ? half : 0, 0, half, frame.rgb.rows * 3 / 5)).setTo(255);
    wall &= frame.labels == static_cast<int>(PixelLabel::kBackground);
    cv::Mat painted(frame.rgb.size(), CV_8UC3, wall_bgr), noise(frame.rgb.size(), CV_8UC3);
    cv::RNG rng(testing::kTestSeed);
    rng.fill(noise, cv::RNG::NORMAL, cv::Scalar::all(0), cv::Scalar::all(3));
    painted += noise;
    cv::Mat with_wall = frame.rgb.clone();
    painted.copyTo(with_wall, wall);
    // The regions' pixels on the wall, and their share of the hand's pixels.
    auto segment = [&](double face_chroma) {
      SkinOptions skin;
      skin.face_chroma = face_chroma;
      SkinSegmenter segmenter(skin);
      const SkinSegmentation s = segmenter.Segment(with_wall);
      EXPECT_EQ(s.faces.size(), 1u) << tone;
      const cv::Mat regions = Regions(s);
      return std::pair{cv::countNonZero(regions & wall & ~arm), static_cast<double>(cv::countNonZero(regions & hand)) / cv::countNonZero(hand)};
    };
    const auto [on_wall, hand_share] = segment(SkinOptions{}.face_chroma);
    const auto [on_wall_without, hand_share_without] = segment(0.0);
    EXPECT_GT(on_wall_without, 0.3 * cv::countNonZero(wall)) << tone << ": the fixed model takes the wall";
    EXPECT_LT(on_wall, 0.01 * on_wall_without) << tone;
    EXPECT_GT(hand_share, 0.8) << tone;
    EXPECT_GT(hand_share, 0.95 * hand_share_without) << tone;
  }
}

TEST(SkinTest, BadInputIsRefused) {
  SkinSegmenter segmenter(NoFaces());
  testing::ExpectError([&] { segmenter.Segment(cv::Mat()); }, "8-bit BGR");
  testing::ExpectError([&] { segmenter.Segment(cv::Mat(10, 10, CV_8UC1)); }, "8-bit BGR");
  SkinOptions options = NoFaces();
  options.cr_min = 200;
  testing::ExpectError([&] { SkinSegmenter bad(options); }, "min <= max");
  options = NoFaces();
  options.rim_cr_max = 150;
  testing::ExpectError([&] { SkinSegmenter bad(options); }, "hold the skin box");
  options = NoFaces();
  options.rim_area = 1.0;
  testing::ExpectError([&] { SkinSegmenter bad(options); }, "rim's largest piece");
  options = NoFaces();
  options.work_width = 10;
  testing::ExpectError([&] { SkinSegmenter bad(options); }, "working width");
  options = NoFaces();
  options.face_chroma = -1.0;
  testing::ExpectError([&] { SkinSegmenter bad(options); }, "face's chroma reach");
  options = SkinOptions{};
  options.face_cascade = "/nonexistent/cascade.xml";
  testing::ExpectError([&] { SkinSegmenter bad(options); }, "no face cascade");
  // The default cascade loads (Debian's opencv-data is a set-up dependency).
  SkinSegmenter with_faces;
  EXPECT_TRUE(with_faces.Segment(MakeBackground(BackgroundKind::kPlain, cv::Size(64, 48), 1)).faces.empty());
}

}  // namespace
}  // namespace nphand
