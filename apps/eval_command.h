// `nphand eval features`: the paper's feature study on a database.
#pragma once

#include <filesystem>

#include "nphand/eval/feature_study.h"

namespace nphand {

struct EvalFeaturesCommandOptions {
  std::filesystem::path db = "out/nphand.db";
  std::filesystem::path out_dir;  // if set: feature_study.json and feature_study.png there
  std::string name = "feature_study";
  FeatureStudyOptions study;
  bool quiet = false;
};

FeatureStudyResult RunEvalFeatures(const EvalFeaturesCommandOptions& options);

}  // namespace nphand
