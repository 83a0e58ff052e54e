#include "nphand/features/crop.h"

#include <algorithm>
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

TEST(CropTest, ElongationIsTheRatioOfThePrincipalAxes) {
  cv::Mat mask = cv::Mat::zeros(100, 100, CV_8UC1);
  EXPECT_DOUBLE_EQ(Elongation(mask), 1.0) << "empty";
  cv::rectangle(mask, cv::Rect(40, 10, 10, 80), cv::Scalar(255), cv::FILLED);
  EXPECT_NEAR(Elongation(mask), 8.0, 0.05);
  cv::Mat turned = RotateMask(mask, 0.6);
  EXPECT_NEAR(Elongation(turned), 8.0, 0.4) << "in any direction";
  cv::Mat coverage;
  mask.convertTo(coverage, CV_32F, 1.0 / 255.0);
  EXPECT_NEAR(Elongation(coverage), 8.0, 0.05) << "a crop's coverage";
  cv::Mat disk = cv::Mat::zeros(100, 100, CV_8UC1);
  cv::circle(disk, cv::Point(50, 50), 30, cv::Scalar(255), cv::FILLED);
  EXPECT_NEAR(Elongation(disk), 1.0, 0.02);
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

TEST(CropTest, CropFromImageMapsSourcePixelsOntoTheCrop) {
  cv::Mat mask(150, 200, CV_8UC1, cv::Scalar(0));
  cv::rectangle(mask, cv::Rect(60, 30, 20, 90), cv::Scalar(255), cv::FILLED);
  cv::circle(mask, {70, 35}, 18, cv::Scalar(255), cv::FILLED);
  // Marked source points: the knob's centre and the bar's far end.
  const std::vector<cv::Point2d> marks = {{70, 35}, {70, 115}};
  for (double degrees : {0.0, 35.0, -100.0}) {
    const cv::Mat turned = RotateMask(mask, degrees * std::numbers::pi / 180.0);
    for (bool normalize : {false, true}) {
      const CropOptions options{.size = 64, .margin = 0.1, .normalize_roll = normalize};
      const HandCrop crop = *CropHand(turned, options);
      // The turned mask's marks, found by turning them as RotateMask turns pixels.
      const cv::Mat turn = cv::getRotationMatrix2D(cv::Point2f(100, 75), degrees, 1.0);
      const int side = turned.cols;
      for (const cv::Point2d& p : marks) {
        const cv::Point2d q(turn.at<double>(0, 0) * p.x + turn.at<double>(0, 1) * p.y + turn.at<double>(0, 2) + 0.5 * (side - 200),
                            turn.at<double>(1, 0) * p.x + turn.at<double>(1, 1) * p.y + turn.at<double>(1, 2) + 0.5 * (side - 150));
        const cv::Matx23d& a = crop.crop_from_image;
        const cv::Point2d c(a(0, 0) * q.x + a(0, 1) * q.y + a(0, 2), a(1, 0) * q.x + a(1, 1) * q.y + a(1, 2));
        ASSERT_GE(c.x, 0);
        ASSERT_GE(c.y, 0);
        ASSERT_LT(c.x, 64);
        ASSERT_LT(c.y, 64);
        EXPECT_GT(crop.image.at<float>(static_cast<int>(c.y), static_cast<int>(c.x)), 0.5f) << degrees << " " << normalize;
      }
      if (normalize) {
        const cv::Matx23d& a = crop.crop_from_image;
        EXPECT_GT(crop.roll_skewness, 0.1);
        const cv::Mat before = crop.image.clone();
        const HandCrop half = HalfTurn(crop);
        EXPECT_EQ(cv::norm(before, crop.image, cv::NORM_INF), 0.0);
        EXPECT_NEAR(std::abs(std::remainder(half.roll - crop.roll, 2 * std::numbers::pi)), std::numbers::pi, 1e-9);
        EXPECT_NEAR(half.image.at<float>(63 - 10, 63 - 32), crop.image.at<float>(10, 32), 1e-6f);
        EXPECT_NEAR(half.crop_from_image(0, 2) + a(0, 2), 63.0, 1e-9);
      }
    }
  }
  // A disc's ends look alike.
  cv::Mat disc(100, 100, CV_8UC1, cv::Scalar(0));
  cv::circle(disc, {50, 50}, 30, cv::Scalar(255), cv::FILLED);
  EXPECT_LT(CropHand(disc, {64, 0.1, true})->roll_skewness, 0.02);
}

TEST(CropTest, ATiltedCropTurnsItsImageItsRollAndItsMapTogether) {
  cv::Mat mask(150, 200, CV_8UC1, cv::Scalar(0));
  cv::rectangle(mask, cv::Rect(60, 30, 20, 90), cv::Scalar(255), cv::FILLED);
  cv::circle(mask, {70, 35}, 18, cv::Scalar(255), cv::FILLED);
  const HandCrop crop = *CropHand(mask, {.size = 64, .margin = 0.1, .normalize_roll = true});
  // The knob's centre and the bar's far end lie on the shape; beside the bar, off it.
  const std::vector<cv::Point2d> on = {{70, 35}, {70, 115}}, off = {{95, 110}, {45, 110}};
  const auto at = [](const HandCrop& c, const cv::Point2d& p) {
    const cv::Matx23d& a = c.crop_from_image;
    const cv::Point2d q(a(0, 0) * p.x + a(0, 1) * p.y + a(0, 2), a(1, 0) * p.x + a(1, 1) * p.y + a(1, 2));
    EXPECT_TRUE(q.x >= 0 && q.y >= 0 && q.x < c.image.cols && q.y < c.image.rows) << q;
    return c.image.at<float>(std::clamp(static_cast<int>(std::lround(q.y)), 0, c.image.rows - 1),
                             std::clamp(static_cast<int>(std::lround(q.x)), 0, c.image.cols - 1));
  };
  for (double degrees : {15.0, -30.0, 90.0}) {
    const HandCrop tilted = TiltCrop(crop, degrees * std::numbers::pi / 180.0);
    EXPECT_NEAR(std::remainder(tilted.roll - crop.roll - degrees * std::numbers::pi / 180.0, 2 * std::numbers::pi), 0.0, 1e-9);
    EXPECT_EQ(tilted.roll_skewness, crop.roll_skewness);
    for (const cv::Point2d& p : on) EXPECT_GT(at(tilted, p), 0.5f) << degrees;
    for (const cv::Point2d& p : off) EXPECT_LT(at(tilted, p), 0.5f) << degrees;
    // The shape stays within the square (the crop's margin holds it at these turns).
    EXPECT_NEAR(cv::sum(tilted.image)[0], cv::sum(crop.image)[0], 0.03 * cv::sum(crop.image)[0]) << degrees;
    // Turned back, the middle of the square is the crop's again (but for two bilinear
    // resamplings of its edges).
    const HandCrop back = TiltCrop(tilted, -degrees * std::numbers::pi / 180.0);
    const cv::Rect middle(16, 16, 32, 32);
    EXPECT_LT(cv::norm(back.image(middle), crop.image(middle), cv::NORM_L1) / cv::sum(crop.image(middle))[0], 0.1) << degrees;
    for (int r = 0; r < 2; ++r) {
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(back.crop_from_image(r, c), crop.crop_from_image(r, c), 1e-9);
    }
  }
  // A tilt leaves the crop it was made from as it was.
  const cv::Mat before = crop.image.clone();
  const HandCrop tilted = TiltCrop(crop, 0.3);
  EXPECT_EQ(cv::norm(before, crop.image, cv::NORM_INF), 0.0);
  EXPECT_NE(tilted.image.data, crop.image.data);
}

}  // namespace
}  // namespace nphand
