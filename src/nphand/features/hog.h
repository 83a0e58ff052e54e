// Histograms of oriented gradients of a hand crop, as in the paper (Sec. 4, Fig. 3): the
// crop is divided into cells x cells non-overlapping cells, and each cell holds a histogram
// of its pixels' gradient orientations in `bins` bins, weighted by gradient magnitude.
//
// Exact definition (tests check it on tiny images):
//  - gradients by central differences, gx = I(x+1, y) - I(x-1, y), gy = I(x, y+1) - I(x, y-1),
//    with the border replicated;
//  - orientation atan2(gy, gx), folded into [0, pi) unless signed; bin k is centred on
//    k * range / bins, and a pixel votes its magnitude into the two nearest bins, linearly
//    (wrapping around);
//  - pyramid: the levels cells, cells/2, ... down to 1 (while divisible), each cell the sum
//    of the four below it, appended after the finest level;
//  - normalisation: the whole descriptor to unit L2 norm, or (the paper's "normalised
//    holes") each cell's histogram to sum 1, which discards how much edge a cell holds.
//    An all-zero descriptor stays zero.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace nphand {

enum class HogNormalization : uint8_t { kGlobalL2, kCellSum };
std::string ToString(HogNormalization normalization);
HogNormalization HogNormalizationFromString(const std::string& text);

struct HogOptions {
  int cells = 8;                 // cells per side
  int bins = 8;                  // orientation bins per cell
  bool pyramid = false;          // append the coarser cell levels
  bool signed_orientation = false;  // bins over [0, 2 pi) instead of [0, pi)
  HogNormalization normalization = HogNormalization::kGlobalL2;

  bool Check(std::string* why) const;
  // The descriptor's length: bins * (cells^2 [+ (cells/2)^2 + ... + 1]).
  int Dimension() const;
  // A short name: "hog8x8x8", "hog8x8x8_pyr", "hog8x8x8_nh", "hog8x8x8_signed".
  std::string Name() const;
};

// The HOG of `crop` (CV_32FC1, square, side divisible by options.cells). Throws
// nphand::Error otherwise.
std::vector<float> ComputeHog(const cv::Mat& crop, const HogOptions& options = {});

}  // namespace nphand
