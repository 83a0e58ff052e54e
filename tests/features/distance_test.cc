#include "nphand/features/distance.h"

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "nphand/util/check.h"

namespace nphand {
namespace {

cv::Mat Square(int side, cv::Rect box) {
  cv::Mat crop(side, side, CV_32FC1, cv::Scalar(0));
  crop(box).setTo(1.0f);
  return crop;
}

TEST(DistanceTest, EdgeMapIsTheMaskOutline) {
  const cv::Mat edges = EdgeMap(Square(16, {4, 4, 6, 6}));
  EXPECT_EQ(cv::countNonZero(edges), 4 * 6 - 4);  // the ring of a 6 x 6 square
  EXPECT_EQ(edges.at<uint8_t>(4, 4), 255);
  EXPECT_EQ(edges.at<uint8_t>(6, 6), 0);
  // Mask pixels on the crop's border are contour too.
  EXPECT_EQ(cv::countNonZero(EdgeMap(Square(8, {0, 0, 8, 8}))), 28);
}

TEST(DistanceTest, ContourDistanceIsInCropSides) {
  const cv::Mat distance = ContourDistance(EdgeMap(Square(16, {4, 4, 6, 6})));
  EXPECT_FLOAT_EQ(distance.at<float>(4, 4), 0.0f);
  EXPECT_NEAR(distance.at<float>(4, 0), 4.0f / 16.0f, 1e-4f);
  const cv::Mat empty = ContourDistance(cv::Mat(8, 8, CV_8UC1, cv::Scalar(0)));
  EXPECT_EQ(cv::countNonZero(empty != 1.0f), 0);
}

TEST(DistanceTest, ChamferIsZeroForTheSameShapeAndGrowsWithShift) {
  const cv::Mat a = Square(32, {8, 8, 10, 10});
  const cv::Mat edges = EdgeMap(a);
  EXPECT_DOUBLE_EQ(ChamferDistance(edges, ContourDistance(edges)), 0.0);
  const cv::Mat shifted = EdgeMap(Square(32, {11, 8, 10, 10}));
  const double d = ChamferDistance(edges, ContourDistance(shifted));
  EXPECT_GT(d, 0.0);
  EXPECT_LE(d, 3.0 / 32.0 + 1e-6);  // no edge point is further than the shift
  EXPECT_DOUBLE_EQ(ChamferDistance(cv::Mat(32, 32, CV_8UC1, cv::Scalar(0)), ContourDistance(edges)), 1.0);
}

TEST(DistanceTest, DistanceFeatureIsAGridOfMeans) {
  const std::vector<float> feature = DistanceTransformFeature(Square(64, {10, 20, 30, 20}));
  EXPECT_EQ(feature.size(), 32u * 32u);
  EXPECT_THROW(DistanceTransformFeature(Square(60, {1, 1, 5, 5}), 32), Error);
}

}  // namespace
}  // namespace nphand
