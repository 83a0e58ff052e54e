// `nphand bench render`: how fast label images of a hand plus an object render on one core.
#pragma once

#include <cstdint>
#include <filesystem>

#include <nlohmann/json.hpp>

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

}  // namespace nphand
