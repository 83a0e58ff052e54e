#include "nphand/eval/plot.h"

#include <cmath>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "testing/testing.h"

namespace nphand {
namespace {

// Pixels of `colour` in the image.
int Count(const cv::Mat& image, const cv::Scalar& colour) {
  cv::Mat match;
  cv::inRange(image, colour, colour, match);
  return cv::countNonZero(match);
}

TEST(PlotTest, LinesAreDrawnInTheirColoursAndSkipWhatIsNotANumber) {
  const cv::Scalar second(220, 60, 30);  // the palette's second colour
  const cv::Mat one = PlotLines({{"a", {0, 1, 2}, {1, 2, 3}}}, "t", "x");
  ASSERT_EQ(one.type(), CV_8UC3);
  EXPECT_EQ(Count(one, second), 0);
  const cv::Mat two = PlotLines({{"a", {0, 1, 2}, {1, 2, 3}}, {"b", {0, 1, 2}, {3, NAN, 1}}}, "t", "x");
  EXPECT_GT(Count(two, second), 100) << "the second series and its legend";
  testing::ExpectError([] { PlotLines({{"a", {0, 1}, {1}}}, "t", "x"); }, "series 'a'");
}

TEST(PlotTest, BarsGrowWithTheirValues) {
  const cv::Scalar first(0, 0, 0), second(220, 60, 30);
  const cv::Mat low = PlotBars({"a", "b"}, {4.0, 1.0}, "t");
  const cv::Mat high = PlotBars({"a", "b"}, {4.0, 3.0}, "t");
  EXPECT_GT(Count(high, second), 2 * Count(low, second));
  EXPECT_GT(Count(low, first), 0);
  testing::ExpectError([] { PlotBars({"a"}, {1.0, 2.0}, "t"); }, "one name per value");
}

}  // namespace
}  // namespace nphand
