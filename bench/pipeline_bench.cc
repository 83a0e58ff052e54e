// Google Benchmark of the estimator's stages that need no database: skin segmentation of a
// 640x480 camera-like frame, the picture within it, the forearm cut, the descriptor of the
// hand's crop, and the temporal prior over K = 500 hypotheses. The whole path, search
// included, is `nphand bench pipeline`; the search alone is index_bench. OpenCV runs on one
// thread, as there.
#include <benchmark/benchmark.h>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>

#include "nphand/estimate/estimator.h"
#include "nphand/features/descriptor.h"
#include "nphand/segment/forearm.h"
#include "nphand/segment/picture.h"
#include "nphand/segment/skin.h"
#include "nphand/sequence/sequence.h"
#include "nphand/util/check.h"
#include "nphand/util/random.h"

namespace nphand {
namespace {

// A camera-like frame midway through a rendered sequence, with a face beside the hand or not.
const SequenceFrame& Frame(bool face = false) {
  auto render = [](bool with_face) {
    static const HandModel hand = HandModel::Load(Handedness::kRight);
    SequenceOptions options;
    options.background = BackgroundKind::kClutter;
    options.face = with_face;
    options.seed = 3;
    Sequence sequence(hand, options);
    return sequence.Render(options.frames / 2);
  };
  if (face) {
    static const SequenceFrame with = render(true);
    return with;
  }
  static const SequenceFrame without = render(false);
  return without;
}

SkinOptions NoFaces() {
  SkinOptions options;
  options.face_cascade.clear();
  return options;
}

// With and without skin's rim (SkinOptions::rim_area).
void BM_SkinSegment(benchmark::State& state) {
  SkinOptions options = NoFaces();
  if (state.range(0) == 0) options.rim_area = 0.0;
  SkinSegmenter segmenter(options);
  for (auto _ : state) benchmark::DoNotOptimize(segmenter.Segment(Frame().rgb).regions.size());
}
BENCHMARK(BM_SkinSegment)->ArgName("rim")->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);

// A frame with a face in view, looked for once and followed since, without and with the face's
// chroma gate (SkinOptions::face_chroma), which classifies the frame's skin a second time.
void BM_SkinSegmentBesideAFace(benchmark::State& state) {
  const SequenceFrame& frame = Frame(true);
  SkinOptions options;
  options.face_interval = 1000000;
  options.face_chroma = state.range(0) == 0 ? 0.0 : SkinOptions{}.face_chroma;
  SkinSegmenter segmenter(options);
  NPHAND_THROW_CHECK(segmenter.Segment(frame.rgb).faces.size() == 1, "the benchmark's frame must show its face");
  for (auto _ : state) benchmark::DoNotOptimize(segmenter.Segment(frame.rgb).regions.size());
}
BENCHMARK(BM_SkinSegmentBesideAFace)->ArgName("face_chroma")->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);

void BM_FaceCascade(benchmark::State& state) {
  SkinOptions options;
  options.face_interval = 1;
  SkinSegmenter segmenter(options);
  for (auto _ : state) benchmark::DoNotOptimize(segmenter.Segment(Frame().rgb).faces.size());
}
BENCHMARK(BM_FaceCascade)->Unit(benchmark::kMicrosecond);

void BM_ForearmCut(benchmark::State& state) {
  SkinSegmenter segmenter(NoFaces());
  const SkinSegmentation s = segmenter.Segment(Frame().rgb);
  const cv::Mat region = s.RegionMask(s.regions.at(0));
  for (auto _ : state) benchmark::DoNotOptimize(CutForearm(region, 0).cut);
}
BENCHMARK(BM_ForearmCut)->Unit(benchmark::kMicrosecond);

// The picture within the frame: a camera's frame has no bars (arg 0), a pillarboxed one
// has (arg 1: the frame's outer eighths black).
void BM_PictureOf(benchmark::State& state) {
  cv::Mat frame = Frame().rgb.clone();
  if (state.range(0) == 1) {
    frame.colRange(0, frame.cols / 8).setTo(cv::Scalar::all(0));
    frame.colRange(frame.cols - frame.cols / 8, frame.cols).setTo(cv::Scalar::all(0));
  }
  for (auto _ : state) benchmark::DoNotOptimize(PictureOf(frame).area());
}
BENCHMARK(BM_PictureOf)->ArgName("bars")->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);

void BM_Describe(benchmark::State& state) {
  const cv::Mat hand = Frame().labels == static_cast<int>(PixelLabel::kHand);
  const cv::Rect box = cv::boundingRect(hand);
  const cv::Mat roi = hand(box);
  const DescriptorConfig config;
  for (auto _ : state) benchmark::DoNotOptimize(Describe(roi, config)->values.data());
}
BENCHMARK(BM_Describe)->Unit(benchmark::kMicrosecond);

void BM_CombineWithPrior(benchmark::State& state) {
  Random random(1);
  std::vector<PoseX> poses(500);
  std::vector<double> weights(500, 1.0 / 500);
  for (PoseX& x : poses) {
    for (int i = 0; i < x.size(); ++i) x[i] = random.Uniform(-1.0, 1.0);
  }
  std::vector<WeightedPose> carried;
  for (int i = 0; i < state.range(0); ++i) carried.push_back({poses[i * 7], 1.0 / state.range(0), {}});
  const EstimatorOptions options;
  bool used = false;
  for (auto _ : state) benchmark::DoNotOptimize(CombineWithPrior(poses, weights, carried, options, &used).data());
}
BENCHMARK(BM_CombineWithPrior)->Arg(5)->Arg(20)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace nphand

int main(int argc, char** argv) {
  cv::setNumThreads(1);
  nphand::Frame();  // rendered once, before any timing
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
