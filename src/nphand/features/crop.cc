#include "nphand/features/crop.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <opencv2/imgproc.hpp>

#include "nphand/util/check.h"

namespace nphand {

bool CropOptions::Check(std::string* why) const {
  if (size < 4 || size > 1024) {
    *why = "crop size must be between 4 and 1024 pixels";
    return false;
  }
  if (!(margin >= 0.0 && margin <= 1.0)) {
    *why = "crop margin must be within [0, 1]";
    return false;
  }
  return true;
}

cv::Mat RotateMask(const cv::Mat& mask, double angle) {
  const int side = static_cast<int>(std::ceil(std::hypot(mask.cols, mask.rows))) + 2;
  cv::Mat transform = cv::getRotationMatrix2D(cv::Point2f(0.5f * mask.cols, 0.5f * mask.rows),
                                              angle * 180.0 / std::numbers::pi, 1.0);
  transform.at<double>(0, 2) += 0.5 * (side - mask.cols);
  transform.at<double>(1, 2) += 0.5 * (side - mask.rows);
  cv::Mat turned;
  cv::warpAffine(mask, turned, transform, cv::Size(side, side), cv::INTER_NEAREST, cv::BORDER_CONSTANT, cv::Scalar(0));
  return turned;
}

double PrincipalRoll(const cv::Mat& mask) {
  const cv::Moments m = cv::moments(mask != 0, true);
  if (m.m00 <= 0.0) return 0.0;
  // The major axis makes the angle `axis` with +x in image coordinates (y down), i.e. -axis
  // counter-clockwise as displayed; turning by pi/2 + axis makes it vertical.
  const double axis = 0.5 * std::atan2(2.0 * m.mu11, m.mu20 - m.mu02);
  double roll = std::numbers::pi / 2.0 + axis;
  // The turned image's "down" is u = (-sin roll, cos roll) in the original one; the third
  // central moment along u tells which end of the axis has the tail.
  const double ux = -std::sin(roll), uy = std::cos(roll);
  const double skew = m.mu30 * ux * ux * ux + 3.0 * m.mu21 * ux * ux * uy + 3.0 * m.mu12 * ux * uy * uy +
                      m.mu03 * uy * uy * uy;
  if (skew > 0.0) roll += std::numbers::pi;  // a tail towards the bottom: turn it over
  return std::remainder(roll, 2.0 * std::numbers::pi);
}

std::optional<HandCrop> CropHand(const cv::Mat& source, const CropOptions& options) {
  std::string why;
  NPHAND_THROW_CHECK(options.Check(&why), "crop: ", why);
  NPHAND_THROW_CHECK(!source.empty() && source.type() == CV_8UC1, "crop: the hand mask must be a non-empty 8-bit single-channel image");
  const double roll = options.normalize_roll ? PrincipalRoll(source) : 0.0;
  const cv::Mat mask = options.normalize_roll ? RotateMask(source, roll) : source;
  const cv::Rect box = cv::boundingRect(mask);
  if (box.area() == 0) return std::nullopt;

  const int longer = std::max(box.width, box.height);
  const int side = std::max(1, static_cast<int>(std::lround(longer * (1.0 + 2.0 * options.margin))));
  // Centre the square on the box; with integer corners the centre moves by at most half a pixel.
  const int x0 = box.x + (box.width - side) / 2;
  const int y0 = box.y + (box.height - side) / 2;
  const cv::Rect window(x0, y0, side, side);

  // Copy the window, with zeros where it extends past the image.
  cv::Mat square(side, side, CV_32FC1, cv::Scalar(0));
  const cv::Rect inside = window & cv::Rect(0, 0, mask.cols, mask.rows);
  cv::Mat binary;
  cv::Mat(mask(inside) != 0).convertTo(binary, CV_32FC1, 1.0 / 255.0);
  binary.copyTo(square(cv::Rect(inside.x - window.x, inside.y - window.y, inside.width, inside.height)));

  HandCrop crop;
  crop.window = window;
  crop.roll = roll;
  cv::resize(square, crop.image, cv::Size(options.size, options.size), 0, 0,
             side >= options.size ? cv::INTER_AREA : cv::INTER_LINEAR);
  return crop;
}

}  // namespace nphand
