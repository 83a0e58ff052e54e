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

namespace {

// The turn of RotateMask: source pixel to the turned canvas, and the canvas's side.
cv::Mat TurnTransform(const cv::Mat& mask, double angle, int* side) {
  *side = static_cast<int>(std::ceil(std::hypot(mask.cols, mask.rows))) + 2;
  cv::Mat transform = cv::getRotationMatrix2D(cv::Point2f(0.5f * mask.cols, 0.5f * mask.rows),
                                              angle * 180.0 / std::numbers::pi, 1.0);
  transform.at<double>(0, 2) += 0.5 * (*side - mask.cols);
  transform.at<double>(1, 2) += 0.5 * (*side - mask.rows);
  return transform;
}

// The mask's pixels turned counter-clockwise by `angle` about the pixel at the centre of
// their bounding box, onto a canvas just large enough, with `turn` the source-to-canvas map.
// Everything depends on the pixels alone, not on where they sit in the image: a mask moved
// by whole pixels turns into the same canvas, bit for bit (resampling about another centre
// would change the boundary pixels and with them the descriptor).
cv::Mat TurnAboutBox(const cv::Mat& mask, double angle, cv::Matx23d* turn) {
  const cv::Rect box = cv::boundingRect(mask);
  if (box.area() == 0) return cv::Mat::zeros(1, 1, CV_8UC1);
  const cv::Point2f centre(static_cast<float>(box.x + box.width / 2), static_cast<float>(box.y + box.height / 2));
  cv::Mat transform = cv::getRotationMatrix2D(centre, angle * 180.0 / std::numbers::pi, 1.0);
  // Where the box's corners go; the canvas starts a pixel before the lowest.
  double low_x = 1e300, low_y = 1e300, high_x = -1e300, high_y = -1e300;
  for (const cv::Point2d corner : {cv::Point2d(box.x - 1, box.y - 1), cv::Point2d(box.x + box.width, box.y - 1),
                                   cv::Point2d(box.x - 1, box.y + box.height),
                                   cv::Point2d(box.x + box.width, box.y + box.height)}) {
    const double x = transform.at<double>(0, 0) * corner.x + transform.at<double>(0, 1) * corner.y + transform.at<double>(0, 2);
    const double y = transform.at<double>(1, 0) * corner.x + transform.at<double>(1, 1) * corner.y + transform.at<double>(1, 2);
    low_x = std::min(low_x, x);
    low_y = std::min(low_y, y);
    high_x = std::max(high_x, x);
    high_y = std::max(high_y, y);
  }
  transform.at<double>(0, 2) -= std::floor(low_x);
  transform.at<double>(1, 2) -= std::floor(low_y);
  const cv::Size canvas(static_cast<int>(std::ceil(high_x) - std::floor(low_x)) + 2,
                        static_cast<int>(std::ceil(high_y) - std::floor(low_y)) + 2);
  for (int r = 0; r < 2; ++r) {
    for (int c = 0; c < 3; ++c) (*turn)(r, c) = transform.at<double>(r, c);
  }
  // Bilinear, then cut at half: the turned outline is the true one's to within half a pixel,
  // where nearest-neighbour sampling makes steps.
  cv::Mat turned;
  cv::warpAffine(mask != 0, turned, transform, canvas, cv::INTER_LINEAR, cv::BORDER_CONSTANT, cv::Scalar(0));
  return turned >= 128;
}

}  // namespace

cv::Mat RotateMask(const cv::Mat& mask, double angle) {
  int side = 0;
  const cv::Mat transform = TurnTransform(mask, angle, &side);
  cv::Mat turned;
  cv::warpAffine(mask, turned, transform, cv::Size(side, side), cv::INTER_NEAREST, cv::BORDER_CONSTANT, cv::Scalar(0));
  return turned;
}

double Elongation(const cv::Mat& coverage) {
  const cv::Moments m = coverage.type() == CV_8UC1 ? cv::moments(coverage, true) : cv::moments(coverage);
  if (m.m00 <= 0.0) return 1.0;
  const double a = m.mu20 / m.m00, b = m.mu02 / m.m00, c = m.mu11 / m.m00;
  const double spread = std::sqrt(0.25 * (a - b) * (a - b) + c * c);
  return std::sqrt((0.5 * (a + b) + spread) / std::max(0.5 * (a + b) - spread, 1e-12));
}

