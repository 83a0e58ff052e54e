// `nphand estimate`: hand poses for every frame of a video, an image folder or a camera,
// one JSON line per frame (docs/FORMAT.md), optionally an overlay video; progress on
// files; Ctrl-C, SIGTERM and SIGHUP stop after the current frame and leave complete files.
#pragma once

#include <atomic>
#include <filesystem>
#include <ostream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "apps/estimator_files.h"
#include "nphand/estimate/estimator.h"
#include "nphand/model/hand_model.h"
#include "nphand/refine/refiner.h"

namespace nphand {

struct EstimateCommandOptions : EstimatorFiles {
  std::string input;                      // video file, image folder or camera index
  std::filesystem::path out = "out/poses.jsonl";
  std::filesystem::path overlay;          // optional .mp4: the frame with the skeleton, the matched view beside it
  std::filesystem::path bvh;              // optional .bvh: the skeleton's motion (nphand/motion/bvh.h)
  std::filesystem::path gltf;             // optional .glb: the rigged mesh with the motion (nphand/motion/gltf_motion.h)
  std::string hand = "right";
  std::string observation = "fixed";
  std::string prior = "product";
  std::vector<std::string> refine_move = RefineMoves(RefineOptions{});  // what the refinement moves (SetRefineMoves)
  double fps = 30.0;                      // for image folders
  uint64_t max_frames = 0;                // 0: all
  bool top = false;                       // write the top-N hypotheses
  bool faces = true;                      // set faces aside (OpenCV's cascade from opencv-data)
  std::vector<int> roi;                   // x, y, width, height: the hand sought there only (empty: everywhere)
  EstimatorOptions estimator;
};

// Runs the estimator over the input (docs/FORMAT.md says what each ending leaves). The motion
// files hold one track of the hand's side (with --hand auto, the side found in more frames);
// frames without it hold the last pose. They are written after the poses, and a run
// without any hand writes none of them and says so. Before any
// work, an output that is an input or another output is refused, and so is a second run
// into the same outputs. `stop` (if not null) is polled between frames: when it holds a
// signal number the run ends cleanly after the current frame. Returns a summary (frames,
// detected, unreadable, stopped and by which signal, whether the input was whole, files).
// A run stopped before its first frame replaces nothing ("out" is null).
nlohmann::json RunEstimate(const EstimateCommandOptions& options, std::ostream* progress, const std::atomic<int>* stop);

// "SIGINT", "SIGTERM", "SIGHUP".
const char* SignalName(int signal);

}  // namespace nphand
