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

}  // namespace nphand