double PrincipalRoll(const cv::Mat& mask, double* skewness) {
  if (skewness != nullptr) *skewness = 0.0;
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
  if (skewness != nullptr) {
    const double variance = m.mu20 * ux * ux + 2.0 * m.mu11 * ux * uy + m.mu02 * uy * uy;
    *skewness = variance > 0.0 ? std::abs(skew) * std::sqrt(m.m00) / std::pow(variance, 1.5) : 0.0;
  }
  if (skew > 0.0) roll += std::numbers::pi;  // a tail towards the bottom: turn it over
  return std::remainder(roll, 2.0 * std::numbers::pi);
}

std::optional<HandCrop> CropHand(const cv::Mat& source, const CropOptions& options) {
  std::string why;
  NPHAND_THROW_CHECK(options.Check(&why), "crop: ", why);
  NPHAND_THROW_CHECK(!source.empty() && source.type() == CV_8UC1, "crop: the hand mask must be a non-empty 8-bit single-channel image");
  double skewness = 0.0;
  const double roll = options.normalize_roll ? PrincipalRoll(source, &skewness) : 0.0;
  cv::Matx23d turn(1, 0, 0, 0, 1, 0);
  const cv::Mat mask = options.normalize_roll ? TurnAboutBox(source, roll, &turn) : source;
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
  crop.roll_skewness = skewness;
  // Resampling maps window pixel centres (i + 0.5) * size / side - 0.5.
  const double scale = static_cast<double>(options.size) / side;
  for (int r = 0; r < 2; ++r) {
    for (int c = 0; c < 3; ++c) crop.crop_from_image(r, c) = scale * turn(r, c);
  }
  crop.crop_from_image(0, 2) += scale * (0.5 - window.x) - 0.5;
  crop.crop_from_image(1, 2) += scale * (0.5 - window.y) - 0.5;
  cv::resize(square, crop.image, cv::Size(options.size, options.size), 0, 0,
             side >= options.size ? cv::INTER_AREA : cv::INTER_LINEAR);
  return crop;
}

HandCrop HalfTurn(const HandCrop& crop) {
  HandCrop turned = crop;
  turned.image = cv::Mat();  // the copy shares the pixels; the flip must not write into them
  cv::flip(crop.image, turned.image, -1);
  turned.roll = std::remainder(crop.roll + std::numbers::pi, 2.0 * std::numbers::pi);
  const double last = crop.image.cols - 1.0;
  for (int c = 0; c < 3; ++c) {
    turned.crop_from_image(0, c) = -crop.crop_from_image(0, c);
    turned.crop_from_image(1, c) = -crop.crop_from_image(1, c);
  }
  turned.crop_from_image(0, 2) += last;
  turned.crop_from_image(1, 2) += last;
  return turned;
}

cv::Matx23d Compose(const cv::Matx23d& a, const cv::Matx23d& b) {
  const cv::Matx33d a3(a(0, 0), a(0, 1), a(0, 2), a(1, 0), a(1, 1), a(1, 2), 0, 0, 1);
  const cv::Matx33d b3(b(0, 0), b(0, 1), b(0, 2), b(1, 0), b(1, 1), b(1, 2), 0, 0, 1);
  const cv::Matx33d c = a3 * b3;
  return cv::Matx23d(c(0, 0), c(0, 1), c(0, 2), c(1, 0), c(1, 1), c(1, 2));
}

HandCrop TiltCrop(const HandCrop& crop, double angle) {
  HandCrop tilted = crop;
  const double centre = (crop.image.cols - 1) / 2.0;
  // OpenCV's positive angle turns counter-clockwise as displayed (y down).
  const cv::Mat turn = cv::getRotationMatrix2D(cv::Point2d(centre, centre), angle * 180.0 / std::numbers::pi, 1.0);
  tilted.image = cv::Mat();
  cv::warpAffine(crop.image, tilted.image, turn, crop.image.size(), cv::INTER_LINEAR, cv::BORDER_CONSTANT, cv::Scalar(0));
  tilted.roll = std::remainder(crop.roll + angle, 2.0 * std::numbers::pi);
  tilted.crop_from_image = Compose(cv::Matx23d(turn), crop.crop_from_image);
  return tilted;
}

}  // namespace nphand
