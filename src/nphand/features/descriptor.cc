#include "nphand/features/descriptor.h"

#include <sstream>

#include "nphand/util/check.h"

namespace nphand {

bool DescriptorConfig::Check(std::string* why) const {
  if (!Crop().Check(why) || !hog.Check(why)) return false;
  if (crop_size % hog.cells != 0) {
    *why = "the HOG cell count must divide the crop side " + std::to_string(crop_size);
    return false;
  }
  return true;
}

std::string DescriptorConfig::ToString() const {
  std::ostringstream out;
  out << hog.Name() << ", crop " << crop_size << " px + " << crop_margin << " margin, "
      << (normalize_roll ? "roll-normalised" : "roll as seen");
  return out.str();
}

bool DescriptorConfig::operator==(const DescriptorConfig& other) const {
  return crop_size == other.crop_size && crop_margin == other.crop_margin && normalize_roll == other.normalize_roll &&
         hog.cells == other.hog.cells && hog.bins == other.hog.bins && hog.pyramid == other.hog.pyramid &&
         hog.signed_orientation == other.hog.signed_orientation && hog.normalization == other.hog.normalization;
}

nlohmann::json ToJson(const DescriptorConfig& config) {
  return {{"crop_size", config.crop_size},
          {"crop_margin", config.crop_margin},
          {"normalize_roll", config.normalize_roll},
          {"hog",
           {{"name", config.hog.Name()},
            {"cells", config.hog.cells},
            {"bins", config.hog.bins},
            {"pyramid", config.hog.pyramid},
            {"signed", config.hog.signed_orientation},
            {"normalization", ToString(config.hog.normalization)},
            {"dimension", config.Dimension()}}}};
}

DescriptorConfig DescriptorConfigFromJson(const nlohmann::json& json, const std::string& source) {
  DescriptorConfig config;
  try {
    config.crop_size = json.at("crop_size").get<int>();
    config.crop_margin = json.at("crop_margin").get<double>();
    config.normalize_roll = json.at("normalize_roll").get<bool>();
    const nlohmann::json& hog = json.at("hog");
    config.hog.cells = hog.at("cells").get<int>();
    config.hog.bins = hog.at("bins").get<int>();
    config.hog.pyramid = hog.at("pyramid").get<bool>();
    config.hog.signed_orientation = hog.at("signed").get<bool>();
    const std::string normalization = hog.at("normalization").get<std::string>();
    NPHAND_THROW_CHECK(normalization == ToString(HogNormalization::kGlobalL2) ||
                           normalization == ToString(HogNormalization::kCellSum),
                       source, ": unknown HOG normalisation '", normalization, "'");
    config.hog.normalization = HogNormalizationFromString(normalization);
    NPHAND_THROW_CHECK(hog.at("dimension").get<int>() == config.Dimension(), source, ": the descriptor's dimension ",
                       hog.at("dimension").get<int>(), " does not match ", config.hog.Name());
  } catch (const nlohmann::json::exception& e) {
    NPHAND_THROW(source, ": the descriptor config is missing a field or has one of the wrong type (", e.what(), ")");
  }
  std::string why;
  NPHAND_THROW_CHECK(config.Check(&why), source, ": invalid descriptor config (", why, ")");
  return config;
}

std::optional<Descriptor> Describe(const cv::Mat& mask, const DescriptorConfig& config) {
  std::string why;
  NPHAND_THROW_CHECK(config.Check(&why), "descriptor: ", why);
  const std::optional<HandCrop> crop = CropHand(mask, config.Crop());
  if (!crop.has_value()) return std::nullopt;
  return DescribeCrop(*crop, config);
}

Descriptor DescribeCrop(const HandCrop& crop, const DescriptorConfig& config) {
  NPHAND_THROW_CHECK(crop.image.type() == CV_32FC1 && crop.image.rows == config.crop_size &&
                         crop.image.cols == config.crop_size,
                     "descriptor: a crop of ", crop.image.cols, "x", crop.image.rows, " is not the config's ",
                     config.crop_size, " pixels");
  return Descriptor{config, ComputeHog(crop.image, config.hog), crop.roll, crop.roll_skewness};
}

DescriptorMatrix::DescriptorMatrix(const DescriptorConfig& config, size_t rows)
    : DescriptorMatrix(config, std::vector<float>(rows * config.Dimension(), 0.0f)) {}

DescriptorMatrix::DescriptorMatrix(const DescriptorConfig& config, std::vector<float> values)
    : config_(config), dimension_(config.Dimension()), values_(std::move(values)) {
  NPHAND_THROW_CHECK(values_.size() % dimension_ == 0, "descriptor matrix: ", values_.size(),
                     " values are not whole rows of ", dimension_);
  rows_ = values_.size() / dimension_;
}

std::span<const float> DescriptorMatrix::Row(size_t i) const {
  NPHAND_CHECK(i < rows_, "row ", i, " of ", rows_);
  return {values_.data() + i * dimension_, static_cast<size_t>(dimension_)};
}

std::span<float> DescriptorMatrix::MutableRow(size_t i) {
  NPHAND_CHECK(i < rows_, "row ", i, " of ", rows_);
  return {values_.data() + i * dimension_, static_cast<size_t>(dimension_)};
}

void CheckSameDescriptor(const DescriptorConfig& expected, const DescriptorConfig& actual, const std::string& what) {
  NPHAND_THROW_CHECK(expected == actual, what, ": described as ", actual.ToString(), ", but ", expected.ToString(),
                     " is expected");
}

}  // namespace nphand
