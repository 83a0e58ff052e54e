// `nphand eval features`: the paper's feature study on a database.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "apps/estimator_files.h"
#include "nphand/eval/ann_study.h"
#include "nphand/eval/estimator_study.h"
#include "nphand/eval/motion_check.h"
#include "nphand/eval/pose_errors.h"
#include "nphand/eval/pose_report.h"
#include "nphand/eval/pose_study.h"
#include "nphand/eval/feature_study.h"
#include "nphand/refine/refiner.h"

namespace nphand {

struct EvalFeaturesCommandOptions {
  std::filesystem::path db = "out/nphand.db";
  std::filesystem::path out_dir;  // if set: feature_study.json and feature_study.png there
  std::string name = "feature_study";
  FeatureStudyOptions study;
  bool quiet = false;
};

FeatureStudyResult RunEvalFeatures(const EvalFeaturesCommandOptions& options);

// `nphand eval ann`: the nearest-neighbour study (paper Fig. 5) on a database.
struct EvalAnnCommandOptions {
  std::filesystem::path db = "out/nphand.db";
  std::filesystem::path asset_dir = DefaultAssetDir();
  std::filesystem::path out_dir;  // if set: ann_study.json and ann_study.png there
  std::string name = "ann_study";
  AnnStudyOptions study;
};

AnnStudyResult RunEvalAnn(const EvalAnnCommandOptions& options);

struct EvalEstimatorCommandOptions : EstimatorFiles {
  std::filesystem::path out_dir;  // if set: <name>.json there
  std::string name = "estimator_study";
  EstimatorStudyOptions study;
};

struct EvalPosesCommandOptions {
  std::filesystem::path truth;   // truth.jsonl of `nphand sequence`
  std::filesystem::path poses;   // poses.jsonl of `nphand estimate`
  std::filesystem::path out_dir; // if set: <name>.json and <name>.png there
  std::string name = "errors";
};

// Errors of estimated poses against ground truth (docs/FORMAT.md), frame by frame.
PoseErrorSummary RunEvalPoses(const EvalPosesCommandOptions& options);

struct EvalMotionCommandOptions {
  std::filesystem::path poses;  // poses.jsonl of `nphand estimate`
  std::filesystem::path bvh;    // its --bvh, its --gltf: at least one
  std::filesystem::path gltf;
};

// The motion files read back against the poses (nphand/eval/motion_check.h).
MotionCheck RunEvalMotion(const EvalMotionCommandOptions& options);

struct EvalPoseStudyCommandOptions : EstimatorFiles {
  std::filesystem::path out_dir;  // if set: <part>.json and its plots there
  PoseStudyOptions study;
};

// `nphand eval baselines|noise|robustness` (docs/EVALUATION.md).
PoseStudyResult RunEvalPoseStudy(PoseStudyPart part, const EvalPoseStudyCommandOptions& options);

// `nphand eval all`: the feature study, the nearest-neighbour study at the database's full
// size (exact, lsh, hnswlib-sq8, faiss-ivf), the noise study (whose alpha-0 rows are the
// baselines) and the robustness study, each written to out_dir as its own command would,
// and evaluation.json: what ran, how long each part took, on what machine.
nlohmann::json RunEvalAll(const EvalPoseStudyCommandOptions& options);

// `nphand eval real`: the estimator on labelled real images and video (real-dev's format),
// scored as real-dev's reference scorer does (eval/real_score.h).
struct EvalRealCommandOptions : EstimatorFiles {
  std::filesystem::path labels;   // labels.jsonl; the files it names are relative to its folder
  std::filesystem::path out_dir;  // if set: real.json, real_predictions.jsonl, real_contact.png there
  bool faces = true;              // set faces aside (OpenCV's cascade)
  std::string hand = "given";     // "given": the labelled side; "auto": the estimator chooses
  bool refine = false;            // the estimator refines its best view (refine/refiner.h)
  std::vector<std::string> refine_move = RefineMoves(RefineOptions{});  // what the refinement moves (SetRefineMoves)
  double max_distance = EstimatorOptions{}.max_distance;  // "no hand" beyond this feature distance
  int k = EstimatorOptions{}.k;            // neighbours searched
  int track_views = EstimatorOptions{}.track_views;  // viewpoints of the track's views searched besides
  int carried = EstimatorOptions{}.carried;          // hypotheses carried to the next frame
  int carry_apart_frames = EstimatorOptions{}.carry_apart_frames;  // a track's first frames carry one hypothesis per mode
  int prior_reset_frames = EstimatorOptions{}.prior_reset_frames;  // a track let go after this many frames against it
  double prior_reset_margin = EstimatorOptions{}.prior_reset_margin;  // how much nearer the view outside the mode lies
  double face_chroma = SkinOptions{}.face_chroma;  // skin only near a face's colours while one is in view (0: off)
  double arm_agreement = EstimatorOptions{}.arm_agreement;  // hypotheses turned against the arm cut off weigh less
  bool objects = true;  // false: the hands hold nothing (EstimatorOptions::objects)
  std::vector<double> tilts_deg = EstimatorOptions{}.tilts_deg;  // the crop's tilts where the match is poor
  // The hand's place given: each labelled hand estimated within its found region (the
  // pose alone judged, apart from finding the hand).
  bool given_box = false;
  // Frames shrunk to at most this longer side before they are estimated (RealRunOptions).
  int max_side = 0;
};

struct EvalRealResult {
  nlohmann::json figures;  // eval/real_score.h's ToJson, with the run's settings
  std::string table;
};

EvalRealResult RunEvalReal(const EvalRealCommandOptions& options, std::ostream* progress);

// The estimator's validation sweep (docs/estimator.md).
std::vector<EstimatorScore> RunEvalEstimator(const EvalEstimatorCommandOptions& options);

}  // namespace nphand
