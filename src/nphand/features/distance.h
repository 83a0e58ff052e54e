// Contour features of a hand crop, the paper's alternatives to HOG (Sec. 4.1): the edge
// map (for chamfer distance) and its distance transform subsampled to a small grid.
#pragma once

#include <vector>

#include <opencv2/core.hpp>

namespace nphand {

// The hand's contour in a crop (CV_32FC1 coverage): pixels of the mask (coverage >= 0.5)
// with a 4-neighbour outside it, or on the crop's border. CV_8UC1, 255 on the contour.
cv::Mat EdgeMap(const cv::Mat& crop);

// Each pixel's Euclidean distance to the nearest contour pixel, divided by the crop's side
// (CV_32FC1). Pixels of a crop without contour are all 1.
cv::Mat ContourDistance(const cv::Mat& edges);

// The paper's "dist" feature: ContourDistance of the crop, area-averaged to grid x grid
// (grid must divide the crop's side), row-major.
std::vector<float> DistanceTransformFeature(const cv::Mat& crop, int grid = 32);

// The mean, over the contour pixels of `edges_a`, of the distance to the nearest contour
// pixel of the other crop (its ContourDistance, `distance_b`), in crop sides; 1 when
// `edges_a` is empty. Directed: average it both ways for a symmetric distance.
double ChamferDistance(const cv::Mat& edges_a, const cv::Mat& distance_b);

}  // namespace nphand
