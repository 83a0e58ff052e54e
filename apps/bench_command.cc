#include "apps/bench_command.h"

#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <numbers>
#include <optional>

#include <opencv2/core/utility.hpp>

#include "apps/index_command.h"
#include "nphand/estimate/estimator.h"
#include "nphand/index/backends.h"
#include "nphand/render/renderer.h"
#include "nphand/sequence/sequence.h"
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

double PeakRssMb() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_maxrss / 1024.0;  // Linux reports kilobytes
}

nlohmann::json Stage(std::vector<double> ms) {
  std::sort(ms.begin(), ms.end());
  double sum = 0.0;
  for (double v : ms) sum += v;
  return {{"median", ms[ms.size() / 2]}, {"mean", sum / ms.size()}, {"p95", ms[ms.size() * 95 / 100]}};
}

}  // namespace

bool BenchPipelineOptions::Check(std::string* why) const {
  if (frames < 1 || frames > 1000000 || width < 64 || height < 64 || width > 4096 || height > 4096 || k < 1 ||
      threads < 1 || threads > 256) {
    *why = "bench pipeline needs at least 1 frame, a frame size of 64..4096 a side, k >= 1 and 1..256 threads";
    return false;
  }
  return true;
}

nlohmann::json RunBenchPipeline(const BenchPipelineOptions& options) {
  std::string why;
  NPHAND_THROW_CHECK(options.Check(&why), "bench pipeline: ", why);
  // OpenCV's thread count is process-wide: set for the run, then given back.
  const int opencv_threads = cv::getNumThreads();
  cv::setNumThreads(options.threads);
  struct Restore {
    int threads;
    ~Restore() { cv::setNumThreads(threads); }
  } restore{opencv_threads};
  const OpenedFiles files(options);
  const Database& db = files.db;
  const KnnIndex& index = *files.index;
  const HandModel& hand = files.hand;
  EstimatorOptions estimator_options;
  estimator_options.k = options.k;
  estimator_options.track_views = options.track_views;
  SetHandChoice(options.hand, &estimator_options);
  estimator_options.refine = options.refine;
  estimator_options.tilts_deg = options.tilts_deg;
  Estimator estimator(db, index, hand, estimator_options);
  const double rss_loaded = PeakRssMb();

  // Frames come from rendered sequences, one at a time (rendering is not timed).
  constexpr int kWarmUp = 30;
  constexpr int kPerSequence = 60;
  std::vector<double> segment, describe, search, weigh, refine, place, total;
  int detected = 0;
  std::optional<Sequence> sequence;
  for (int i = 0; i < kWarmUp + options.frames; ++i) {
    if (i % kPerSequence == 0) {
      SequenceOptions s;
      s.frames = kPerSequence;
      s.width = options.width;
      s.height = options.height;
      s.seed = options.seed + static_cast<uint64_t>(i / kPerSequence);
      s.face = options.face;
      sequence.emplace(hand, s);
      estimator.Reset();
    }
    const SequenceFrame frame = sequence->Render(i % kPerSequence);
    const FrameResult r = estimator.Process(frame.rgb, frame.time_s);
    if (i < kWarmUp) continue;
    detected += r.detected();
    segment.push_back(r.ms.segment);
    describe.push_back(r.ms.describe);
    search.push_back(r.ms.search);
    weigh.push_back(r.ms.weigh);
    refine.push_back(r.ms.refine);
    place.push_back(r.ms.place);
    total.push_back(r.ms.total);
  }
  double total_ms = 0.0;
  for (double v : total) total_ms += v;
  return {
      {"fps", 1000.0 * options.frames / total_ms},
      {"ms", {{"segment", Stage(segment)}, {"describe", Stage(describe)}, {"search", Stage(search)},
              {"weigh", Stage(weigh)}, {"refine", Stage(refine)}, {"place", Stage(place)}, {"total", Stage(total)}}},
      {"frames", options.frames},
      {"detected", detected},
      {"width", options.width},
      {"height", options.height},
      {"db_entries", db.size()},
      {"db_file_mb", db.file_bytes() / 1e6},
      {"backend", index.Backend()},
      {"index_mb", index.MemoryBytes() / 1e6},
      {"k", options.k},
      {"track_views", options.track_views},
      {"refine", options.refine},
      {"tilts_deg", options.tilts_deg},
      {"face", options.face},
      {"hand", options.hand},
      {"peak_rss_mb", PeakRssMb()},
      {"rss_after_load_mb", rss_loaded},
      {"threads", options.threads},
      {"machine", MachineDescription()},
  };
}

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
