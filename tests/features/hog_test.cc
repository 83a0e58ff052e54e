#include "nphand/features/hog.h"

#include <cmath>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "nphand/util/check.h"

namespace nphand {
namespace {

// A 4 x 4 image, 1 where `inside(x, y)`.
template <typename F>
cv::Mat Tiny(F inside) {
  cv::Mat image(4, 4, CV_32FC1, cv::Scalar(0));
  for (int y = 0; y < 4; ++y) {
    for (int x = 0; x < 4; ++x) image.at<float>(y, x) = inside(x, y) ? 1.0f : 0.0f;
  }
  return image;
}

// The histograms with each cell summed to 1 (the "normalised holes" variant).
std::vector<float> Raw(const cv::Mat& image, HogOptions options) {
  options.normalization = HogNormalization::kCellSum;
  return ComputeHog(image, options);
}

TEST(HogTest, VerticalEdgeVotesIntoTheZeroDegreeBin) {
  // Columns 2, 3 are hand: gx = 1 at x = 1 and x = 2 (replicated border: 0 elsewhere).
  const cv::Mat image = Tiny([](int x, int) { return x >= 2; });
  const HogOptions options{.cells = 2, .bins = 4};
  const std::vector<float> hog = ComputeHog(image, options);
  ASSERT_EQ(hog.size(), 16u);
  // Each 2 x 2 cell holds two pixels of magnitude 1 at 0 degrees: [2, 0, 0, 0] per cell,
  // divided by the L2 norm sqrt(4 * 2^2) = 4.
  for (int cell = 0; cell < 4; ++cell) {
    EXPECT_FLOAT_EQ(hog[cell * 4 + 0], 0.5f);
    for (int b = 1; b < 4; ++b) EXPECT_FLOAT_EQ(hog[cell * 4 + b], 0.0f);
  }
}

TEST(HogTest, UnsignedOrientationFoldsOppositeGradients) {
  const cv::Mat left = Tiny([](int x, int) { return x < 2; });  // gx = -1: 180 degrees
  const HogOptions unsigned_options{.cells = 2, .bins = 4};
  EXPECT_EQ(ComputeHog(left, unsigned_options), ComputeHog(Tiny([](int x, int) { return x >= 2; }), unsigned_options));
  // Signed: 4 bins over 360 degrees, 180 degrees is bin 2.
  const std::vector<float> hog = Raw(left, {.cells = 2, .bins = 4, .signed_orientation = true});
  for (int cell = 0; cell < 4; ++cell) EXPECT_FLOAT_EQ(hog[cell * 4 + 2], 1.0f);
}

TEST(HogTest, HorizontalEdgeAndInBetweenAnglesSplitLinearly) {
  // Rows 2, 3 are hand: gy = 1, 90 degrees = bin 2 of 4 (45 degrees apart).
  const std::vector<float> horizontal = Raw(Tiny([](int, int y) { return y >= 2; }), {.cells = 1, .bins = 4});
  EXPECT_EQ(horizontal, (std::vector<float>{0, 0, 1, 0}));
  // The ramp I = x + y on 6 x 6: inside, gx = gy = 2, 45 degrees. With 3 unsigned bins
  // (centres 0, 60, 120 degrees) 45 degrees lies 3/4 of the way from bin 0 to bin 1, so the
  // centre cell of 3 x 3 (its pixels are all inside) holds [1/4, 3/4, 0] of its votes.
  cv::Mat ramp(6, 6, CV_32FC1);
  for (int y = 0; y < 6; ++y) {
    for (int x = 0; x < 6; ++x) ramp.at<float>(y, x) = static_cast<float>(x + y);
  }
  const std::vector<float> hog = Raw(ramp, {.cells = 3, .bins = 3});
  const int centre = 4 * 3;
  EXPECT_NEAR(hog[centre + 0], 0.25f, 1e-6f);
  EXPECT_NEAR(hog[centre + 1], 0.75f, 1e-6f);
  EXPECT_NEAR(hog[centre + 2], 0.0f, 1e-6f);
  // Unnormalised, that cell holds 4 pixels of magnitude 2 sqrt(2): global L2 keeps the
  // ratios between cells, so the centre's share of the whole equals its raw share.
  const std::vector<float> l2 = ComputeHog(ramp, {.cells = 3, .bins = 3});
  EXPECT_NEAR(l2[centre + 1] / l2[centre + 0], 3.0f, 1e-5f);
}

TEST(HogTest, PyramidLevelsAreSumsOfTheCellsBelow) {
  cv::Mat image(32, 32, CV_32FC1, cv::Scalar(0));
  cv::circle(image, {15, 18}, 9, cv::Scalar(1.0f), -1);
  const HogOptions options{.cells = 4, .bins = 8, .pyramid = true};
  EXPECT_EQ(options.Dimension(), 8 * (16 + 4 + 1));
  const std::vector<float> hog = ComputeHog(image, options);
  ASSERT_EQ(static_cast<int>(hog.size()), options.Dimension());
  for (int b = 0; b < 8; ++b) {
    float fine = 0, middle = 0;
    for (int c = 0; c < 16; ++c) fine += hog[c * 8 + b];
    for (int c = 0; c < 4; ++c) middle += hog[(16 + c) * 8 + b];
    EXPECT_NEAR(middle, fine, 1e-5f);
    EXPECT_NEAR(hog[(20) * 8 + b], fine, 1e-5f);
  }
  EXPECT_EQ(options.Name(), "hog4x4x8_pyr");
}

TEST(HogTest, EmptyCropGivesZerosAndBadInputIsRefused) {
  const std::vector<float> zeros = ComputeHog(cv::Mat(64, 64, CV_32FC1, cv::Scalar(0)));
  EXPECT_EQ(zeros.size(), 512u);
  for (float v : zeros) EXPECT_EQ(v, 0.0f);
  EXPECT_THROW(ComputeHog(cv::Mat(60, 60, CV_32FC1, cv::Scalar(0))), Error);  // 60 % 8 != 0
  EXPECT_THROW(ComputeHog(cv::Mat(64, 64, CV_8UC1, cv::Scalar(0))), Error);
  EXPECT_THROW(ComputeHog(cv::Mat(64, 64, CV_32FC1), {.cells = 8, .bins = 1}), Error);
  EXPECT_EQ(HogNormalizationFromString(ToString(HogNormalization::kCellSum)), HogNormalization::kCellSum);
}

}  // namespace
}  // namespace nphand
