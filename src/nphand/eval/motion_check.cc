#include "nphand/eval/motion_check.h"

#include <algorithm>
#include <cstdio>
#include <functional>
#include <vector>

#include "nphand/eval/json_lines.h"
#include "nphand/motion/bvh.h"
#include "nphand/motion/gltf_motion.h"
#include "nphand/util/check.h"
#include "nphand/util/io.h"

namespace nphand {
namespace {

// The keypoints in the camera frame (metres) of each line with a hand of the track's side
// (the side of more lines, as the motion files hold); none for the others.
std::vector<std::optional<Keypoints3d>> EstimatedKeypoints(const std::filesystem::path& poses) {
  std::vector<std::optional<Keypoints3d>> frames;
  std::vector<bool> left;
  for (const JsonLine& line : ReadJsonLines(poses)) {
    std::optional<Keypoints3d> keypoints;
    if (line.json.value("detected", false)) {
      const nlohmann::json& points = line.json.at("keypoints_3d_camera_m");
      NPHAND_THROW_CHECK(points.is_array() && points.size() == kNumKeypoints, poses.string(), ": line ", line.number,
                         ": keypoints_3d_camera_m is not 21 points");
      keypoints.emplace();
      for (int k = 0; k < kNumKeypoints; ++k) {
        for (int a = 0; a < 3; ++a) (*keypoints)[k][a] = points[k].at(a).get<double>();
      }
    }
    frames.push_back(keypoints);
    left.push_back(line.json.value("hand", "right") == "left");
  }
  size_t lefts = 0, rights = 0;
  for (size_t f = 0; f < frames.size(); ++f) {
    if (frames[f].has_value()) ++(left[f] ? lefts : rights);
  }
  for (size_t f = 0; f < frames.size(); ++f) {
    if (left[f] != (lefts > rights)) frames[f].reset();
  }
  return frames;
}

MotionDifference Compare(const std::vector<std::optional<Keypoints3d>>& estimated, size_t frames,
                         const std::function<Keypoints3d(size_t)>& read, const std::string& what) {
  NPHAND_THROW_CHECK(frames == estimated.size(), what, " holds ", frames, " frames, the poses ", estimated.size());
  MotionDifference difference;
  size_t count = 0;
  for (size_t f = 0; f < estimated.size(); ++f) {
    if (!estimated[f].has_value()) continue;
    const Keypoints3d keypoints = read(f);
    for (int k = 0; k < kNumKeypoints; ++k) {
      const double mm = 1000.0 * (keypoints[k] - (*estimated[f])[k]).norm();
      difference.max_mm = std::max(difference.max_mm, mm);
      difference.mean_mm += mm;
      ++count;
    }
  }
  if (count > 0) difference.mean_mm /= count;
  return difference;
}

}  // namespace

MotionCheck CheckMotion(const std::filesystem::path& poses, const std::filesystem::path& bvh,
                        const std::filesystem::path& gltf) {
  const std::vector<std::optional<Keypoints3d>> estimated = EstimatedKeypoints(poses);
  MotionCheck check;
  check.frames = estimated.size();
  check.compared = std::count_if(estimated.begin(), estimated.end(), [](const auto& k) { return k.has_value(); });
  if (!bvh.empty()) {
    const Bvh file = ReadBvh(bvh);
    check.bvh = Compare(estimated, file.frames.size(), [&](size_t f) { return BvhKeypoints(file, f); }, bvh.string());
  }
  if (!gltf.empty()) {
    const GltfMotion file = ReadGltfMotion(ReadFileBytes(gltf), gltf.string());
    check.gltf = Compare(estimated, file.frames.size(), [&](size_t f) { return GltfKeypoints(file, f); }, gltf.string());
  }
  return check;
}

nlohmann::json ToJson(const MotionCheck& check) {
  nlohmann::json j = {{"frames", check.frames}, {"compared", check.compared}};
  if (check.bvh.has_value()) j["bvh"] = {{"max_mm", check.bvh->max_mm}, {"mean_mm", check.bvh->mean_mm}};
  if (check.gltf.has_value()) j["gltf"] = {{"max_mm", check.gltf->max_mm}, {"mean_mm", check.gltf->mean_mm}};
  return j;
}

std::string FormatTable(const MotionCheck& check) {
  char line[160];
  std::snprintf(line, sizeof(line), "frames %zu, with a hand %zu (compared)\n", check.frames, check.compared);
  std::string text = line;
  const auto row = [&](const char* name, const std::optional<MotionDifference>& d) {
    if (!d.has_value()) return;
    std::snprintf(line, sizeof(line), "%-5s keypoints read back: max %.4f mm, mean %.4f mm from the estimate's\n", name,
                  d->max_mm, d->mean_mm);
    text += line;
  };
  row("bvh", check.bvh);
  row("gltf", check.gltf);
  return text;
}

}  // namespace nphand
