#include "nphand/features/crop.h"

#include <algorithm>
#include <cmath>

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

std::optional<HandCrop> CropHand(const cv::Mat& mask, const CropOptions& options) {
  std::string why;
  NPHAND_THROW_CHECK(options.Check(&why), "crop: ", why);
  NPHAND_THROW_CHECK(!mask.empty() && mask.type() == CV_8UC1, "crop: the hand mask must be a non-empty 8-bit single-channel image");
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
  cv::resize(square, crop.image, cv::Size(options.size, options.size), 0, 0,
             side >= options.size ? cv::INTER_AREA : cv::INTER_LINEAR);
  return crop;
}

}  // namespace nphand
