// The feature study of the paper (Sec. 4.1, Fig. 4): how well does nearness in a feature
// space predict nearness in pose? Query entries are removed from the database in turn
// (with their twin: the same grasp, step and viewpoint rendered with/without the object),
// their nearest neighbours in feature space are found (exact search), and the cumulative
// mean pose error of neighbours 1..K is reported: the mean absolute joint-angle error in
// degrees (the paper's measure) and the wrist-orientation error in degrees beside it.
#pragma once

#include <cstdint>
#include <ostream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "nphand/db/database.h"
#include "nphand/features/hog.h"

namespace nphand {

// A feature of the study: "joints" (neighbours in pose space: the lower bound), a HOG
// variant, "dist32" (the contour distance transform on 32 x 32), or "chamfer_rerank": the
// symmetric chamfer distance between contours, applied to the 200 nearest by HOG 8x8x8
// (an exhaustive chamfer search over the database is out of proportion).
struct StudyFeature {
  std::string name;
  enum class Kind { kJoints, kHog, kDistance, kChamferRerank } kind = Kind::kHog;
  HogOptions hog;
};
// The paper's candidates: joints, hog8x8x8, hog8x8x4, hog8x8x16, hog4x4x8, hog16x16x8,
// hog8x8x8_pyr, hog8x8x8_nh, dist32, chamfer_rerank.
std::vector<StudyFeature> PaperFeatures();

struct FeatureStudyOptions {
  int queries = 2000;                // query entries, drawn with `seed` among those with a hand
  int neighbours = 50;               // K
  uint64_t seed = 1;
  std::vector<std::string> features; // names from PaperFeatures(); empty: all
  bool roll_queries = false;         // turn each query's hand by a random in-plane angle
  bool normalize_roll = false;       // crop every hand by its principal axis (CropOptions)
  size_t chunk = 16384;              // database entries cropped and described at once (memory)

  bool Check(std::string* why) const;
};

struct FeatureCurve {
  std::string name;
  int dimension = 0;
  std::vector<double> joint_deg;  // [k-1]: mean over queries of the mean error of neighbours 1..k
  std::vector<double> wrist_deg;
};

struct FeatureStudyResult {
  FeatureStudyOptions options;
  uint64_t candidates = 0;         // database entries searched (those with a hand)
  double seconds = 0.0;
  std::vector<FeatureCurve> curves;
};

FeatureStudyResult RunFeatureStudy(const Database& db, const FeatureStudyOptions& options, std::ostream* progress);

nlohmann::json ToJson(const FeatureStudyResult& result);
// The paper-style table: per feature, the joint error at neighbours 1 (2, 5, 10), the wrist
// error at 1 and 10, and the paper's figure where it has one.
std::string FormatTable(const FeatureStudyResult& result);
// The curves as a picture (joint error against neighbours), one colour per feature.
cv::Mat PlotCurves(const FeatureStudyResult& result);

}  // namespace nphand
