#include "nphand/features/crop.h"

#include <gtest/gtest.h>

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
