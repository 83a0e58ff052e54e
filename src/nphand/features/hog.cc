#include "nphand/features/hog.h"

#include <cmath>
#include <numbers>

#include "nphand/util/check.h"

namespace nphand {

std::string ToString(HogNormalization normalization) {
  return normalization == HogNormalization::kGlobalL2 ? "global_l2" : "cell_sum";
}

HogNormalization HogNormalizationFromString(const std::string& text) {
  if (text == "global_l2") return HogNormalization::kGlobalL2;
  if (text == "cell_sum") return HogNormalization::kCellSum;
  NPHAND_THROW("unknown HOG normalisation '", text, "' (choices: global_l2, cell_sum)");
}

bool HogOptions::Check(std::string* why) const {
  if (cells < 1 || cells > 64 || bins < 2 || bins > 64) {
    *why = "HOG needs 1 to 64 cells per side and 2 to 64 bins";
    return false;
  }
  return true;
}

int HogOptions::Dimension() const {
  int cell_count = cells * cells;
  if (pyramid) {
    for (int c = cells; c % 2 == 0; c /= 2) cell_count += (c / 2) * (c / 2);
  }
  return bins * cell_count;
}

std::string HogOptions::Name() const {
  std::string name = "hog" + std::to_string(cells) + "x" + std::to_string(cells) + "x" + std::to_string(bins);
  if (pyramid) name += "_pyr";
  if (normalization == HogNormalization::kCellSum) name += "_nh";
  if (signed_orientation) name += "_signed";
  return name;
}

std::vector<float> ComputeHog(const cv::Mat& crop, const HogOptions& options) {
  std::string why;
  NPHAND_THROW_CHECK(options.Check(&why), "hog: ", why);
  NPHAND_THROW_CHECK(crop.type() == CV_32FC1 && crop.rows == crop.cols && crop.rows % options.cells == 0,
                     "hog: the crop must be a square CV_32FC1 image whose side (", crop.cols,
                     ") is divisible by the cell count (", options.cells, ")");
  const int side = crop.rows, cells = options.cells, bins = options.bins;
  const int cell_side = side / cells;
  const double range = options.signed_orientation ? 2.0 * std::numbers::pi : std::numbers::pi;
  const double bins_per_radian = bins / range;

  // All levels in one vector: the finest first, then (pyramid) each coarser one.
  std::vector<double> all(static_cast<size_t>(options.Dimension()), 0.0);
  for (int y = 0; y < side; ++y) {
    const float* row = crop.ptr<float>(y);
    const float* up = crop.ptr<float>(std::max(0, y - 1));
    const float* down = crop.ptr<float>(std::min(side - 1, y + 1));
    for (int x = 0; x < side; ++x) {
      const double gx = row[std::min(side - 1, x + 1)] - row[std::max(0, x - 1)];
      const double gy = down[x] - up[x];
      if (gx == 0.0 && gy == 0.0) continue;  // most of a mask: inside or outside the hand
      const double magnitude = std::hypot(gx, gy);
      double angle = std::atan2(gy, gx);
      angle = std::fmod(angle + 2.0 * range, range);  // [0, range)
      const double position = angle * bins_per_radian;
      const int lower = static_cast<int>(std::floor(position)) % bins;
      const double upper_share = position - std::floor(position);
      double* cell = &all[(static_cast<size_t>(y / cell_side) * cells + x / cell_side) * bins];
      cell[lower] += magnitude * (1.0 - upper_share);
      cell[(lower + 1) % bins] += magnitude * upper_share;
    }
  }

  // Coarser levels: each cell the sum of the 2 x 2 cells below it.
  if (options.pyramid) {
    size_t fine = 0, coarse = static_cast<size_t>(cells) * cells * bins;
    for (int c = cells; c % 2 == 0; c /= 2) {
      for (int cy = 0; cy < c; ++cy) {
        for (int cx = 0; cx < c; ++cx) {
          for (int b = 0; b < bins; ++b) {
            all[coarse + ((cy / 2) * (c / 2) + cx / 2) * bins + b] += all[fine + (cy * c + cx) * bins + b];
          }
        }
      }
      fine = coarse;
      coarse += static_cast<size_t>(c / 2) * (c / 2) * bins;
    }
  }

  if (options.normalization == HogNormalization::kGlobalL2) {
    double norm = 0.0;
    for (double v : all) norm += v * v;
    norm = std::sqrt(norm);
    if (norm > 0.0) {
      for (double& v : all) v /= norm;
    }
  } else {
    for (size_t begin = 0; begin < all.size(); begin += bins) {
      double sum = 0.0;
      for (int b = 0; b < bins; ++b) sum += all[begin + b];
      if (sum > 0.0) {
        for (int b = 0; b < bins; ++b) all[begin + b] /= sum;
      }
    }
  }
  return std::vector<float>(all.begin(), all.end());
}

}  // namespace nphand
