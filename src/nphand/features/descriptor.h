// The descriptor nphand searches with: one function from a hand mask to the vector that the
// database stores and that queries are compared against. The builder, the feature study
// and the estimator all call Describe with the config the database file records, so a query
// described differently from its database cannot happen by construction; an index refuses
// descriptors whose config differs from its own, naming both.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "nphand/features/crop.h"
#include "nphand/features/hog.h"

namespace nphand {

struct DescriptorConfig {
  int crop_size = 64;          // side of the resampled crop, pixels (CropOptions::size)
  double crop_margin = 0.1;    // CropOptions::margin
  // Turn each mask by its principal axis before describing it (CropOptions::normalize_roll),
  // so that a hand turned in the image plane finds its pose; the turn comes back in
  // Descriptor::roll. docs/feature_study.md measures why this is the default.
  bool normalize_roll = true;
  HogOptions hog;              // 8 x 8 cells x 8 bins: 512 values

  bool Check(std::string* why) const;
  int Dimension() const { return hog.Dimension(); }
  CropOptions Crop() const { return {crop_size, crop_margin, normalize_roll}; }
  // "hog8x8x8, crop 64 px + 0.1 margin, roll-normalised": for messages.
  std::string ToString() const;
  bool operator==(const DescriptorConfig& other) const;
};

// The config as JSON, and back; FromJson throws nphand::Error naming `source` and the field
// when one is missing or out of range.
nlohmann::json ToJson(const DescriptorConfig& config);
DescriptorConfig DescriptorConfigFromJson(const nlohmann::json& json, const std::string& source);

struct Descriptor {
  std::vector<float> values;  // config.Dimension() values
  double roll = 0.0;          // radians the mask was turned before it was described
};

// The descriptor of the non-zero pixels of `mask` (CV_8UC1); std::nullopt when it has none
// ("no hand"). Throws nphand::Error for an invalid config or mask.
std::optional<Descriptor> Describe(const cv::Mat& mask, const DescriptorConfig& config);

}  // namespace nphand
