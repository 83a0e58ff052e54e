#include "apps/bench_command.h"

#include <chrono>
#include <numbers>

#include "nphand/render/renderer.h"
#include "nphand/scene/viewpoint.h"
#include "nphand/util/check.h"
#include "nphand/util/random.h"
#include "nphand/util/system.h"

namespace nphand {
namespace {

std::vector<Scene> BenchScenes(const HandModel& model, int count, uint64_t seed) {
  Random random(seed);
  SceneObject ball;
  ball.spec = {ObjectShape::kSphere, {0.035, 0.0, 0.0}, 32};
  ball.hand_from_object.translation() = Eigen::Vector3d(0.09, 0.0, -0.05);
  std::vector<Scene> scenes(count);
  for (Scene& scene : scenes) {
    scene.hand.angles = RandomArticulation(random);
    scene.hand.camera_from_hand = CameraFromHand(RandomViewpoint(random));
    scene.wrist_in_camera = CenteredWristPosition(scene.hand.camera_from_hand, model.bind_centre(), 0.5);
    scene.objects = {ball};
  }
  return scenes;
}

}  // namespace

bool BenchRenderOptions::Check(std::string* why) const {
  if (images < 1 || size < 8 || size > 4096) {
    *why = "bench render needs at least 1 image and a size between 8 and 4096";
    return false;
  }
  return true;
}

nlohmann::json RunBenchRender(const BenchRenderOptions& options) {
  std::string why;
  NPHAND_THROW_CHECK(options.Check(&why), "bench render: ", why);
  const HandModel model = HandModel::Load(Handedness::kRight, options.asset_dir);
  const Intrinsics intrinsics = Intrinsics::FromFieldOfView(options.size, options.size, 30.0 * std::numbers::pi / 180.0);
  const std::vector<Scene> scenes = BenchScenes(model, options.images, options.seed);
  Renderer renderer(model);
  cv::Mat labels;
  uint64_t hand_pixels = 0;
  for (int i = 0; i < std::max(1, options.images / 10); ++i) renderer.RenderLabels(scenes[i], intrinsics, &labels);

  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  for (const Scene& scene : scenes) {
    renderer.RenderLabels(scene, intrinsics, &labels);
    hand_pixels += static_cast<uint64_t>(cv::countNonZero(labels == static_cast<int>(PixelLabel::kHand)));
  }
  const double label_seconds = std::chrono::duration<double>(Clock::now() - start).count();

  const int full_count = std::max(1, options.images / 4);
  const auto full_start = Clock::now();
  for (int i = 0; i < full_count; ++i) renderer.Render(scenes[i], intrinsics);
  const double full_seconds = std::chrono::duration<double>(Clock::now() - full_start).count();

  return {
      {"label_images_per_s", options.images / label_seconds},
      {"full_images_per_s", full_count / full_seconds},
      {"width", options.size},
      {"height", options.size},
      {"images", options.images},
      {"seconds", label_seconds},
      {"mean_hand_pixels", static_cast<double>(hand_pixels) / options.images},
      {"hand_triangles", renderer.HandTriangleCount()},
      {"object_triangles", renderer.ObjectTriangleCount(scenes.front())},
      {"threads", 1},
      {"machine", MachineDescription()},
  };
}

}  // namespace nphand
