#include "nphand/sequence/background.h"

#include <algorithm>
#include <array>
#include <cmath>

#include <opencv2/imgproc.hpp>

#include "nphand/util/check.h"
#include "nphand/util/random.h"

namespace nphand {
namespace {

constexpr std::array<const char*, 3> kKindNames = {"plain", "texture", "clutter"};

// A colour without skin chroma: hue in OpenCV's [45, 135] (yellow-green to blue) or a grey.
cv::Vec3f NonSkinColour(Random& random) {
  if (random.Uniform() < 0.25) {
    const float v = static_cast<float>(random.Uniform(30.0, 230.0));
    return {v, v, v};
  }
  cv::Mat hsv(1, 1, CV_8UC3, cv::Scalar(random.Uniform(45.0, 135.0), random.Uniform(40.0, 230.0),
                                       random.Uniform(40.0, 235.0)));
  cv::Mat bgr;
  cv::cvtColor(hsv, bgr, cv::COLOR_HSV2BGR);
  const cv::Vec3b c = bgr.at<cv::Vec3b>(0, 0);
  return {static_cast<float>(c[0]), static_cast<float>(c[1]), static_cast<float>(c[2])};
}

// Multi-scale value noise in [0, 1]: random grids, smoothly enlarged, summed by octave.
cv::Mat ValueNoise(cv::Size size, Random& random) {
  cv::Mat sum = cv::Mat::zeros(size, CV_32FC1);
  double amplitude = 1.0, total = 0.0;
  for (int cells = 3; cells <= 48; cells *= 2) {
    cv::Mat grid(cells, cells, CV_32FC1);
    for (int i = 0; i < cells * cells; ++i) grid.ptr<float>()[i] = static_cast<float>(random.Uniform());
    cv::Mat big;
    cv::resize(grid, big, size, 0, 0, cv::INTER_CUBIC);
    sum += amplitude * big;
    total += amplitude;
    amplitude *= 0.55;
  }
  sum /= total;
  double low = 0.0, high = 1.0;
  cv::minMaxLoc(sum, &low, &high);
  return (sum - low) / std::max(high - low, 1e-6);
}

cv::Mat Palette(const cv::Mat& noise, const std::array<cv::Vec3f, 3>& colours) {
  cv::Mat out(noise.size(), CV_8UC3);
  for (int y = 0; y < noise.rows; ++y) {
    for (int x = 0; x < noise.cols; ++x) {
      const float t = 2.0f * std::clamp(noise.at<float>(y, x), 0.0f, 1.0f);
      const int i = std::min(1, static_cast<int>(t));
      const float f = t - static_cast<float>(i);
      const cv::Vec3f c = (1.0f - f) * colours[i] + f * colours[i + 1];
      out.at<cv::Vec3b>(y, x) = cv::Vec3b(cv::saturate_cast<uchar>(c[0]), cv::saturate_cast<uchar>(c[1]),
                                          cv::saturate_cast<uchar>(c[2]));
    }
  }
  return out;
}

}  // namespace

std::string ToString(BackgroundKind kind) { return kKindNames[static_cast<int>(kind)]; }

BackgroundKind BackgroundKindFromString(const std::string& text) {
  for (size_t i = 0; i < kKindNames.size(); ++i) {
    if (text == kKindNames[i]) return static_cast<BackgroundKind>(i);
  }
  NPHAND_THROW("unknown background '", text, "' (choose plain, texture or clutter)");
}

std::vector<std::string> BackgroundKindNames() { return {kKindNames.begin(), kKindNames.end()}; }

cv::Mat MakeBackground(BackgroundKind kind, cv::Size size, uint64_t seed) {
  NPHAND_THROW_CHECK(size.width > 0 && size.height > 0 && size.width <= 16384 && size.height <= 16384,
                     "background: size ", size.width, "x", size.height, " is not a valid image size");
  Random random(seed);
  const std::array<cv::Vec3f, 3> colours = {NonSkinColour(random), NonSkinColour(random), NonSkinColour(random)};
  if (kind == BackgroundKind::kPlain) {
    // A wall: one colour, lit more on one side.
    cv::Mat out(size, CV_8UC3);
    const double angle = random.Uniform(0.0, 2.0 * 3.141592653589793);
    const double ax = std::cos(angle) / size.width, ay = std::sin(angle) / size.height;
    for (int y = 0; y < size.height; ++y) {
      for (int x = 0; x < size.width; ++x) {
        const float light = static_cast<float>(0.8 + 0.35 * (ax * (x - 0.5 * size.width) + ay * (y - 0.5 * size.height)));
        const cv::Vec3f c = light * colours[0];
        out.at<cv::Vec3b>(y, x) = cv::Vec3b(cv::saturate_cast<uchar>(c[0]), cv::saturate_cast<uchar>(c[1]),
                                            cv::saturate_cast<uchar>(c[2]));
      }
    }
    return out;
  }
  cv::Mat out = Palette(ValueNoise(size, random), colours);
  if (kind == BackgroundKind::kClutter) {
    const int shapes = 25 + static_cast<int>(random.UniformIndex(20));
    const int scale = std::min(size.width, size.height);
    for (int s = 0; s < shapes; ++s) {
      const cv::Vec3f c = NonSkinColour(random);
      const cv::Scalar colour(c[0], c[1], c[2]);
      const cv::Point p(static_cast<int>(random.UniformIndex(size.width)), static_cast<int>(random.UniformIndex(size.height)));
      const int extent = static_cast<int>(scale * random.Uniform(0.03, 0.25));
      switch (random.UniformIndex(3)) {
        case 0:
          cv::rectangle(out, cv::Rect(p.x, p.y, extent, static_cast<int>(extent * random.Uniform(0.3, 2.0))), colour,
                        cv::FILLED, cv::LINE_AA);
          break;
        case 1:
          cv::circle(out, p, extent / 2, colour, cv::FILLED, cv::LINE_AA);
          break;
        default:
          cv::line(out, p, p + cv::Point(extent, static_cast<int>(extent * random.Uniform(-1.0, 1.0))), colour,
                   1 + static_cast<int>(random.UniformIndex(6)), cv::LINE_AA);
      }
    }
  }
  return out;
}

void DrawFace(const cv::Vec3f& skin_bgr, cv::Point centre, int height, cv::Mat* bgr) {
  NPHAND_THROW_CHECK(bgr != nullptr && bgr->type() == CV_8UC3, "face: needs an 8-bit BGR image");
  NPHAND_THROW_CHECK(height >= 8, "face: height must be at least 8 pixels");
  const cv::Scalar skin(skin_bgr[0], skin_bgr[1], skin_bgr[2]);
  const cv::Scalar dark(0.35 * skin_bgr[0], 0.3 * skin_bgr[1], 0.3 * skin_bgr[2]);
  const int h = height / 2, w = height * 3 / 8;
  cv::ellipse(*bgr, centre, cv::Size(w, h), 0, 0, 360, skin, cv::FILLED, cv::LINE_AA);
  // Neck below the head.
  cv::rectangle(*bgr, cv::Rect(centre.x - w / 2, centre.y + h * 3 / 4, w, h), skin, cv::FILLED);
  for (int side = -1; side <= 1; side += 2) {
    const cv::Point eye(centre.x + side * w * 2 / 5, centre.y - h / 6);
    cv::ellipse(*bgr, eye, cv::Size(std::max(1, w / 6), std::max(1, h / 14)), 0, 0, 360, dark, cv::FILLED, cv::LINE_AA);
    cv::line(*bgr, eye + cv::Point(-w / 5, -h / 6), eye + cv::Point(w / 5, -h / 5), dark, std::max(1, h / 25), cv::LINE_AA);
  }
  cv::ellipse(*bgr, centre + cv::Point(0, h / 2), cv::Size(std::max(1, w / 3), std::max(1, h / 14)), 0, 0, 360, dark,
              cv::FILLED, cv::LINE_AA);
}

void DrawSweater(const cv::Vec3f& bgr_colour, cv::Point centre, int height, cv::Mat* bgr) {
  NPHAND_THROW_CHECK(bgr != nullptr && bgr->type() == CV_8UC3, "sweater: needs an 8-bit BGR image");
  NPHAND_THROW_CHECK(height >= 8, "sweater: height must be at least 8 pixels");
  const cv::Scalar wool(bgr_colour[0], bgr_colour[1], bgr_colour[2]);
  const cv::Scalar rib(0.85 * bgr_colour[0], 0.85 * bgr_colour[1], 0.85 * bgr_colour[2]);
  const int h = height / 2, w = height * 3 / 8;  // the head's half-height and half-width, as DrawFace's
  const int shoulders = centre.y + h * 3 / 2;
  const int half_width = w * 5 / 2;
  cv::ellipse(*bgr, cv::Point(centre.x, shoulders + h), cv::Size(half_width, h), 0, 180, 360, wool, cv::FILLED, cv::LINE_AA);
  const cv::Rect chest(centre.x - half_width, shoulders + h, 2 * half_width, std::max(0, bgr->rows - shoulders - h));
  cv::rectangle(*bgr, chest, wool, cv::FILLED);
  for (int x = chest.x + w / 4; x < chest.x + chest.width; x += std::max(2, w / 4)) {
    cv::line(*bgr, cv::Point(x, shoulders + h), cv::Point(x, bgr->rows - 1), rib, std::max(1, w / 16), cv::LINE_AA);
  }
}

}  // namespace nphand
