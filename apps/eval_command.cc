#include "apps/eval_command.h"

#include <iostream>

#include "nphand/render/draw.h"
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

}  // namespace nphand
