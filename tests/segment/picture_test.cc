#include "nphand/segment/picture.h"

#include <cmath>
#include <cstdint>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "nphand/sequence/background.h"
#include "testing/testing.h"

namespace nphand {
namespace {

// A cluttered room of `size` (BGR), as the rendered sequences' backgrounds are.
cv::Mat Scene(cv::Size size, uint64_t seed) { return MakeBackground(BackgroundKind::kClutter, size, seed); }

// `picture` in a black frame of `frame`, at `at`, through JPEG (its noise lifts the bars'
// pixels and blurs their edges).
cv::Mat Boxed(const cv::Mat& picture, cv::Size frame, cv::Point at) {
  cv::Mat boxed = cv::Mat::zeros(frame, CV_8UC3);
  picture.copyTo(boxed(cv::Rect(at, picture.size())));
  std::vector<uint8_t> jpeg;
  cv::imencode(".jpg", boxed, jpeg, {cv::IMWRITE_JPEG_QUALITY, 75});
  return cv::imdecode(jpeg, cv::IMREAD_COLOR);
}

// Within `slack` lines past the bars' inner edges (JPEG blurs them).
void ExpectPicture(const cv::Rect& found, const cv::Rect& truth, int slack = kBarEdgeLeast) {
  EXPECT_GE(found.x, truth.x);
  EXPECT_LE(found.x, truth.x + slack);
  EXPECT_GE(found.y, truth.y);
  EXPECT_LE(found.y, truth.y + slack);
  EXPECT_LE(found.br().x, truth.br().x);
  EXPECT_GE(found.br().x, truth.br().x - slack);
  EXPECT_LE(found.br().y, truth.br().y);
  EXPECT_GE(found.br().y, truth.br().y - slack);
}

TEST(PictureTest, PillarboxedAndLetterboxedPicturesAreFoundWithinTheirBars) {
  // An upright phone clip in a wide frame, a wide film in a tall one, and both at once.
  const cv::Rect pillarbox(140, 0, 360, 480), letterbox(0, 60, 640, 360), windowbox(80, 40, 480, 400);
  for (const cv::Rect& truth : {pillarbox, letterbox, windowbox}) {
    const cv::Mat frame = Boxed(Scene(truth.size(), testing::kTestSeed), cv::Size(640, 480), truth.tl());
    ExpectPicture(PictureOf(frame), truth);
  }
  // A dark spot on the bar's edge passes for its blur: the picture starts past it, within
  // the edge's reach (kBarEdge of the side).
  cv::Mat spotted = Scene(pillarbox.size(), testing::kTestSeed + 1);
  cv::circle(spotted, cv::Point(3, 240), 6, cv::Scalar::all(0), cv::FILLED);
  const cv::Rect found = PictureOf(Boxed(spotted, cv::Size(640, 480), pillarbox.tl()));
  ExpectPicture(found, pillarbox, static_cast<int>(kBarEdge * 640));
  EXPECT_GT(found.x, pillarbox.x + kBarEdgeLeast) << "the spot is within the picture's edge";
}

// Clean bars (no JPEG) are found to the line, also where the two are not equally deep,
// within kBarPairing of the side, and in a frame that is a view into a larger image.
TEST(PictureTest, CleanBarsAreFoundToTheLine) {
  const cv::Size frame(640, 480);
  auto barred = [&](int left, int right, int top, int bottom) {
    cv::Mat f = Scene(frame, testing::kTestSeed);
    f.colRange(0, left).setTo(cv::Scalar::all(0));
    f.colRange(frame.width - right, frame.width).setTo(cv::Scalar::all(0));
    f.rowRange(0, top).setTo(cv::Scalar::all(0));
    f.rowRange(frame.height - bottom, frame.height).setTo(cv::Scalar::all(0));
    return f;
  };
  EXPECT_EQ(PictureOf(barred(140, 148, 0, 0)), cv::Rect(140, 0, 352, 480));
  EXPECT_EQ(PictureOf(barred(0, 0, 60, 52)), cv::Rect(0, 60, 640, 368));
  EXPECT_EQ(PictureOf(barred(60, 70, 0, 0)), cv::Rect(60, 0, 510, 480)) << "10 lines apart, within 2 % of 640";
  EXPECT_EQ(PictureOf(barred(60, 100, 0, 0)), cv::Rect(0, 0, 640, 480)) << "40 lines apart: no pair";
  // A view into a larger image, bright around it: its rows are apart in memory.
  cv::Mat larger(700, 900, CV_8UC3, cv::Scalar::all(200));
  barred(140, 148, 0, 0).copyTo(larger(cv::Rect(100, 120, 640, 480)));
  EXPECT_EQ(PictureOf(larger(cv::Rect(100, 120, 640, 480))), cv::Rect(140, 0, 352, 480));
}

// A phone's upright clip (9:16) in a 16:9 frame leaves bars of 0.342 of the width.
TEST(PictureTest, AnUprightClipInAWideFrameIsFound) {
  const cv::Rect clip(437, 0, 405, 720);
  const cv::Mat frame = Boxed(Scene(clip.size(), testing::kTestSeed), cv::Size(1280, 720), clip.tl());
  ExpectPicture(PictureOf(frame), clip);
}

TEST(PictureTest, AFrameWithoutPairedStraightBarsIsWhole) {
  const cv::Rect whole(0, 0, 640, 480);
  // No bars.
  EXPECT_EQ(PictureOf(Scene(whole.size(), testing::kTestSeed)), whole);
  // A dark scene along one side (a doorway, a black backdrop): no twin on the other.
  cv::Mat one_side = Scene(whole.size(), testing::kTestSeed);
  one_side(cv::Rect(0, 0, 120, 480)).setTo(cv::Scalar::all(3));
  EXPECT_EQ(PictureOf(one_side), whole);
  // Dark along both sides, but its edge is not straight: the dark goes on, ragged.
  cv::Mat ragged = Scene(whole.size(), testing::kTestSeed);
  for (int y = 0; y < 480; ++y) {
    const int reach = 60 + static_cast<int>(40.0 * std::sin(y / 15.0));
    ragged(cv::Rect(0, y, reach, 1)).setTo(cv::Scalar::all(0));
    ragged(cv::Rect(640 - reach, y, reach, 1)).setTo(cv::Scalar::all(0));
  }
  EXPECT_EQ(PictureOf(ragged), whole);
  // One black line along each side is the scene's.
  cv::Mat lines = Scene(whole.size(), testing::kTestSeed);
  lines.col(0).setTo(cv::Scalar::all(0));
  lines.col(639).setTo(cv::Scalar::all(0));
  EXPECT_EQ(PictureOf(lines), whole);
  // A night: dark past kBarMost of the width on both sides is no bar, and an all-black
  // frame is all picture.
  cv::Mat night = Scene(whole.size(), testing::kTestSeed);
  night(cv::Rect(0, 0, 260, 480)).setTo(cv::Scalar::all(0));
  night(cv::Rect(380, 0, 260, 480)).setTo(cv::Scalar::all(0));
  EXPECT_EQ(PictureOf(night), whole);
  EXPECT_EQ(PictureOf(cv::Mat::zeros(480, 640, CV_8UC3)), whole);
  // Frames under 8 pixels across have no bars; at 9, two black lines each side are a pair.
  for (int side : {1, 2, 3, 7}) {
    EXPECT_EQ(PictureOf(cv::Mat::zeros(side, side, CV_8UC3)), cv::Rect(0, 0, side, side));
  }
  cv::Mat small(9, 9, CV_8UC3, cv::Scalar::all(200));
  small.colRange(0, 2).setTo(cv::Scalar::all(0));
  small.colRange(7, 9).setTo(cv::Scalar::all(0));
  EXPECT_EQ(PictureOf(small), cv::Rect(2, 0, 5, 9));
}

TEST(PictureTest, OtherImagesAreRefused) {
  testing::ExpectError([] { PictureOf(cv::Mat()); }, "non-empty 8-bit BGR");
  testing::ExpectError([] { PictureOf(cv::Mat::zeros(10, 10, CV_8UC1)); }, "non-empty 8-bit BGR");
}

}  // namespace
}  // namespace nphand
