#include "nphand/eval/estimator_study.h"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <numbers>
#include <sstream>

#include "nphand/eval/measures.h"
#include "nphand/sequence/sequence.h"
#include "nphand/util/check.h"
#include "nphand/util/progress.h"

namespace nphand {

std::vector<EstimatorSetting> EstimatorSweep(const EstimatorOptions& base) {
  std::vector<EstimatorSetting> out;
  EstimatorOptions nn = base;
  nn.prior = PriorCombination::kNone;
  out.push_back({"nn", nn});
  struct Observation {
    std::string name;
    ObservationWeight weight;
    double sigma_y;
  };
  const std::vector<Observation> observations = {
      {"adaptive", ObservationWeight::kAdaptive, base.sigma_y},
      {"fixed0.03", ObservationWeight::kFixed, 0.03},
      {"fixed0.1", ObservationWeight::kFixed, 0.1},
      {"fixed0.2", ObservationWeight::kFixed, 0.2}};
  for (const Observation& o : observations) {
    for (double sigma_x : {0.25, 0.5, 1.0}) {
      EstimatorOptions e = base;
      e.observation = o.weight;
      e.sigma_y = o.sigma_y;
      e.prior = PriorCombination::kProduct;
      e.sigma_x = sigma_x;
      std::ostringstream name;
      name << o.name << "-product" << sigma_x;
      out.push_back({name.str(), e});
    }
    EstimatorOptions e = base;
    e.observation = o.weight;
    e.sigma_y = o.sigma_y;
    e.prior = PriorCombination::kSum;
    e.sigma_x = 0.5;
    out.push_back({o.name + "-sum0.5", e});
  }
  // The default (the product) with one thing changed.
  auto around_default = [&](const std::string& name, const auto& change) {
    EstimatorOptions e = base;
    e.prior = PriorCombination::kProduct;
    change(e);
    out.push_back({name, e});
  };
  // The carried hypotheses one per mode in a track's first frames (all its frames: 100000).
  for (int frames : {10, 30, 100000}) {
    around_default("carry-apart" + std::to_string(frames), [&](EstimatorOptions& e) { e.carry_apart_frames = frames; });
  }
  for (int carried : {20, 100}) {
    around_default("carried" + std::to_string(carried), [&](EstimatorOptions& e) { e.carried = carried; });
  }
  // A track let go where the frames' nearest view lies outside its mode, clearly nearer, for
  // this many frames in a row.
  for (int frames : {3, 5, 10}) {
    for (double margin : {0.05, 0.1}) {
      std::ostringstream name;
      name << "reset" << frames << "-m" << margin;
      around_default(name.str(), [&](EstimatorOptions& e) {
        e.prior_reset_frames = frames;
        e.prior_reset_margin = margin;
      });
    }
  }
  // The estimate as the mode's weighted mean: how far from the best its hypotheses may lie
  // (0: the best alone).
  for (double reach : {0.0, 0.25, 0.5, 1.0, 1.5, 2.0}) {
    std::ostringstream name;
    name << "mode-mean" << reach;
    around_default(name.str(), [&](EstimatorOptions& e) { e.mode_mean = reach; });
  }
  // How often the half-turned crop is searched too (its cost: a second descriptor and search).
  for (double ambiguity : {0.0, 0.15, 0.3}) {
    std::ostringstream name;
    name << "turns" << ambiguity;
    around_default(name.str(), [&](EstimatorOptions& e) { e.roll_ambiguity = ambiguity; });
  }
  // How long an arm must be (in its widths) unless it enters from the frame's edge: shorter
  // and it is taken for fingers.
  for (double length : {1.2, 1.6, 2.0}) {
    std::ostringstream name;
    name << "arm-length" << length;
    around_default(name.str(), [&](EstimatorOptions& e) { e.forearm.min_arm_length = length; });
  }
  // How much a hand turned against the arm it was cut from weighs less.
  for (double agreement : {0.0, 2.0, 8.0, 16.0}) {
    std::ostringstream name;
    name << "arm" << agreement;
    around_default(name.str(), [&](EstimatorOptions& e) { e.arm_agreement = agreement; });
  }
  // How far the nearest view may lie before a region is "no hand".
  for (double distance : {0.85, 0.9}) {
    std::ostringstream name;
    name << "max-distance" << distance;
    around_default(name.str(), [&](EstimatorOptions& e) { e.max_distance = distance; });
  }
  // Refinement beyond the database (refine/refiner.h): its default (the place and the
  // wrist, pulled towards the last frame's), the place alone, with the fingers too (in two
  // step sizes), other pulls, finer renders and more passes.
  around_default("refine", [&](EstimatorOptions& e) { e.refine = true; });
  for (double ambiguity : {0.15, 0.3, 9.0}) {
    std::ostringstream name;
    name << "refine-turns" << ambiguity;
    around_default(name.str(), [&](EstimatorOptions& e) {
      e.refine = true;
      e.roll_ambiguity = ambiguity;
    });
  }
  around_default("refine-1turn-turns9", [&](EstimatorOptions& e) {
    e.refine = true;
    e.roll_ambiguity = 9.0;
    e.refine_both_turns = false;
  });
  around_default("refine-one-turn", [&](EstimatorOptions& e) {
    e.refine = true;
    e.refine_both_turns = false;
  });
  // Smoothing over time (estimate/smoother.h): the One Euro filter's cutoff at rest and its
  // rise with speed (the rotation's filter kept at its default) ...
  for (double cutoff : {0.5, 1.0, 2.0, 4.0}) {
    for (double beta : {0.5, 2.0, 5.0}) {
      std::ostringstream name;
      name << "smooth-c" << cutoff << "-b" << beta;
      around_default(name.str(), [&](EstimatorOptions& e) {
        e.smooth = true;
        e.smoothing.min_cutoff_hz = cutoff;
        e.smoothing.beta = beta;
      });
    }
  }
  // ... and the rotation's: its cutoff at rest, its rise with speed, its rate's cutoff and
  // its trend (`smooth-rotation-c4-b0.5-d1-t0` is the rotation as the other groups).
  struct RotationSmoothing {
    double cutoff, beta, derivative, trend;
  };
  for (const RotationSmoothing& r : std::vector<RotationSmoothing>{{4.0, 0.5, 1.0, 0.0},
                                                                   {2.0, 0.5, 1.0, 0.0},
                                                                   {2.0, 0.5, 0.5, 0.0},
                                                                   {4.0, 0.5, 0.5, 0.5},
                                                                   {3.0, 0.5, 0.5, 0.5},
                                                                   {2.0, 0.0, 0.5, 0.5},
                                                                   {2.0, 0.5, 0.5, 0.5},
                                                                   {2.0, 1.0, 0.5, 0.5},
                                                                   {2.0, 0.5, 0.25, 0.5},
                                                                   {2.0, 0.5, 0.5, 1.0},
                                                                   {1.5, 0.5, 0.5, 0.5},
                                                                   {1.0, 0.5, 0.5, 0.5}}) {
    std::ostringstream name;
    name << "smooth-rotation-c" << r.cutoff << "-b" << r.beta << "-d" << r.derivative << "-t" << r.trend;
    around_default(name.str(), [&](EstimatorOptions& e) {
      e.rotation_smoothing = {.min_cutoff_hz = r.cutoff, .beta = r.beta, .derivative_cutoff_hz = r.derivative, .trend = r.trend};
    });
  }
  around_default("refine-place", [&](EstimatorOptions& e) {
    e.refine = true;
    e.refinement.move_wrist = false;
  });
  for (double step : {4.0, 12.0}) {
    std::ostringstream name;
    name << "refine-fingers" << step;
    around_default(name.str(), [&](EstimatorOptions& e) {
      e.refine = true;
      e.refinement.move_fingers = true;
      e.refinement.joint_step_deg = step;
    });
  }
  for (double track : {0.0, 0.5, 8.0}) {
    std::ostringstream name;
    name << "refine-track" << track;
    around_default(name.str(), [&](EstimatorOptions& e) {
      e.refine = true;
      e.refinement.track = track;
    });
  }
  for (int side : {64, 128}) {
    for (int sweeps : {3, 6}) {
      if (side == RefineOptions{}.render_side && sweeps == RefineOptions{}.sweeps) continue;  // the default's
      around_default("refine-render" + std::to_string(side) + "-sweeps" + std::to_string(sweeps), [&](EstimatorOptions& e) {
        e.refine = true;
        e.refinement.render_side = side;
        e.refinement.sweeps = sweeps;
        e.refinement.halvings = sweeps > 3 ? 4 : 2;
      });
    }
  }
  for (int k : {50, 100, 250, 2000}) {
    around_default("k" + std::to_string(k), [&](EstimatorOptions& e) {
      e.k = k;
      e.carried = std::min(e.carried, k);
    });
  }
  // The track's views: none, or more viewpoints of them than the default's.
  for (int views : {0, 8}) {
    around_default("track-views" + std::to_string(views), [&](EstimatorOptions& e) { e.track_views = views; });
  }
  // The crop's tilts where the match is poor: none, other angles, other thresholds, more
  // neighbours and a fuller search of each.
  const std::vector<std::pair<std::string, std::vector<double>>> tilts = {
      {"none", {}}, {"10", {10.0}}, {"20", {20.0}}, {"30", {30.0}}, {"20-40", {20.0, 40.0}}, {"10-20-30", {10.0, 20.0, 30.0}}};
  for (const auto& tilt : tilts) {
    around_default("tilts-" + tilt.first, [&](EstimatorOptions& e) { e.tilts_deg = tilt.second; });
  }
  for (double above : {0.5, 0.55, 0.65, 0.7}) {
    std::ostringstream name;
    name << "tilt-above" << above;
    around_default(name.str(), [&](EstimatorOptions& e) { e.tilt_above = above; });
  }
  around_default("tilt-effort100", [&](EstimatorOptions& e) { e.tilt_effort = 100; });
  around_default("tilt-k500-effort500", [&](EstimatorOptions& e) {
    e.tilt_k = 500;
    e.tilt_effort = 500;
  });
  return out;
}

bool EstimatorStudyOptions::Check(std::string* why) const {
  if (sequences < 1 || sequences > 1000 || frames < 2 || frames > 10000) {
    *why = "sequences must be within 1..1000 and frames within 2..10000";
  } else if (width < 64 || height < 64 || width > 4096 || height > 4096) {
    *why = "the frame size must be within 64..4096 pixels a side";
  } else {
    return true;
  }
  return false;
}

std::vector<SequenceOptions> ValidationSequences(const EstimatorStudyOptions& options) {
  std::vector<SequenceOptions> out;
  for (int s = 0; s < options.sequences; ++s) {
    SequenceOptions sequence;
    sequence.frames = options.frames;
    sequence.width = options.width;
    sequence.height = options.height;
    sequence.seed = options.seed + static_cast<uint64_t>(s);
    sequence.forearm = static_cast<ForearmKind>(s % 3 == 2 ? 0 : 1 + s % 2);
    sequence.background = static_cast<BackgroundKind>((s / 2) % 3);
    sequence.face = s % 4 == 3;
    sequence.adult_arm = options.adult_arm && sequence.forearm != ForearmKind::kNone;
    out.push_back(sequence);
  }
  return out;
}

std::vector<EstimatorScore> RunEstimatorStudy(const Database& db, const KnnIndex& index, const HandModel& hand,
                                              const EstimatorOptions& base, const EstimatorStudyOptions& options,
                                              std::ostream* progress) {
  std::string why;
  NPHAND_THROW_CHECK(options.Check(&why), "estimator study: ", why);
  std::vector<EstimatorSetting> settings;
  for (const EstimatorSetting& s : EstimatorSweep(base)) {
    if (options.settings.empty() || std::find(options.settings.begin(), options.settings.end(), s.name) != options.settings.end()) {
      settings.push_back(s);
    }
  }
  for (const std::string& name : options.settings) {
    NPHAND_THROW_CHECK(std::any_of(settings.begin(), settings.end(), [&](const EstimatorSetting& s) { return s.name == name; }),
                       "estimator study: unknown setting '", name, "'");
  }

  // The validation frames: sequences that vary everything the estimator must cope with.
  std::vector<std::vector<SequenceFrame>> sequences;
  ProgressLine render_line(progress, "estimator study: rendering", static_cast<uint64_t>(options.sequences), "sequences");
  for (const SequenceOptions& sequence : ValidationSequences(options)) {
    Sequence rendered(hand, sequence);
    std::vector<SequenceFrame> frames;
    for (int i = 0; i < rendered.size(); ++i) frames.push_back(rendered.Render(i));
    sequences.push_back(std::move(frames));
    render_line.Update(sequences.size());
  }
  render_line.Finish();

  std::vector<EstimatorScore> scores;
  ProgressLine line(progress, "estimator study", static_cast<uint64_t>(settings.size()), "settings");
  for (const EstimatorSetting& setting : settings) {
    EstimatorOptions e = setting.options;
    // The truth is the model's hand: compare in its size.
    e.hand_length_m = ModelHandLength(db);
    Estimator estimator(db, index, hand, e);
    EstimatorScore score;
    score.name = setting.name;
    score.options = {{"k", e.k},           {"observation", ToString(e.observation)}, {"sigma_y", e.sigma_y},
                     {"prior", ToString(e.prior)}, {"sigma_x", e.sigma_x}, {"prior_share", e.prior_share},
                     {"carried", e.carried},        {"carry_apart_frames", e.carry_apart_frames},
                     {"prior_reset_frames", e.prior_reset_frames}, {"prior_reset_margin", e.prior_reset_margin},
                     {"roll_ambiguity", e.roll_ambiguity},
                     {"tilts_deg", e.tilts_deg}, {"tilt_above", e.tilt_above}, {"tilt_k", e.tilt_k}, {"tilt_effort", e.tilt_effort},
                     {"mode_mean", e.mode_mean},       {"refine", RefinementJson(e)},
                     {"smooth", SmoothingJson(e)}};
    std::vector<double> ms;
    RunJitter jitter;
    std::vector<Keypoints3d> run;  // the keypoints of the current run of detected frames
    auto close_run = [&]() {
      jitter.Add(run);
      run.clear();
    };
    LagMeter lag;
    for (const std::vector<SequenceFrame>& frames : sequences) {
      estimator.Reset();
      close_run();
      lag.Restart();
      for (const SequenceFrame& truth : frames) {
        const FrameResult r = options.masks ? estimator.ProcessMask(truth.labels == static_cast<int>(PixelLabel::kHand), truth.time_s)
                                            : estimator.Process(truth.rgb, truth.time_s);
        ++score.frames;
        ms.push_back(r.ms.total);
        lag.Add(truth.keypoints, r.detected() ? &r.keypoints_hand : nullptr);
        if (!r.detected()) {
          close_run();
          continue;
        }
        run.push_back(r.keypoints_hand);
        ++score.detected;
        score.both_turns += r.both_turns;
        score.tilted += r.tilted;
        double joint = 0.0, px = 0.0, camera = 0.0;
        for (int d = 0; d < kNumDofs; ++d) joint += std::abs(r.pose.angles[d] - truth.pose.angles[d]);
        for (int k = 0; k < kNumKeypoints; ++k) {
          px += (r.keypoints_2d[k] - truth.keypoints_2d[k]).norm();
          camera += (r.keypoints_camera[k] - (truth.wrist_in_camera + truth.keypoints[k])).norm();
        }
        const double keypoint = RootRelativeError(r.keypoints_hand, truth.keypoints);
        score.joint_deg += joint / kNumDofs * 180.0 / std::numbers::pi;
        const double wrist = RotationAngleDeg(r.pose.camera_from_hand, truth.pose.camera_from_hand);
        score.wrist_deg += wrist;
        score.turned += wrist >= kTurnedDeg;
        const Facing true_facing = FacingOf(truth.keypoints_2d, ToString(truth.pose.handedness));
        score.flipped += true_facing != Facing::kUnknown && FacingOf(r.keypoints_2d, ToString(r.hand)) != true_facing;
        score.keypoint_mm += 1000.0 * keypoint;
        score.keypoint_px += px / kNumKeypoints;
        score.camera_mm += 1000.0 * camera / kNumKeypoints;
      }
    }
    if (score.detected > 0) {
      for (double* v : {&score.joint_deg, &score.wrist_deg, &score.keypoint_mm, &score.keypoint_px, &score.camera_mm}) {
        *v /= score.detected;
      }
    }
    close_run();
    score.jitter_mm = 1000.0 * jitter.mean();
    score.lag_frames = lag.Lag();
    score.ms_median = Median(ms);
    scores.push_back(score);
    line.Update(scores.size());
  }
  line.Finish();
  return scores;
}

nlohmann::json ToJson(const std::vector<EstimatorScore>& scores) {
  nlohmann::json rows = nlohmann::json::array();
  for (const EstimatorScore& s : scores) {
    rows.push_back({{"name", s.name},
                    {"options", s.options},
                    {"frames", s.frames},
                    {"detected", s.detected},
                    {"both_turns", s.both_turns},
                    {"tilted", s.tilted},
                    {"turned", s.turned},
                    {"flipped", s.flipped},
                    {"joint_deg", s.joint_deg},
                    {"wrist_deg", s.wrist_deg},
                    {"keypoint_mm", s.keypoint_mm},
                    {"keypoint_px", s.keypoint_px},
                    {"camera_mm", s.camera_mm},
                    {"jitter_mm", s.jitter_mm},
                    {"lag_frames", s.lag_frames.has_value() ? nlohmann::json(*s.lag_frames) : nlohmann::json(nullptr)},
                    {"ms_median", s.ms_median}});
  }
  return rows;
}

std::string FormatTable(const std::vector<EstimatorScore>& scores) {
  std::ostringstream out;
  out << std::left << std::setw(22) << "setting" << std::right << std::setw(10) << "detected" << std::setw(10)
      << "joint_deg" << std::setw(10) << "wrist_deg" << std::setw(12) << "keypoint_mm" << std::setw(12) << "keypoint_px"
      << std::setw(11) << "camera_mm" << std::setw(8) << "jitter" << std::setw(8) << "ms" << std::setw(8) << "2turns" << std::setw(8) << "tilted" << std::setw(8) << "turned" << std::setw(8) << "flipped" << std::setw(5) << "lag" << "\n";
  out << std::fixed;
  for (const EstimatorScore& s : scores) {
    out << std::left << std::setw(22) << s.name << std::right << std::setw(10)
        << (std::to_string(s.detected) + "/" + std::to_string(s.frames)) << std::setprecision(2) << std::setw(10)
        << s.joint_deg << std::setw(10) << s.wrist_deg << std::setprecision(1) << std::setw(12) << s.keypoint_mm
        << std::setw(12) << s.keypoint_px << std::setw(11) << s.camera_mm << std::setw(8) << s.jitter_mm
        << std::setprecision(2) << std::setw(8) << s.ms_median << std::setprecision(0) << std::setw(7)
        << (s.detected > 0 ? 100.0 * s.both_turns / s.detected : 0.0) << "%" << std::setw(7)
        << (s.detected > 0 ? 100.0 * s.tilted / s.detected : 0.0) << "%" << std::setw(8) << s.turned << std::setw(8) << s.flipped << std::setw(5) << (s.lag_frames.has_value() ? std::to_string(*s.lag_frames) : "-") << "\n";
  }
  return out.str();
}

}  // namespace nphand
