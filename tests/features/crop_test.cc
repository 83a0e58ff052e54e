#include "nphand/features/crop.h"

#include <cmath>
#include <numbers>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "nphand/util/check.h"

namespace nphand {
namespace {

TEST(CropTest, SquareAroundTheBoundingBoxWithMargin) {
  cv::Mat mask(100, 200, CV_8UC1, cv::Scalar(0));
  mask(cv::Rect(50, 20, 40, 20)).setTo(255);  // 40 wide, 20 tall
  const auto crop = CropHand(mask, {.size = 16, .margin = 0.25});
  ASSERT_TRUE(crop.has_value());
  EXPECT_EQ(crop->window, cv::Rect(40, 0, 60, 60));  // 40 * 1.5, centred on (70, 30)
  EXPECT_EQ(crop->image.size(), cv::Size(16, 16));
  EXPECT_EQ(crop->image.type(), CV_32FC1);
  // Resampling keeps the covered area, scaled to the crop.
  EXPECT_NEAR(cv::sum(crop->image)[0], 40.0 * 20.0 * (16.0 * 16.0) / (60.0 * 60.0), 1e-3);
  double low, high;
  cv::minMaxLoc(crop->image, &low, &high);
  EXPECT_GE(low, 0.0);
  EXPECT_LE(high, 1.0 + 1e-6);
}

TEST(CropTest, WindowPastTheImageIsPaddedWithBackground) {
  cv::Mat mask(50, 50, CV_8UC1, cv::Scalar(0));
  mask(cv::Rect(0, 0, 10, 30)).setTo(1);  // any non-zero value is hand
  const auto crop = CropHand(mask, {.size = 40, .margin = 0.5});
  ASSERT_TRUE(crop.has_value());
  EXPECT_LT(crop->window.x, 0);
  EXPECT_NEAR(cv::sum(crop->image)[0], 10.0 * 30.0 * (40.0 * 40.0) / (60.0 * 60.0), 1e-3);
}

TEST(CropTest, EmptyMaskIsNoHandAndWrongInputIsRefused) {
  EXPECT_FALSE(CropHand(cv::Mat(10, 10, CV_8UC1, cv::Scalar(0))).has_value());
  EXPECT_THROW(CropHand(cv::Mat(10, 10, CV_32FC1, cv::Scalar(1))), Error);
  EXPECT_THROW(CropHand(cv::Mat()), Error);
  cv::Mat mask(10, 10, CV_8UC1, cv::Scalar(255));
  EXPECT_THROW(CropHand(mask, {.size = 2, .margin = 0.1}), Error);
}

}  // namespace
}  // namespace nphand

namespace nphand {
namespace {

TEST(CropTest, RollNormalisationUndoesInPlaneRotation) {
  // An asymmetric shape: a bar with a knob at one end.
  cv::Mat mask(120, 120, CV_8UC1, cv::Scalar(0));
  cv::rectangle(mask, cv::Rect(50, 20, 16, 70), cv::Scalar(255), cv::FILLED);
  cv::circle(mask, {58, 25}, 14, cv::Scalar(255), cv::FILLED);
  const CropOptions options{.size = 32, .margin = 0.1, .normalize_roll = true};
  const HandCrop reference = *CropHand(mask, options);
  for (double degrees : {17.0, 90.0, 161.0, -120.0}) {
    const double angle = degrees * std::numbers::pi / 180.0;
    const HandCrop turned = *CropHand(RotateMask(mask, angle), options);
    // The same crop, up to resampling of the turned pixels.
    EXPECT_LT(cv::norm(turned.image, reference.image, cv::NORM_L1) / cv::sum(reference.image)[0], 0.15) << degrees;
    // The recovered turns differ by the applied one.
    EXPECT_NEAR(std::remainder(reference.roll - turned.roll - angle, 2 * std::numbers::pi), 0.0, 0.05) << degrees;
  }
}

}  // namespace
}  // namespace nphand
