// The descriptor nphand searches with: one function from a hand mask to the vector that the
// database stores and that queries are compared against. The builder, the feature study
// and the estimator all call Describe with the config the database file records, so a query
// described differently from its database cannot happen by construction; an index refuses
// descriptors whose config differs from its own, naming both.
#pragma once

#include <optional>
#include <span>
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
  DescriptorConfig config;    // how it was computed
  std::vector<float> values;  // config.Dimension() values
  double roll = 0.0;          // radians the mask was turned before it was described
  double roll_skewness = 0.0; // HandCrop::roll_skewness: how sure the turn's direction is
};

// Descriptors of one config, one per row, contiguous (row-major), as every index backend
// takes them.
class DescriptorMatrix {
 public:
  // `rows` rows of zeros.
  DescriptorMatrix(const DescriptorConfig& config, size_t rows);
  // Takes `values`; throws nphand::Error unless it holds whole rows.
  DescriptorMatrix(const DescriptorConfig& config, std::vector<float> values);

  const DescriptorConfig& config() const { return config_; }
  size_t rows() const { return rows_; }
  int dimension() const { return dimension_; }
  std::span<const float> Row(size_t i) const;
  std::span<float> MutableRow(size_t i);
  const std::vector<float>& values() const { return values_; }

 private:
  DescriptorConfig config_;
  int dimension_ = 0;
  size_t rows_ = 0;
  std::vector<float> values_;
};

// Throws nphand::Error, naming `what` and both configs, unless `actual` equals `expected`.
void CheckSameDescriptor(const DescriptorConfig& expected, const DescriptorConfig& actual, const std::string& what);

// The descriptor of the non-zero pixels of `mask` (CV_8UC1); std::nullopt when it has none
// ("no hand"). Throws nphand::Error for an invalid config or mask.
std::optional<Descriptor> Describe(const cv::Mat& mask, const DescriptorConfig& config);
// The same from a crop already made with config.Crop() (the estimator keeps the crop to
// place keypoints, and describes its half turn too).
Descriptor DescribeCrop(const HandCrop& crop, const DescriptorConfig& config);

}  // namespace nphand
