// `nphand estimate`: hand poses for every frame of a video, an image folder or a camera,
// one JSON line per frame (docs/FORMAT.md), optionally an overlay video; progress on
// files; Ctrl-C stops after the current frame and leaves complete files.
#pragma once

#include <atomic>
#include <filesystem>
#include <ostream>
#include <string>

#include <nlohmann/json.hpp>

#include "nphand/estimate/estimator.h"
#include "nphand/model/hand_model.h"

namespace nphand {

struct EstimateCommandOptions {
  std::filesystem::path db = "out/nphand.db";
  std::filesystem::path index;            // default: the database's path + ".idx"
  std::string input;                      // video file, image folder or camera index
  std::filesystem::path out = "out/poses.jsonl";
  std::filesystem::path overlay;          // optional .mp4: the frame with the skeleton, the matched view beside it
  std::string hand = "right";
  std::string observation = "fixed";
  std::string prior = "product";
  double fps = 30.0;                      // for image folders
  uint64_t max_frames = 0;                // 0: all
  bool top = false;                       // write the top-N hypotheses
  bool faces = true;                      // set faces aside (OpenCV's cascade from opencv-data)
  EstimatorOptions estimator;
  std::filesystem::path asset_dir = DefaultAssetDir();
};

// Runs the estimator over the input. `stop` (if not null) is polled between frames: when it
// turns true the run ends cleanly. Returns a summary (frames, detected, fps, files).
nlohmann::json RunEstimate(const EstimateCommandOptions& options, std::ostream* progress, const std::atomic<bool>* stop);

}  // namespace nphand
