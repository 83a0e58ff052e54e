#include "nphand/segment/regions.h"

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "testing/testing.h"

namespace nphand {
namespace {

// Masks of blobs, specks, rings (a region around a hole and one inside it), lines one
// pixel wide, regions touching every edge; odd widths (runs crossing the eight-pixel steps)
// and a mask that is a view into a larger image.
std::vector<cv::Mat> Masks() {
  std::vector<cv::Mat> masks;
  cv::RNG rng(testing::kTestSeed);
  for (const cv::Size size : {cv::Size(320, 240), cv::Size(37, 23), cv::Size(1, 9), cv::Size(9, 1)}) {
    cv::Mat m = cv::Mat::zeros(size, CV_8UC1);
    for (int i = 0; i < 60; ++i) {
      const cv::Point at(rng.uniform(0, size.width), rng.uniform(0, size.height));
      switch (i % 4) {
        case 0: cv::circle(m, at, rng.uniform(1, 20), cv::Scalar(255), cv::FILLED); break;
        case 1: cv::circle(m, at, rng.uniform(3, 30), cv::Scalar(200), 2); break;
        case 2: cv::line(m, at, cv::Point(rng.uniform(0, size.width), rng.uniform(0, size.height)), cv::Scalar(1), 1); break;
        default: m.at<uint8_t>(at) = 7; break;
      }
    }
    masks.push_back(m);
  }
  cv::Mat full = cv::Mat::ones(50, 60, CV_8UC1);
  masks.push_back(full);
  masks.push_back(cv::Mat::zeros(5, 5, CV_8UC1));
  cv::Mat large = masks[0].clone();
  masks.push_back(large(cv::Rect(13, 7, 203, 151)));
  return masks;
}

TEST(RegionsTest, LabelsAndStatisticsAreOpenCVsOwn) {
  for (const cv::Mat& mask : Masks()) {
    for (int connectivity : {8, 4}) {
      cv::Mat expected_labels, stats, centroids;
      const int count = cv::connectedComponentsWithStats(mask, expected_labels, stats, centroids, connectivity, CV_32S);
      cv::Mat labels;
      const std::vector<RegionStats> found = LabelRegions(mask, &labels, connectivity);
      ASSERT_EQ(static_cast<int>(found.size()), count) << mask.size() << " connectivity " << connectivity;
      EXPECT_EQ(cv::countNonZero(labels != expected_labels), 0);
      for (int l = 1; l < count; ++l) {
        EXPECT_EQ(found[l].area, stats.at<int>(l, cv::CC_STAT_AREA));
        EXPECT_EQ(found[l].box, cv::Rect(stats.at<int>(l, cv::CC_STAT_LEFT), stats.at<int>(l, cv::CC_STAT_TOP),
                                         stats.at<int>(l, cv::CC_STAT_WIDTH), stats.at<int>(l, cv::CC_STAT_HEIGHT)));
        EXPECT_EQ(found[l].centroid.x, centroids.at<double>(l, 0));
        EXPECT_EQ(found[l].centroid.y, centroids.at<double>(l, 1));
        // The first pixel: in the box's top row, the region's own, and no earlier one of it.
        const cv::Point first = found[l].first;
        EXPECT_EQ(first.y, found[l].box.y);
        EXPECT_EQ(labels.at<int>(first), l);
        for (int x = 0; x < first.x; ++x) EXPECT_NE(labels.at<int>(first.y, x), l);
      }
    }
  }
}

TEST(RegionsTest, RunsAreTheRowsNonZeroStretches) {
  cv::Mat mask = cv::Mat::zeros(3, 20, CV_8UC1);
  mask(cv::Rect(0, 0, 2, 1)).setTo(1);
  mask(cv::Rect(9, 0, 11, 1)).setTo(255);  // across the eight-pixel steps, to the edge
  mask.at<uint8_t>(2, 8) = 3;
  const std::vector<MaskRun> runs = Runs(mask);
  ASSERT_EQ(runs.size(), 3u);
  EXPECT_EQ((std::vector<int>{runs[0].y, runs[0].x0, runs[0].x1}), (std::vector<int>{0, 0, 1}));
  EXPECT_EQ((std::vector<int>{runs[1].y, runs[1].x0, runs[1].x1}), (std::vector<int>{0, 9, 19}));
  EXPECT_EQ((std::vector<int>{runs[2].y, runs[2].x0, runs[2].x1}), (std::vector<int>{2, 8, 8}));
}

TEST(RegionsTest, BadMasksAreRefused) {
  cv::Mat labels;
  testing::ExpectError([&] { LabelRegions(cv::Mat(), &labels); }, "8-bit single-channel");
  testing::ExpectError([&] { LabelRegions(cv::Mat(4, 4, CV_32FC1), &labels); }, "8-bit single-channel");
  testing::ExpectError([&] { LabelRegions(cv::Mat::zeros(4, 4, CV_8UC1), &labels, 6); }, "connectivity must be 4 or 8");
  testing::ExpectError([&] { Runs(cv::Mat(4, 4, CV_8UC3)); }, "8-bit single-channel");
}

}  // namespace
}  // namespace nphand
