#include "nphand/eval/pose_study.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>

#include <opencv2/imgproc.hpp>

#include "nphand/eval/measures.h"
#include "nphand/eval/pose_methods.h"
#include "nphand/index/exact_index.h"
#include "nphand/util/check.h"
#include "nphand/util/progress.h"
#include "nphand/util/random.h"

namespace nphand {
namespace {

using Clock = std::chrono::steady_clock;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// One method's per-frame figures, gathered before they are summed.
struct FrameFigures {
  bool detected = false;
  double pose_error = 0.0, keypoint_mm = 0.0, pa_mpjpe_mm = 0.0, joint_deg = 0.0, wrist_deg = 0.0, keypoint_px = kNaN;
  std::vector<double> distances;
  Keypoints3d estimate{}, truth{};
  double ms = 0.0;
};

MethodScore Summarise(const std::string& method, const std::string& sequence, double alpha,
                      const std::vector<std::vector<FrameFigures>>& runs, const std::vector<std::vector<bool>>& no_hand) {
  MethodScore s;
  s.method = method;
  s.sequence = sequence;
  s.alpha = alpha;
  std::vector<double> ms;
  double px = 0.0;
  int px_frames = 0;
  RunJitter jitter, truth_jitter;
  LagMeter lag;
  for (const std::vector<FrameFigures>& frames : runs) {
    lag.Restart();
    std::vector<Keypoints3d> run_estimate, run_truth;
    auto close_run = [&]() {
      jitter.Add(run_estimate);
      truth_jitter.Add(run_truth);
      run_estimate.clear();
      run_truth.clear();
    };
    for (const FrameFigures& f : frames) {
      ++s.frames;
      ms.push_back(f.ms);
      lag.Add(f.truth, f.detected ? &f.estimate : nullptr);
      if (!f.detected) {
        close_run();
        continue;
      }
      ++s.detected;
      s.pose_error += f.pose_error;
      s.keypoint_mm += f.keypoint_mm;
      s.pa_mpjpe_mm += f.pa_mpjpe_mm;
      s.joint_deg += f.joint_deg;
      s.wrist_deg += f.wrist_deg;
      s.turned += f.wrist_deg >= kTurnedDeg;
      if (!std::isnan(f.keypoint_px)) {
        px += f.keypoint_px;
        ++px_frames;
      }
      s.distances.insert(s.distances.end(), f.distances.begin(), f.distances.end());
      run_estimate.push_back(f.estimate);
      run_truth.push_back(f.truth);
    }
    close_run();
  }
  if (s.detected > 0) {
    for (double* v : {&s.pose_error, &s.keypoint_mm, &s.pa_mpjpe_mm, &s.joint_deg, &s.wrist_deg}) *v /= s.detected;
  }
  s.keypoint_px = px_frames > 0 ? px / px_frames : kNaN;
  s.within_20mm = FractionWithin(s.distances, 0.020);
  s.auc_0_50 = AreaUnderCurve(s.distances, 0.050);
  s.jitter_mm = jitter.empty() ? kNaN : 1000.0 * jitter.mean();
  s.truth_jitter_mm = truth_jitter.empty() ? kNaN : 1000.0 * truth_jitter.mean();
  s.lag_frames = lag.Lag();
  s.ms_median = Median(ms);
  for (const std::vector<bool>& found : no_hand) {
    s.no_hand_frames += static_cast<int>(found.size());
    s.false_detections += static_cast<int>(std::count(found.begin(), found.end(), true));
  }
  return s;
}

}  // namespace

std::vector<StudySequence> TestSequences(int frames, int width, int height, uint64_t seed, bool adult_arm) {
  struct Plan {
    const char* name;
    int grasp;
    double object_scale;
    ForearmKind forearm;
    BackgroundKind background;
    const char* skin;
    bool face;
  };
  // Objects the database lacks: its sizes scaled by 0.8 or 1.25 (the database's spheres
  // have radii 0.5-4 cm, none 3.2; its box for grasp 18 is 12 x 12 x 2.5 cm).
  const std::vector<Plan> plans = {
      {"box", 18, 1.25, ForearmKind::kBare, BackgroundKind::kTexture, "light", false},       // a 15 x 15 x 3 cm book
      {"ball", 11, 0.8, ForearmKind::kBare, BackgroundKind::kClutter, "olive", false},        // a 6.4 cm ball
      {"bottle", 1, 0.8, ForearmKind::kSleeved, BackgroundKind::kPlain, "brown", false},     // a 6.4 cm bottle
      {"lid", 10, 1.25, ForearmKind::kBare, BackgroundKind::kTexture, "medium", true},       // a 12.5 cm lid, a face beside
      {"pen", 20, 1.25, ForearmKind::kBare, BackgroundKind::kClutter, "dark", false}};       // a writing tripod on a pen
  std::vector<StudySequence> out;
  for (size_t i = 0; i < plans.size(); ++i) {
    StudySequence s;
    s.name = plans[i].name;
    s.options.frames = frames;
    s.options.width = width;
    s.options.height = height;
    s.options.grasp = plans[i].grasp;
    s.options.object_scale = plans[i].object_scale;
    s.options.forearm = plans[i].forearm;
    s.options.background = plans[i].background;
    s.options.skin = plans[i].skin;
    s.options.face = plans[i].face;
    s.options.seed = seed + i;
    s.options.adult_arm = adult_arm;
    out.push_back(s);
  }
  return out;
}

std::vector<StudySequence> RobustnessSequences(int frames, int width, int height, uint64_t seed, bool adult_arm) {
  StudySequence base;
  base.name = "base";
  base.options.frames = frames;
  base.options.width = width;
  base.options.height = height;
  base.options.grasp = 11;
  base.options.object_scale = 0.8;
  base.options.forearm = ForearmKind::kBare;
  base.options.background = BackgroundKind::kPlain;
  base.options.skin = "medium";
  base.options.seed = seed;
  base.options.adult_arm = adult_arm;
  std::vector<StudySequence> out = {base};
  auto variant = [&](const char* name, auto change) {
    StudySequence s = base;
    s.name = name;
    change(s);
    out.push_back(s);
  };
  variant("skin dark", [](StudySequence& s) { s.options.skin = "dark"; });
  variant("skin light", [](StudySequence& s) { s.options.skin = "light"; });
  variant("textured background", [](StudySequence& s) { s.options.background = BackgroundKind::kTexture; });
  variant("sleeve", [](StudySequence& s) { s.options.forearm = ForearmKind::kSleeved; });
  variant("hand 10% longer, narrower", [](StudySequence& s) {
    s.length = 1.1;
    s.width = 0.9;
  });
  return out;
}

std::vector<RenderedSequence> RenderSequences(const HandModel& hand, const std::vector<StudySequence>& sequences,
                                              std::ostream* progress) {
  uint64_t total = 0;
  for (const StudySequence& s : sequences) total += static_cast<uint64_t>(s.options.frames);
  ProgressLine line(progress, "rendering test sequences", total, "frames");
  std::vector<RenderedSequence> out;
  uint64_t done = 0;
  for (const StudySequence& s : sequences) {
    const HandModel proportioned = hand.Reproportioned(s.length, s.width);
    Sequence sequence(proportioned, s.options);
    RenderedSequence r{s, {}, {}};
    for (int i = 0; i < sequence.size(); ++i) {
      StudyFrame f;
      f.truth = sequence.Render(i);
      f.hand_mask = f.truth.labels == static_cast<int>(PixelLabel::kHand);
      f.intrinsics = sequence.intrinsics();
      f.hand_length_m = sequence.hand_length_m();
      if (i % 10 == 0) {
        StudyFrame empty;
        empty.truth.index = i;
        empty.truth.time_s = f.truth.time_s;
        empty.truth.rgb = sequence.RenderEmpty(i);
        empty.hand_mask = cv::Mat::zeros(f.hand_mask.size(), CV_8UC1);
        empty.intrinsics = f.intrinsics;
        empty.hand_length_m = f.hand_length_m;
        r.empty_frames.push_back(std::move(empty));
      }
      r.frames.push_back(std::move(f));
      line.Update(++done);
    }
    out.push_back(std::move(r));
  }
  line.Finish();
  return out;
}

cv::Mat SegmentationNoise(const cv::Mat& mask, double alpha_percent, uint64_t seed) {
  NPHAND_THROW_CHECK(!mask.empty() && mask.type() == CV_8UC1, "segmentation noise: the mask must be 8-bit single-channel");
  NPHAND_THROW_CHECK(std::isfinite(alpha_percent) && alpha_percent >= 0.0 && alpha_percent <= 100.0,
                     "segmentation noise: alpha must be within [0, 100] percent");
  cv::Mat out = (mask != 0);
  if (alpha_percent == 0.0) return out;
  std::vector<cv::Point> pixels;
  cv::findNonZero(out, pixels);
  const size_t remove = static_cast<size_t>(std::llround(alpha_percent / 100.0 * static_cast<double>(pixels.size())));
  Random random(seed);
  for (size_t i = 0; i < remove; ++i) {
    std::swap(pixels[i], pixels[i + random.UniformIndex(pixels.size() - i)]);
    out.at<uint8_t>(pixels[i]) = 0;
  }
  const cv::Mat kernel = cv::getStructuringElement(cv::MORPH_RECT, cv::Size(3, 3));
  cv::erode(out, out, kernel);
  cv::dilate(out, out, kernel);
  return out;
}

std::vector<MethodScore> RunMethods(std::vector<std::unique_ptr<PoseMethod>>& methods,
                                    const std::vector<RenderedSequence>& sequences, const std::vector<double>& alphas,
                                    const HandModel& hand, uint64_t noise_seed, std::ostream* progress) {
  const double model_length = HandLength(hand.KeypointsOf(HandPose{}));
  uint64_t total = 0, frames = 0;
  for (const RenderedSequence& s : sequences) frames += s.frames.size();
  for (double alpha : alphas) {
    for (const auto& m : methods) total += (alpha == 0.0 || !m->FromRgb()) ? frames : 0;
  }
  ProgressLine line(progress, "methods", total, "frames");
  uint64_t done = 0;
  std::vector<MethodScore> scores;
  for (size_t a = 0; a < alphas.size(); ++a) {
    const double alpha = alphas[a];
    // The same noisy masks for every method.
    std::vector<std::vector<cv::Mat>> masks(sequences.size());
    for (size_t s = 0; s < sequences.size(); ++s) {
      for (size_t i = 0; i < sequences[s].frames.size(); ++i) {
        masks[s].push_back(SegmentationNoise(sequences[s].frames[i].hand_mask, alpha,
                                             noise_seed + 1000003 * a + 1009 * s + i));
      }
    }
    for (const auto& method : methods) {
      if (alpha != 0.0 && method->FromRgb()) continue;
      std::vector<std::vector<FrameFigures>> runs(sequences.size());
      std::vector<std::vector<bool>> no_hand(sequences.size());
      for (size_t s = 0; s < sequences.size(); ++s) {
        method->Reset();
        for (size_t i = 0; i < sequences[s].frames.size(); ++i) {
          const StudyFrame& frame = sequences[s].frames[i];
          const Clock::time_point start = Clock::now();
          const MethodEstimate e = method->Estimate(frame, masks[s][i]);
          FrameFigures f;
          f.ms = std::chrono::duration<double, std::milli>(Clock::now() - start).count();
          f.detected = e.detected;
          f.truth = frame.truth.keypoints;
          if (e.detected) {
            const HandPose& truth = frame.truth.pose;
            f.pose_error = (ToPoseVector(e.pose) - ToPoseVector(truth)).norm();
            f.estimate = e.keypoints_hand.has_value() ? *e.keypoints_hand : hand.KeypointsOf(e.pose);
            for (Eigen::Vector3d& k : f.estimate) k *= frame.hand_length_m / model_length;
            f.distances = RootRelativeDistances(f.estimate, f.truth);
            f.keypoint_mm = 1000.0 * RootRelativeError(f.estimate, f.truth);
            f.pa_mpjpe_mm = 1000.0 * ProcrustesError(f.estimate, f.truth);
            for (int d = 0; d < kNumDofs; ++d) f.joint_deg += std::abs(e.pose.angles[d] - truth.angles[d]);
            f.joint_deg *= 180.0 / std::numbers::pi / kNumDofs;
            f.wrist_deg = RotationAngleDeg(e.pose.camera_from_hand, truth.camera_from_hand);
            if (e.keypoints_2d) {
              f.keypoint_px = 0.0;
              for (int k = 0; k < kNumKeypoints; ++k) f.keypoint_px += ((*e.keypoints_2d)[k] - frame.truth.keypoints_2d[k]).norm();
              f.keypoint_px /= kNumKeypoints;
            }
          }
          runs[s].push_back(std::move(f));
          line.Update(++done);
        }
        if (method->FromRgb()) {
          method->Reset();
          for (const StudyFrame& empty : sequences[s].empty_frames) {
            no_hand[s].push_back(method->Estimate(empty, empty.hand_mask).detected);
          }
        }
      }
      scores.push_back(Summarise(method->Name(), "all", alpha, runs, no_hand));
      for (size_t s = 0; s < sequences.size(); ++s) {
        scores.push_back(Summarise(method->Name(), sequences[s].sequence.name, alpha, {runs[s]}, {no_hand[s]}));
      }
    }
  }
  line.Finish();
  // Fig. 6's normalisation: by the NN-pose bound on the same frames.
  for (MethodScore& s : scores) {
    s.pose_error_norm = s.keypoint_norm = kNaN;
    for (const MethodScore& bound : scores) {
      if (bound.method == "NN pose" && bound.sequence == s.sequence && bound.alpha == s.alpha && bound.detected > 0) {
        s.pose_error_norm = s.pose_error / bound.pose_error;
        s.keypoint_norm = s.keypoint_mm / bound.keypoint_mm;
      }
    }
  }
  return scores;
}

nlohmann::json DescribeSequences(const std::vector<RenderedSequence>& sequences) {
  nlohmann::json out = nlohmann::json::array();
  for (const RenderedSequence& r : sequences) {
    const SequenceOptions& o = r.sequence.options;
    out.push_back({{"name", r.sequence.name},
                   {"seed", o.seed},
                   {"frames", o.frames},
                   {"size", {o.width, o.height}},
                   {"grasp", o.grasp},
                   {"object_scale", o.object_scale},
                   {"forearm", ToString(o.forearm)},
                   {"adult_arm", o.adult_arm},
                   {"background", ToString(o.background)},
                   {"skin", o.skin},
                   {"face", o.face},
                   {"hand_length_factor", r.sequence.length},
                   {"hand_width_factor", r.sequence.width}});
  }
  return out;
}
std::string ToString(PoseStudyPart part) {
  switch (part) {
    case PoseStudyPart::kBaselines:
      return "baselines";
    case PoseStudyPart::kNoise:
      return "noise";
    case PoseStudyPart::kRobustness:
      return "robustness";
  }
  return "?";
}

bool PoseStudyOptions::Check(std::string* why) const {
  if (frames < 3 || frames > 10000) {
    *why = "frames must be within 3..10000";
  } else if (width < 64 || height < 64 || width > 4096 || height > 4096) {
    *why = "the frame size must be within 64..4096 pixels a side";
  } else if (alphas.empty() || std::any_of(alphas.begin(), alphas.end(), [](double a) { return !(a >= 0.0 && a <= 100.0); })) {
    *why = "alphas must be given, each within [0, 100] percent";
  } else if (lsq_rows < 2 || gp_rows < 2 || rvm_rows < 2) {
    *why = "each regression needs at least 2 rows";
  } else {
    return true;
  }
  return false;
}

PoseStudyResult RunPoseStudy(PoseStudyPart part, const Database& db, const KnnIndex& index, const HandModel& hand,
                             const EstimatorOptions& options_base, const PoseStudyOptions& options, std::ostream* progress) {
  std::string why;
  NPHAND_THROW_CHECK(options.Check(&why), "eval ", ToString(part), ": ", why);
  const Clock::time_point start = Clock::now();
  PoseStudyResult result;
  result.part = ToString(part);
  const std::vector<RenderedSequence> sequences = RenderSequences(
      hand,
      part == PoseStudyPart::kRobustness
          ? RobustnessSequences(options.frames, options.width, options.height, options.seed + 100, options.adult_arm)
          : TestSequences(options.frames, options.width, options.height, options.seed, options.adult_arm),
      progress);
  result.sequences = DescribeSequences(sequences);

  // The paper's PNP: each frame's estimate as it comes, unsmoothed (nphand's default,
  // smoothed, has rows of its own), the estimate the mode's mean about the best (as
  // nphand's default; the paper's is the best alone, `mode_mean` 0). NN feature is the
  // paper's: the nearest neighbour in feature space, alone.
  EstimatorOptions pnp = options_base;
  pnp.hand_length_m = ModelHandLength(db);
  pnp.smooth = false;
  EstimatorOptions nn_feature = pnp;
  nn_feature.prior = PriorCombination::kNone;
  nn_feature.mode_mean = 0.0;
  std::unique_ptr<KnnIndex> exact;
  std::vector<std::unique_ptr<PoseMethod>> methods;
  if (options.exact && part != PoseStudyPart::kRobustness) {
    exact = std::make_unique<ExactIndex>(DatabaseDescriptors(db));
    methods.push_back(MakeEstimatorMethod("PNP exact", db, *exact, hand, pnp, false));
  }
  EstimatorOptions refined = pnp;
  refined.refine = true;
  EstimatorOptions smoothed = pnp;
  smoothed.smooth = true;
  EstimatorOptions both = refined;
  both.smooth = true;
  // The hand's proportions measured too: for the robustness study's hand unlike the model.
  EstimatorOptions proportioned = refined;
  proportioned.refinement.move_proportions = true;
  methods.push_back(MakeEstimatorMethod("PNP", db, index, hand, pnp, false));
  methods.push_back(MakeEstimatorMethod("PNP + refine", db, index, hand, refined, false));
  if (part == PoseStudyPart::kRobustness) {
    methods.push_back(MakeEstimatorMethod("PNP + refine + proportions", db, index, hand, proportioned, false));
  }
  methods.push_back(MakeEstimatorMethod("PNP + smooth", db, index, hand, smoothed, false));
  methods.push_back(MakeEstimatorMethod("PNP RGB", db, index, hand, pnp, true));
  methods.push_back(MakeEstimatorMethod("PNP RGB + refine", db, index, hand, refined, true));
  if (part == PoseStudyPart::kRobustness) {
    methods.push_back(MakeEstimatorMethod("PNP RGB + refine + proportions", db, index, hand, proportioned, true));
  }
  methods.push_back(MakeEstimatorMethod("PNP RGB + smooth", db, index, hand, smoothed, true));
  methods.push_back(MakeEstimatorMethod("PNP RGB + refine + smooth", db, index, hand, both, true));
  methods.push_back(MakeEstimatorMethod("NN feature", db, index, hand, nn_feature, false));
  methods.push_back(MakeNearestPoseMethod(db));
  if (part != PoseStudyPart::kRobustness) {
    methods.push_back(MakeMeanPoseMethod(db));
    methods.push_back(MakeRegressionMethod(db, MakeLinearRegressor(), options.lsq_rows, options.fit_seed, progress));
    methods.push_back(MakeRegressionMethod(db, MakeGaussianProcess(), options.gp_rows, options.fit_seed, progress));
    methods.push_back(MakeRegressionMethod(db, MakeRvm(), options.rvm_rows, options.fit_seed, progress));
  }
  result.methods = nlohmann::json::object();
  for (const auto& m : methods) result.methods[m->Name()] = m->Describe();
  const std::vector<double> alphas = part == PoseStudyPart::kNoise ? options.alphas : std::vector<double>{0.0};
  result.scores = RunMethods(methods, sequences, alphas, hand, options.seed ^ 0x9e3779b97f4a7c15ULL, progress);
  result.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  return result;
}

PoseStudyResult BaselinesOf(const PoseStudyResult& noise) {
  PoseStudyResult out = noise;
  out.part = ToString(PoseStudyPart::kBaselines);
  out.scores.clear();
  for (const MethodScore& s : noise.scores) {
    if (s.alpha == 0.0) out.scores.push_back(s);
  }
  return out;
}

}  // namespace nphand
