#include "apps/eval_command.h"

#include <chrono>
#include <iostream>
#include <optional>

#include "apps/index_command.h"
#include "nphand/eval/real_eval.h"
#include "nphand/render/draw.h"
#include "nphand/util/check.h"
#include "nphand/util/file.h"
#include "nphand/util/io.h"
#include "nphand/util/system.h"

namespace nphand {
namespace {

// The files "<dir>/<name><extension>" a study writes, for CheckOutputsApart.
std::vector<NamedPath> NamedOutputs(const std::filesystem::path& dir, const std::string& name,
                                    const std::vector<std::string>& extensions) {
  std::vector<NamedPath> outputs;
  for (const std::string& extension : extensions) outputs.push_back({dir / (name + extension), "--out"});
  return outputs;
}

}  // namespace

FeatureStudyResult RunEvalFeatures(const EvalFeaturesCommandOptions& options) {
  if (!options.out_dir.empty()) {
    CheckFileName(options.name, "eval features --name");
    CheckOutputFolder(options.out_dir, "eval features --out");
    CheckOutputsApart({{options.db, "--db"}}, NamedOutputs(options.out_dir, options.name, {".json", ".png"}));
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
    CheckOutputsApart({{options.db, "--db"}}, NamedOutputs(options.out_dir, options.name, {".json", ".png"}));
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
    CheckOutputsApart({{options.truth, "--truth"}, {options.poses, "--poses"}},
                      NamedOutputs(options.out_dir, options.name, {".json", ".png"}));
  }
  const PoseErrorSummary summary = ComparePoses(options.truth, options.poses);
  if (!options.out_dir.empty()) {
    WriteFileAtomic(options.out_dir / (options.name + ".json"), ToJson(summary).dump(2) + "\n");
    WriteImageAtomic(options.out_dir / (options.name + ".png"),
                     PlotPoseErrors(summary, options.poses.filename().string() + " against " + options.truth.filename().string()));
  }
  return summary;
}

MotionCheck RunEvalMotion(const EvalMotionCommandOptions& options) {
  NPHAND_THROW_CHECK(!options.bvh.empty() || !options.gltf.empty(), "eval motion: give --bvh, --gltf or both");
  return CheckMotion(options.poses, options.bvh, options.gltf);
}

std::vector<EstimatorScore> RunEvalEstimator(const EvalEstimatorCommandOptions& options) {
  std::string why;
  NPHAND_THROW_CHECK(options.study.Check(&why), "eval estimator: ", why);
  if (!options.out_dir.empty()) {
    CheckFileName(options.name, "eval estimator --name");
    CheckOutputFolder(options.out_dir, "eval estimator --out");
  }
  if (!options.out_dir.empty()) {
    CheckOutputsApart(options.Inputs(), NamedOutputs(options.out_dir, options.name, {".json"}));
  }
  const OpenedFiles files(options);
  const std::vector<EstimatorScore> scores =
      RunEstimatorStudy(files.db, *files.index, files.hand, EstimatorOptions{}, options.study, &std::cerr);
  if (!options.out_dir.empty()) {
    nlohmann::json json = {{"study", "estimator validation sweep"},
                           {"database", options.db.filename().string()},
                           {"index", files.index->Backend()},
                           {"sequences", options.study.sequences},
                           {"frames", options.study.frames},
                           {"size", {options.study.width, options.study.height}},
                           {"seed", options.study.seed},
                           {"input", options.study.masks ? "masks" : "rgb"},
                           {"adult_arm", options.study.adult_arm},
                           {"rows", ToJson(scores)}};
    WriteFileAtomic(options.out_dir / (options.name + ".json"), json.dump(2) + "\n");
  }
  return scores;
}

EvalRealResult RunEvalReal(const EvalRealCommandOptions& options, std::ostream* progress) {
  NPHAND_THROW_CHECK(!options.labels.empty(), "eval real: --labels is required (e.g. ../shared/real-dev/labels.jsonl)");
  NPHAND_THROW_CHECK(options.hand == "given" || options.hand == "auto", "eval real: --hand is given or auto, not '", options.hand, "'");
  const RealRunOptions run{.given_box = options.given_box, .max_side = options.max_side};
  std::string why;
  NPHAND_THROW_CHECK(run.Check(&why), "eval real: ", why);
  if (!options.out_dir.empty()) {
    CheckOutputFolder(options.out_dir, "eval real --out");
    std::vector<NamedPath> inputs = options.Inputs();
    inputs.insert(inputs.begin(), {options.labels, "--labels"});
    CheckOutputsApart(inputs, {{options.out_dir, "eval real --out", {".json", ".jsonl", ".png"}}});
  }
  const std::vector<RealLabel> labels = ReadRealLabels(options.labels);
  const std::filesystem::path root = options.labels.has_parent_path() ? options.labels.parent_path() : ".";
  CheckRealFiles(labels, root);
  const OpenedFiles files(options);
  const Database& db = files.db;
  const KnnIndex& index = *files.index;
  const HandModel& hand = files.hand;
  EstimatorOptions estimator_options;
  if (!options.faces) estimator_options.skin.face_cascade.clear();
  estimator_options.refine = options.refine;
  SetRefineMoves(options.refine_move, &estimator_options.refinement);
  estimator_options.max_distance = options.max_distance;
  estimator_options.k = options.k;
  estimator_options.track_views = options.track_views;
  estimator_options.carried = options.carried;
  estimator_options.carry_apart_frames = options.carry_apart_frames;
  estimator_options.prior_reset_frames = options.prior_reset_frames;
  estimator_options.prior_reset_margin = options.prior_reset_margin;
  estimator_options.skin.face_chroma = options.face_chroma;
  estimator_options.arm_agreement = options.arm_agreement;
  estimator_options.objects = options.objects;
  estimator_options.tilts_deg = options.tilts_deg;
  const bool given = options.hand == "given";
  SetHandChoice(given ? "right" : options.hand, &estimator_options);
  Estimator right(db, index, hand, estimator_options);
  // With the side given, a second estimator for the left hands.
  std::optional<Estimator> left;
  if (given) {
    estimator_options.hand = Handedness::kLeft;
    left.emplace(db, index, hand, estimator_options);
  }
  const std::vector<RealPrediction> predictions = EstimateReal(labels, root, &right, left ? &*left : nullptr, run, progress);
  const RealScore score = ScoreReal(labels, predictions);
  EvalRealResult result{ToJson(score), FormatTable(score)};
  result.figures["labels"] = options.labels.string();
  result.figures["database"] = options.db.filename().string();
  result.figures["index"] = index.Backend();
  result.figures["hand"] = options.hand;
  result.figures["refine"] = options.refine;
  result.figures["refine_move"] = options.refine_move;
  result.figures["max_distance"] = options.max_distance;
  result.figures["k"] = options.k;
  result.figures["track_views"] = options.track_views;
  result.figures["carried"] = options.carried;
  result.figures["carry_apart_frames"] = options.carry_apart_frames;
  result.figures["prior_reset_frames"] = options.prior_reset_frames;
  result.figures["prior_reset_margin"] = options.prior_reset_margin;
  result.figures["face_chroma"] = options.face_chroma;
  result.figures["arm_agreement"] = options.arm_agreement;
  result.figures["objects"] = options.objects;
  result.figures["tilts_deg"] = options.tilts_deg;
  result.figures["given_box"] = options.given_box;
  result.figures["max_side"] = options.max_side;
  result.figures["machine"] = MachineDescription();
  if (!options.out_dir.empty()) {
    std::string lines;
    for (const RealPrediction& p : predictions) lines += ToJson(p).dump() + "\n";
    WriteFileAtomic(options.out_dir / "real_predictions.jsonl", lines);
    WriteFileAtomic(options.out_dir / "real.json", result.figures.dump(2) + "\n");
    WriteImageAtomic(options.out_dir / "real_contact.png", RealContactSheet(labels, predictions, score, root));
  }
  return result;
}

namespace {

void WritePoseStudy(const PoseStudyResult& result, const std::filesystem::path& out_dir) {
  WriteFileAtomic(out_dir / (result.part + ".json"), ToJson(result).dump(2) + "\n");
  for (const auto& [stem, image] : PlotPoseStudy(result)) WriteImageAtomic(out_dir / (stem + ".png"), image);
}

// What a pose study reads, opened once its options and outputs are checked.
struct LoadedStudy : OpenedFiles {
  LoadedStudy(const EvalPoseStudyCommandOptions& options, const std::string& command)
      : OpenedFiles(Checked(options, command)) {}
  static const EvalPoseStudyCommandOptions& Checked(const EvalPoseStudyCommandOptions& options,
                                                     const std::string& command) {
    std::string why;
    NPHAND_THROW_CHECK(options.study.Check(&why), command, ": ", why);
    if (!options.out_dir.empty()) {
      CheckOutputFolder(options.out_dir, command + " --out");
      CheckOutputsApart(options.Inputs(), {{options.out_dir, command + " --out", {".json", ".png"}}});
    }
    return options;
  }
};

}  // namespace

PoseStudyResult RunEvalPoseStudy(PoseStudyPart part, const EvalPoseStudyCommandOptions& options) {
  const LoadedStudy loaded(options, "eval " + ToString(part));
  PoseStudyResult result = RunPoseStudy(part == PoseStudyPart::kBaselines ? PoseStudyPart::kNoise : part, loaded.db,
                                        *loaded.index, loaded.hand, EstimatorOptions{},
                                        [&] {
                                          PoseStudyOptions o = options.study;
                                          if (part == PoseStudyPart::kBaselines) o.alphas = {0.0};
                                          return o;
                                        }(),
                                        &std::cerr);
  if (part == PoseStudyPart::kBaselines) result = BaselinesOf(result);
  if (!options.out_dir.empty()) WritePoseStudy(result, options.out_dir);
  return result;
}

nlohmann::json RunEvalAll(const EvalPoseStudyCommandOptions& options) {
  NPHAND_THROW_CHECK(!options.out_dir.empty(), "eval all: --out is required (the study writes its files there)");
  // Everything the pose studies read is opened first: a bad option, a missing index or
  // asset fails now, not after the feature and nearest-neighbour studies.
  const LoadedStudy loaded(options, "eval all");
  using Clock = std::chrono::steady_clock;
  nlohmann::json summary = {{"machine", MachineDescription()}, {"parts", nlohmann::json::object()}};
  const auto timed = [&](const std::string& name, const auto& run) {
    const Clock::time_point start = Clock::now();
    run();
    summary["parts"][name] = std::chrono::duration<double>(Clock::now() - start).count();
    std::cerr << "eval all: " << name << " done\n";
  };
  timed("features", [&] {
    EvalFeaturesCommandOptions features;
    features.db = options.db;
    features.out_dir = options.out_dir;
    RunEvalFeatures(features);
  });
  timed("ann", [&] {
    EvalAnnCommandOptions ann;
    ann.db = options.db;
    ann.asset_dir = options.asset_dir;
    ann.out_dir = options.out_dir;
    ann.study.fractions = {1.0};
    ann.study.configs = {"exact", "lsh", "hnswlib-sq8", "faiss-ivf"};
    RunEvalAnn(ann);
  });
  timed("noise and baselines", [&] {
    const PoseStudyResult noise =
        RunPoseStudy(PoseStudyPart::kNoise, loaded.db, *loaded.index, loaded.hand, EstimatorOptions{}, options.study, &std::cerr);
    WritePoseStudy(noise, options.out_dir);
    WritePoseStudy(BaselinesOf(noise), options.out_dir);
  });
  timed("robustness", [&] {
    WritePoseStudy(RunPoseStudy(PoseStudyPart::kRobustness, loaded.db, *loaded.index, loaded.hand, EstimatorOptions{},
                                options.study, &std::cerr),
                   options.out_dir);
  });
  double total = 0.0;
  for (const auto& [name, seconds] : summary["parts"].items()) total += seconds.get<double>();
  summary["seconds"] = total;
  WriteFileAtomic(options.out_dir / "evaluation.json", summary.dump(2) + "\n");
  return summary;
}

}  // namespace nphand
