#include "nphand/features/distance.h"

#include <opencv2/imgproc.hpp>

#include "nphand/util/check.h"

namespace nphand {

cv::Mat EdgeMap(const cv::Mat& crop) {
  NPHAND_THROW_CHECK(crop.type() == CV_32FC1 && !crop.empty(), "edge map: the crop must be a CV_32FC1 image");
  const cv::Mat mask = crop >= 0.5f;
  cv::Mat eroded;
  // Outside the crop counts as background, so the mask's pixels on the border are contour.
  cv::erode(mask, eroded, cv::getStructuringElement(cv::MORPH_CROSS, cv::Size(3, 3)), cv::Point(-1, -1), 1,
            cv::BORDER_CONSTANT, cv::Scalar(0));
  return mask & ~eroded;
}

cv::Mat ContourDistance(const cv::Mat& edges) {
  NPHAND_THROW_CHECK(edges.type() == CV_8UC1 && edges.rows == edges.cols, "contour distance: edges must be a square CV_8UC1 image");
  if (cv::countNonZero(edges) == 0) return cv::Mat(edges.size(), CV_32FC1, cv::Scalar(1.0f));
  cv::Mat distance;
  cv::distanceTransform(edges == 0, distance, cv::DIST_L2, cv::DIST_MASK_PRECISE);
  return distance / static_cast<float>(edges.cols);
}

std::vector<float> DistanceTransformFeature(const cv::Mat& crop, int grid) {
  NPHAND_THROW_CHECK(grid > 0 && crop.cols % grid == 0, "distance feature: grid ", grid,
                     " must divide the crop side ", crop.cols);
  cv::Mat small;
  cv::resize(ContourDistance(EdgeMap(crop)), small, cv::Size(grid, grid), 0, 0, cv::INTER_AREA);
  return std::vector<float>(small.begin<float>(), small.end<float>());
}

double ChamferDistance(const cv::Mat& edges_a, const cv::Mat& distance_b) {
  NPHAND_THROW_CHECK(edges_a.size() == distance_b.size() && edges_a.type() == CV_8UC1 && distance_b.type() == CV_32FC1,
                     "chamfer distance: an edge map and a contour distance of the same size are needed");
  if (cv::countNonZero(edges_a) == 0) return 1.0;
  return cv::mean(distance_b, edges_a)[0];
}

}  // namespace nphand
