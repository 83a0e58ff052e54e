// How faithfully motion files (nphand estimate --bvh / --gltf) hold the estimate: each file
// read back (the BVH through forward kinematics, the glTF's animated joints), its keypoints
// against the ones poses.jsonl gives for the frames with the track's hand (with --hand auto,
// the side of more frames: the side the files hold).
#pragma once

#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

namespace nphand {

struct MotionDifference {
  double max_mm = 0.0;
  double mean_mm = 0.0;
};

struct MotionCheck {
  size_t frames = 0;    // lines of poses.jsonl
  size_t compared = 0;  // of them, frames with the track's hand
  std::optional<MotionDifference> bvh, gltf;
};

// Either file may be empty (not checked). Throws nphand::Error naming a file that cannot be
// read, and when a file's frame count is not the poses'.
MotionCheck CheckMotion(const std::filesystem::path& poses, const std::filesystem::path& bvh,
                        const std::filesystem::path& gltf);

nlohmann::json ToJson(const MotionCheck& check);
std::string FormatTable(const MotionCheck& check);

}  // namespace nphand
