// Google Benchmark of the render stage: skinning, label images and full images.
#include <numbers>

#include <benchmark/benchmark.h>

#include "nphand/render/renderer.h"
#include "nphand/scene/viewpoint.h"

namespace nphand {
namespace {

const HandModel& Hand() {
  static const HandModel model = HandModel::Load(Handedness::kRight);
  return model;
}

Scene BenchScene(Random& random) {
  Scene scene;
  scene.hand.angles = RandomArticulation(random);
  scene.hand.camera_from_hand = CameraFromHand(RandomViewpoint(random));
  scene.wrist_in_camera = CenteredWristPosition(scene.hand.camera_from_hand, Hand().bind_centre(), 0.5);
  SceneObject ball;
  ball.spec = {ObjectShape::kSphere, {0.035, 0, 0}, 32};
  ball.hand_from_object.translation() = Eigen::Vector3d(0.09, 0.0, -0.05);
  scene.objects = {ball};
  return scene;
}

void BM_Skin(benchmark::State& state) {
  Random random(1);
  const Scene scene = BenchScene(random);
  std::vector<Eigen::Vector3f> vertices, normals;
  for (auto _ : state) {
    Hand().Skin(scene.hand, &vertices, &normals);
    benchmark::DoNotOptimize(vertices.data());
  }
}
BENCHMARK(BM_Skin);

void BM_RenderLabels(benchmark::State& state) {
  const int size = static_cast<int>(state.range(0));
  const Intrinsics camera = Intrinsics::FromFieldOfView(size, size, 30.0 * std::numbers::pi / 180.0);
  Random random(1);
  std::vector<Scene> scenes;
  for (int i = 0; i < 64; ++i) scenes.push_back(BenchScene(random));
  Renderer renderer(Hand());
  cv::Mat labels;
  size_t i = 0;
  for (auto _ : state) {
    renderer.RenderLabels(scenes[i++ % scenes.size()], camera, &labels);
    benchmark::DoNotOptimize(labels.data);
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_RenderLabels)->Arg(64)->Arg(128)->Arg(256);

void BM_RenderFull(benchmark::State& state) {
  const Intrinsics camera = Intrinsics::FromFieldOfView(512, 512, 30.0 * std::numbers::pi / 180.0);
  Random random(1);
  const Scene scene = BenchScene(random);
  Renderer renderer(Hand());
  for (auto _ : state) benchmark::DoNotOptimize(renderer.Render(scene, camera).rgb.data);
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_RenderFull);

}  // namespace
}  // namespace nphand

BENCHMARK_MAIN();
