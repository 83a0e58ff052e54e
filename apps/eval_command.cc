#include "apps/eval_command.h"

#include <iostream>

#include "nphand/render/draw.h"
#include "nphand/util/check.h"
#include "nphand/util/file.h"
#include "nphand/util/io.h"

namespace nphand {

FeatureStudyResult RunEvalFeatures(const EvalFeaturesCommandOptions& options) {
  if (!options.out_dir.empty()) {
    CheckFileName(options.name, "eval features --name");
    CheckOutputFolder(options.out_dir, "eval features --out");
  }
  const Database db = Database::Open(options.db);
  const FeatureStudyResult result = RunFeatureStudy(db, options.study, options.quiet ? nullptr : &std::cerr);
  if (!options.out_dir.empty()) {
    WriteFileAtomic(options.out_dir / (options.name + ".json"), ToJson(result).dump(2) + "\n");
    WriteImageAtomic(options.out_dir / (options.name + ".png"), PlotCurves(result));
  }
  return result;
}

AnnStudyResult RunEvalAnn(const EvalAnnCommandOptions& options) {
  std::string why;
  NPHAND_THROW_CHECK(options.study.Check(&why), "eval ann: ", why);
  if (!options.out_dir.empty()) {
    CheckFileName(options.name, "eval ann --name");
    CheckOutputFolder(options.out_dir, "eval ann --out");
  }
  const Database db = Database::Open(options.db);
  const HandModel hand = HandModel::Load(Handedness::kRight, options.asset_dir);
  const AnnStudyResult result = RunAnnStudy(hand, db, options.study, &std::cerr);
  if (!options.out_dir.empty()) {
    WriteFileAtomic(options.out_dir / (options.name + ".json"), ToJson(result).dump(2) + "\n");
    WriteImageAtomic(options.out_dir / (options.name + ".png"), PlotAnnStudy(result));
  }
  return result;
}

PoseErrorSummary RunEvalPoses(const EvalPosesCommandOptions& options) {
  if (!options.out_dir.empty()) {
    CheckFileName(options.name, "eval poses --name");
    CheckOutputFolder(options.out_dir, "eval poses --out");
  }
  const PoseErrorSummary summary = ComparePoses(options.truth, options.poses);
  if (!options.out_dir.empty()) {
    WriteFileAtomic(options.out_dir / (options.name + ".json"), ToJson(summary).dump(2) + "\n");
    WriteImageAtomic(options.out_dir / (options.name + ".png"),
                     PlotPoseErrors(summary, options.poses.filename().string() + " against " + options.truth.filename().string()));
  }
  return summary;
}

std::vector<EstimatorScore> RunEvalEstimator(const EvalEstimatorCommandOptions& options) {
  std::string why;
  NPHAND_THROW_CHECK(options.study.Check(&why), "eval estimator: ", why);
  if (!options.out_dir.empty()) {
    CheckFileName(options.name, "eval estimator --name");
    CheckOutputFolder(options.out_dir, "eval estimator --out");
  }
  const std::filesystem::path index_path = options.index.empty() ? std::filesystem::path(options.db.string() + ".idx") : options.index;
  const Database db = Database::Open(options.db);
  const std::unique_ptr<KnnIndex> index = LoadIndex(index_path, db);
  const HandModel hand = HandModel::Load(Handedness::kRight, options.asset_dir);
  const std::vector<EstimatorScore> scores = RunEstimatorStudy(db, *index, hand, EstimatorOptions{}, options.study, &std::cerr);
  if (!options.out_dir.empty()) {
    nlohmann::json json = {{"study", "estimator validation sweep"},
                           {"database", options.db.filename().string()},
                           {"index", index->Backend()},
                           {"sequences", options.study.sequences},
                           {"frames", options.study.frames},
                           {"size", {options.study.width, options.study.height}},
                           {"seed", options.study.seed},
                           {"rows", ToJson(scores)}};
    WriteFileAtomic(options.out_dir / (options.name + ".json"), json.dump(2) + "\n");
  }
  return scores;
}

}  // namespace nphand
