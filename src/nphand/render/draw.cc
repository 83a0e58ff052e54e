#include "nphand/render/draw.h"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "nphand/util/check.h"
#include "nphand/util/io.h"

namespace nphand {

void DrawKeypoints(const Intrinsics& intrinsics, const Keypoints3d& keypoints, cv::Mat* bgr) {
  std::array<Eigen::Vector2d, kNumKeypoints> pixels;
  for (int k = 0; k < kNumKeypoints; ++k) pixels[k] = Project(intrinsics, keypoints[k]);
  DrawKeypoints2d(pixels, bgr);
}

void DrawKeypoints2d(const std::array<Eigen::Vector2d, kNumKeypoints>& keypoints, cv::Mat* bgr) {
  NPHAND_THROW_CHECK(bgr->type() == CV_8UC3, "keypoints can only be drawn on a BGR image");
  const int radius = std::max(2, bgr->cols / 160);
  auto pixel = [&](int k) {
    return cv::Point(static_cast<int>(std::lround(keypoints[k].x() - 0.5)), static_cast<int>(std::lround(keypoints[k].y() - 0.5)));
  };
  // One colour per finger (BGR): thumb, index, middle, ring, little.
  const cv::Scalar colours[5] = {{0, 0, 255}, {0, 200, 255}, {0, 220, 0}, {255, 160, 0}, {255, 0, 200}};
  for (int k = 1; k < kNumKeypoints; ++k) {
    cv::line(*bgr, pixel(KeypointParent(k)), pixel(k), colours[(k - 1) / 4], std::max(1, radius / 2), cv::LINE_AA);
  }
  for (int k = 0; k < kNumKeypoints; ++k) {
    const cv::Scalar colour = k == 0 ? cv::Scalar(255, 255, 255) : colours[(k - 1) / 4];
    cv::circle(*bgr, pixel(k), radius, colour, cv::FILLED, cv::LINE_AA);
  }
}

cv::Mat FitInto(const cv::Mat& image, cv::Size size, cv::Scalar border, double* scale, cv::Point* offset) {
  const double s = std::min(static_cast<double>(size.width) / image.cols, static_cast<double>(size.height) / image.rows);
  const cv::Size fitted(std::max(1, static_cast<int>(image.cols * s)), std::max(1, static_cast<int>(image.rows * s)));
  const cv::Point corner((size.width - fitted.width) / 2, (size.height - fitted.height) / 2);
  if (scale != nullptr) *scale = s;
  if (offset != nullptr) *offset = corner;
  if (image.size() == size) return image;
  cv::Mat out(size, CV_8UC3, border);
  cv::resize(image, out(cv::Rect(corner, fitted)), fitted, 0, 0, cv::INTER_AREA);
  return out;
}

cv::Mat LabelsForDisplay(const cv::Mat& labels) {
  cv::Mat lut(1, 256, CV_8UC1, cv::Scalar(128));
  lut.at<uchar>(0) = 0;
  lut.at<uchar>(1) = 255;
  cv::Mat display;
  cv::LUT(labels, lut, display);
  return display;
}

void WriteImageAtomic(const std::filesystem::path& path, const cv::Mat& image) {
  std::vector<uchar> bytes;
  bool encoded = false;
  try {
    encoded = cv::imencode(path.extension().string(), image, bytes);
  } catch (const cv::Exception& e) {
    NPHAND_THROW(path.string(), ": cannot encode the image (", e.what(), ")");
  }
  NPHAND_THROW_CHECK(encoded, path.string(), ": cannot encode the image as ", path.extension().string());
  WriteFileAtomic(path, bytes);
}

}  // namespace nphand
