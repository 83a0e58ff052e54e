#include "nphand/features/descriptor.h"

#include <cmath>
#include <numbers>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "nphand/util/check.h"
#include "testing/testing.h"

namespace nphand {
namespace {

// An asymmetric shape: a bar with a knob at one end.
cv::Mat KnobbedBar() {
  cv::Mat mask(120, 120, CV_8UC1, cv::Scalar(0));
  cv::rectangle(mask, cv::Rect(50, 20, 16, 70), cv::Scalar(255), cv::FILLED);
  cv::circle(mask, {58, 25}, 14, cv::Scalar(255), cv::FILLED);
  return mask;
}

TEST(DescriptorTest, IsTheHogOfTheCrop) {
  DescriptorConfig config;
  config.normalize_roll = false;
  const Descriptor descriptor = *Describe(KnobbedBar(), config);
  EXPECT_EQ(descriptor.values, ComputeHog(CropHand(KnobbedBar(), config.Crop())->image, config.hog));
  EXPECT_EQ(descriptor.values.size(), 512u);
  EXPECT_EQ(descriptor.roll, 0.0);
  EXPECT_FALSE(Describe(cv::Mat::zeros(40, 40, CV_8UC1), config).has_value()) << "no pixels: no hand";
}

TEST(DescriptorTest, RollNormalisedDescriptorIgnoresInPlaneTurnsAndReturnsThem) {
  const DescriptorConfig config;  // roll-normalised by default
  const Descriptor reference = *Describe(KnobbedBar(), config);
  for (double degrees : {30.0, -100.0}) {
    const double angle = degrees * std::numbers::pi / 180.0;
    const Descriptor turned = *Describe(RotateMask(KnobbedBar(), angle), config);
    double distance = 0.0;
    for (size_t i = 0; i < reference.values.size(); ++i) distance += std::pow(turned.values[i] - reference.values[i], 2);
    EXPECT_LT(std::sqrt(distance), 0.35) << degrees << ": unit-norm descriptors, nearly the same";
    EXPECT_NEAR(std::remainder(reference.roll - turned.roll - angle, 2 * std::numbers::pi), 0.0, 0.05) << degrees;
  }
}

TEST(DescriptorTest, ConfigRoundTripsThroughJsonAndBadJsonIsNamed) {
  DescriptorConfig config;
  config.crop_margin = 0.15;
  config.normalize_roll = false;
  config.hog.cells = 4;
  config.hog.pyramid = true;
  EXPECT_EQ(DescriptorConfigFromJson(ToJson(config), "x"), config);
  EXPECT_FALSE(DescriptorConfigFromJson(ToJson(DescriptorConfig()), "x") == config);
  EXPECT_NE(config.ToString().find("hog4x4x8_pyr"), std::string::npos) << config.ToString();
  nlohmann::json bad = ToJson(config);
  bad["hog"].erase("bins");
  testing::ExpectError([&] { DescriptorConfigFromJson(bad, "idx.bin"); }, "idx.bin: the descriptor config is missing");
  bad = ToJson(config);
  bad["hog"]["dimension"] = 512;
  testing::ExpectError([&] { DescriptorConfigFromJson(bad, "idx.bin"); }, "idx.bin: the descriptor's dimension 512");
  bad = ToJson(config);
  bad["crop_size"] = 30;
  testing::ExpectError([&] { DescriptorConfigFromJson(bad, "idx.bin"); }, "must divide the crop side");
}

}  // namespace
}  // namespace nphand
