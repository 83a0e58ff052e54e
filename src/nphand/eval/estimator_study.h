// The estimator's validation sweep: how the observation weight (fixed sigma_y or adaptive),
// the temporal prior (none, product, weighted sum; sigma_x), the hypotheses carried and K
// change the estimates on rendered validation sequences whose grasps are closed onto
// objects of sizes the database does not hold, with forearms, several skin tones,
// backgrounds and faces, and a rolling camera. The defaults of EstimatorOptions are chosen
// from it (docs/estimator.md). Validation seeds are not the evaluation's.
#pragma once

#include <cstdint>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "nphand/db/database.h"
#include "nphand/estimate/estimator.h"
#include "nphand/index/knn_index.h"
#include "nphand/model/hand_model.h"
#include "nphand/sequence/sequence.h"

namespace nphand {

struct EstimatorSetting {
  std::string name;
  EstimatorOptions options;
};

// The sweep: the observation alone (nearest neighbour), then each observation weight with
// each prior, then the number carried and K for the paper's product.
std::vector<EstimatorSetting> EstimatorSweep(const EstimatorOptions& base);

struct EstimatorStudyOptions {
  int sequences = 24;    // 8 proved too few: one sequence locking onto a wrong mode moved the mean by 5 mm
  int frames = 60;        // per sequence
  int width = 640;
  int height = 480;
  uint64_t seed = 7000;   // sequence i uses seed + i (the evaluation uses other seeds)
  std::vector<std::string> settings;  // names from EstimatorSweep(); empty: all
  bool masks = false;     // the rendered hand's mask (the paper's input) instead of the RGB frame
  bool adult_arm = false; // sequences with a forearm render an adult's arm (Forearm::Adult()), not the cone
  bool Check(std::string* why) const;
};

// The validation sequences: sequence i of seed + i, with or without a forearm, bare or
// sleeved, on each background, a face in every fourth.
std::vector<SequenceOptions> ValidationSequences(const EstimatorStudyOptions& options);

struct EstimatorScore {
  std::string name;
  nlohmann::json options;      // what differs from the base
  int frames = 0;
  int detected = 0;            // frames with an estimate
  int both_turns = 0;          // of which searched the half-turned crop too
  int tilted = 0;              // of which searched the crop's tilts too (EstimatorOptions::tilts_deg)
  int turned = 0;              // of which with the wrist turned about a half turn: at least kTurnedDeg from the truth
  int flipped = 0;             // of which, the truth not edge-on, with the other side of the hand towards the camera (FacingOf)
  double joint_deg = 0.0;      // mean absolute joint-angle error, mean over detected frames
  double wrist_deg = 0.0;      // wrist rotation error, mean
  double keypoint_mm = 0.0;    // mean 3D keypoint error about the wrist (the paper's joint-position measure)
  double keypoint_px = 0.0;    // mean 2D keypoint error in the frame
  double camera_mm = 0.0;      // mean 3D keypoint error in the camera frame (includes the distance)
  double jitter_mm = 0.0;      // keypoints about the wrist: mean second difference over runs of detected frames (mm/frame²)
  // The estimate's lag behind the truth (LagMeter, measures.h); none with nothing detected.
  std::optional<int> lag_frames;
  double ms_median = 0.0;      // per frame, the whole estimator
};

// Renders the sequences once and runs every setting over them (one thread).
std::vector<EstimatorScore> RunEstimatorStudy(const Database& db, const KnnIndex& index, const HandModel& hand,
                                              const EstimatorOptions& base, const EstimatorStudyOptions& options,
                                              std::ostream* progress);

nlohmann::json ToJson(const std::vector<EstimatorScore>& scores);
std::string FormatTable(const std::vector<EstimatorScore>& scores);

}  // namespace nphand
