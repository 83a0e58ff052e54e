// `nphand bench render`: how fast label images of a hand plus an object render on one core.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "apps/estimator_files.h"
#include "nphand/estimate/estimator.h"
#include "nphand/model/hand_model.h"

namespace nphand {

struct BenchRenderOptions {
  int images = 2000;      // label images timed (after a warm-up of a tenth as many)
  int size = 128;         // square image side, pixels
  uint64_t seed = 1;      // viewpoints and articulations
  std::filesystem::path asset_dir = DefaultAssetDir();

  bool Check(std::string* why) const;
};

// Renders `images` label images of the right hand (random articulations within limits, a
// sphere in its palm, random viewpoints) on this thread. Returns label_images_per_s,
// full_images_per_s (labels + depth + RGB), the image size, the triangle counts and the
// machine.
nlohmann::json RunBenchRender(const BenchRenderOptions& options);

// `nphand bench pipeline`: frames per second of the whole estimator on one core: skin
// segmentation of the frame, the forearm cut, the descriptor, the K-nearest search, the
// weights and prior, the placement; milliseconds per stage; peak resident memory.
struct BenchPipelineOptions : EstimatorFiles {
  int frames = 300;             // timed (after a warm-up of 30), from rendered sequences
  int width = 640;
  int height = 480;
  int k = 500;
  int track_views = EstimatorOptions{}.track_views;  // viewpoints of the track's views measured besides
  std::string hand = "right";   // right, left or auto
  bool refine = false;          // the estimator refines its best view (refine/refiner.h)
  std::vector<double> tilts_deg = EstimatorOptions{}.tilts_deg;  // the crop's tilts where the match is poor
  // A face beside the hand in every frame, as before a webcam: the face cascade and the
  // skin gate read from the face are then part of the time.
  bool face = true;
  uint64_t seed = 1;
  // OpenCV's threads for the image work (colour, resizing, morphology, the face cascade);
  // 1 keeps the whole path on one core, as the speed goal asks.
  int threads = 1;

  bool Check(std::string* why) const;
};

// Returns fps, ms per stage (median and mean), peak_rss_mb, db_entries, backend, k, the
// frame size and the machine.
nlohmann::json RunBenchPipeline(const BenchPipelineOptions& options);

}  // namespace nphand
