// nphand: one binary, one subcommand per pipeline job. Each subcommand binds its flags to
// the fields of an options struct and calls the matching Run* function.
#include <algorithm>
#include <atomic>
#include <cctype>
#include <csignal>

#include <signal.h>
#include <cstdio>
#include <iostream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <opencv2/core/utils/logger.hpp>

#include "apps/bench_command.h"
#include "apps/db_command.h"
#include "apps/estimate_command.h"
#include "apps/eval_command.h"
#include "apps/index_command.h"
#include "apps/render_command.h"
#include "apps/sequence_command.h"
#include "nphand/util/check.h"
#include "nphand/util/version.h"

namespace {

// JSON as printed: a path that is not UTF-8 (file names are bytes) prints with U+FFFD in
// place of its bad bytes instead of failing after the work is done.
std::string Dump(const nlohmann::json& json, int indent = -1) {
  return json.dump(indent, ' ', false, nlohmann::json::error_handler_t::replace);
}

// A report on stdout: one line with --json, indented otherwise.
void PrintJson(const nlohmann::json& report, bool json) { std::cout << (json ? Dump(report) : Dump(report, 2)) << "\n"; }

// "a, b, c": for the lists of names in help texts.
std::string CommaList(const std::vector<std::string>& names) {
  std::string list;
  for (const std::string& name : names) list += (list.empty() ? "" : ", ") + name;
  return list;
}

// --face-chroma of estimate and eval real (SkinOptions::face_chroma).
constexpr const char* kFaceChromaHelp =
    "While a face is in view, skin is only the colours within this many standard deviations of its cheeks' "
    "(0: off, as when someone else's face is behind the hand)";

// --arm-agreement of estimate and eval real (EstimatorOptions::arm_agreement).
constexpr const char* kArmAgreementHelp =
    "Where a forearm was cut off, how much less a hypothesis weighs whose wrist is turned away from the arm "
    "(log weight per unit of disagreement; 0: the arm is not looked at)";

// --prior-reset and --prior-reset-margin of estimate and eval real
// (EstimatorOptions::prior_reset_frames, prior_reset_margin).
constexpr const char* kPriorResetHelp =
    "With a prior, let a track go when, this many frames in a row, the nearest view lies outside its mode and nearer "
    "than the mode's own by more than --prior-reset-margin (0: never, the default: real video lost more than it gained, "
    "docs/estimator.md)";
constexpr const char* kPriorResetMarginHelp = "How much nearer (feature distance) the view outside the track's mode must lie";

// --no-object of estimate and eval real (EstimatorOptions::objects).
constexpr const char* kNoObjectHelp =
    "The hand holds nothing (gestures, an empty hand): the database's views with an object are not weighed";

// --tilts and --no-tilts of estimate, eval real and bench pipeline (EstimatorOptions::tilts_deg):
// one or the other.
void AddTiltOptions(CLI::App* cmd, std::vector<double>& tilts_deg) {
  CLI::Option* tilts = cmd->add_option("--tilts", tilts_deg,
                                       "Where the nearest view lies --tilt-above (estimate's; 0.6 by default) or farther, search "
                                       "the crop turned by plus and minus each of these degrees too")
                           ->expected(1, 8)
                           ->capture_default_str();
  cmd->add_flag_callback("--no-tilts", [&tilts_deg] { tilts_deg.clear(); }, "Never search the crop tilted")->excludes(tilts);
}

// For options held in unsigned fields, which would take "-1" as a huge number.
CLI::Validator WholeNumber() {
  return CLI::Validator(
      [](std::string& item) {
        const bool digits = !item.empty() && std::all_of(item.begin(), item.end(), [](unsigned char c) { return std::isdigit(c); });
        return digits ? std::string() : "'" + item + "' is not a whole number (0 or more)";
      },
      "", "whole number");
}

void AddGraspCheck(CLI::Option* option) {
  option->check(CLI::Validator(
      [](std::string& item) { return item.empty() ? std::string("an empty item (expected e.g. 1,13)") : std::string(); },
      "", "non-empty"));
}

// --refine-move of estimate and eval real: names, comma-separated (SetRefineMoves).
void AddRefineMoveOption(CLI::App* cmd, std::vector<std::string>& moves) {
  cmd->add_option("--refine-move", moves, "Refinement: what moves, any of place, wrist, fingers and proportions")
      ->delimiter(',')
      ->capture_default_str();
}

// The files a command that estimates reads: one option group for every such command.
void AddEstimatorFileOptions(CLI::App* cmd, nphand::EstimatorFiles& f) {
  cmd->add_option("--db", f.db, "Database file")->capture_default_str();
  cmd->add_option("--index", f.index, "Index file (default: the database's path + .idx)");
  cmd->add_option("--asset-dir", f.asset_dir, "Folder holding right.glb and left.glb")->capture_default_str();
}

void AddRenderCommand(CLI::App& app, nphand::RenderCommandOptions& o) {
  CLI::App* cmd = app.add_subcommand("render", "Render a posed hand (and an object) to PNG: RGB, labels, depth, keypoints");
  cmd->add_option("--hand", o.hand, "Which hand: right or left")->capture_default_str();
  cmd->add_option("--pose", o.pose, "Named articulation: rest, relaxed, fist, point, pinch")->capture_default_str();
  cmd->add_option("--grasp", o.grasp,
                  "A grasp of the GRASP taxonomy (e.g. large_diameter; replaces --pose and --object), "
                  "or 'all' for a contact sheet of the 33");
  cmd->add_option("--gesture", o.gesture,
                  "A gesture held without an object (e.g. peace; replaces --pose and --object), or 'all' for a "
                  "contact sheet of them");
  cmd->add_option("--step", o.step, "The grasp's (or gesture's) time step, 0 (pre-shape) to 4 (grasp)")
      ->capture_default_str();
  cmd->add_option("--angle", o.angles, "Override a joint angle, NAME=DEGREES (e.g. index_pip_flex=45); repeatable");
  cmd->add_option("--azimuth", o.azimuth_deg, "Viewpoint azimuth, degrees (0: palm, 180: back)")->capture_default_str();
  cmd->add_option("--elevation", o.elevation_deg, "Viewpoint elevation, degrees")->capture_default_str();
  cmd->add_option("--roll", o.roll_deg, "Camera roll about the optical axis, degrees")->capture_default_str();
  cmd->add_option("--distance", o.distance, "Camera to hand centre, metres")->capture_default_str();
  cmd->add_option("--width", o.width, "Image width, pixels")->capture_default_str();
  cmd->add_option("--height", o.height, "Image height, pixels")->capture_default_str();
  cmd->add_option("--fov", o.fov_deg, "Horizontal field of view, degrees")->capture_default_str();
  cmd->add_option("--object", o.object, "Object shape: sphere, cylinder, box, disk, torus, stick");
  cmd->add_option("--object-size", o.object_size,
                  "Object size in metres: sphere r; cylinder r,length; box x,y,z; disk r,thickness; "
                  "torus R,r; stick r,length")->delimiter(',');
  cmd->add_option("--object-at", o.object_at, "Object centre in the hand frame x,y,z, metres")
      ->delimiter(',')->capture_default_str();
  cmd->add_option("--object-rotate", o.object_rotate_deg, "Object rotation about hand x,y,z, degrees")
      ->delimiter(',')->capture_default_str();
  cmd->add_option("--background", o.background, "Image file to draw behind the scene");
  cmd->add_option("--out", o.out_dir, "Output folder")->capture_default_str();
  cmd->add_option("--name", o.name, "File name prefix")->capture_default_str();
  cmd->add_option("--asset-dir", o.asset_dir, "Folder holding right.glb and left.glb")->capture_default_str();
  cmd->callback([&o]() {
    const nphand::RenderCommandResult result = nphand::RunRender(o);
    for (const auto& path : result.files) std::cout << path.string() << "\n";
    std::cout << "hand pixels: " << result.hand_pixels << ", object pixels: " << result.object_pixels << "\n";
  });
}

void AddSequenceCommand(CLI::App& app, nphand::SequenceCommandOptions& o) {
  CLI::App* cmd = app.add_subcommand(
      "sequence", "Render a grasping sequence with ground truth (frames, labels, truth.jsonl; an input of estimate)");
  nphand::SequenceOptions& s = o.sequence;
  cmd->add_option("--frames", s.frames, "Number of frames")->capture_default_str();
  cmd->add_option("--fps", s.fps, "Frames per second (times in truth.jsonl, the video)")->capture_default_str();
  cmd->add_option("--width", s.width, "Frame width, pixels")->capture_default_str();
  cmd->add_option("--height", s.height, "Frame height, pixels")->capture_default_str();
  cmd->add_option("--fov", s.fov_deg, "Horizontal field of view, degrees")->capture_default_str();
  cmd->add_option("--grasp", s.grasp,
                  "Grasp, taxonomy number 1..33, or a gesture's 34..49 with --no-object (0: a grasp chosen by the seed)")
      ->capture_default_str();
  cmd->add_option("--gesture", o.gesture, "A gesture held without an object instead of a grasp (e.g. peace)");
  cmd->add_option("--object-scale", s.object_scale,
                  "Object size over the database's (the hand closes onto it afresh; 0: 0.8 or 1.25 by the seed)")
      ->capture_default_str();
  cmd->add_flag("!--no-object", s.object, "The same motion without the object");
  cmd->add_option("--beyond-steps", s.beyond_steps, "How far the hand opens (and, empty, closes) past the database's steps")
      ->capture_default_str();
  cmd->add_option("--forearm", o.forearm, "none, bare or sleeved")->capture_default_str();
  cmd->add_flag("--adult-arm", s.adult_arm,
                "An adult's forearm (rounder and thicker towards the elbow) and upper arm, not the cone sized to the mesh's wrist");
  cmd->add_option("--skin", s.skin, "Skin tone: light, medium, olive, brown, dark (default: by the seed)");
  cmd->add_option("--background", o.background, "plain, texture or clutter")->capture_default_str();
  cmd->add_flag("--face", s.face, "Put a face beside the hand");
  cmd->add_flag("--sweater", s.sweater, "Dress the face's person in a skin-coloured sweater (cream to camel; needs --face)");
  cmd->add_option("--turn", s.turn_deg, "How far the viewing direction travels, degrees")->capture_default_str();
  cmd->add_option("--roll", s.roll_deg, "How far the camera rolls, degrees")->capture_default_str();
  cmd->add_option("--distance", s.distance_m, "Camera to hand, metres (average)")->capture_default_str();
  cmd->add_option("--noise", s.noise, "Sensor noise, standard deviation in 8-bit levels")->capture_default_str();
  cmd->add_option("--hand", o.hand, "right or left (the right hand's mirror image)")->capture_default_str();
  cmd->add_option("--proportions", o.proportions,
                  "LENGTH,WIDTH: the hand's length and width as factors of the database hand's (each within 0.5..2)")
      ->delimiter(',')
      ->expected(2)
      ->capture_default_str();
  cmd->add_option("--seed", s.seed, "Seed of every random choice")->check(WholeNumber())->capture_default_str();
  cmd->add_flag("--video", o.video, "Also write video.mp4");
  cmd->add_option("--out", o.out_dir, "Output folder")->capture_default_str();
  cmd->add_option("--asset-dir", o.asset_dir, "Folder holding right.glb and left.glb")->capture_default_str();
  cmd->callback([&o]() {
    const nlohmann::json description = nphand::RunSequence(o, &std::cerr);
    std::cout << (o.out_dir / "frames").string() << "\n" << (o.out_dir / "truth.jsonl").string() << "\n"
              << "grasp " << description["grasp"]["name"].get<std::string>() << ", skin "
              << description["skin"].get<std::string>() << ", " << description["frames"] << " frames\n";
  });
}

// The signal that asked a long job to stop (0: none), and the exit status main returns.
std::atomic<int> g_stop{0};
int g_exit_status = 0;

// Ctrl-C, `kill`/`timeout` (SIGTERM) and a closed terminal (SIGHUP) ask the job to stop
// after its current frame; a second such signal ends the process at once.
void CatchStopSignals() {
  struct sigaction action {};
  action.sa_handler = [](int signal) { g_stop = signal; };
  sigemptyset(&action.sa_mask);
  action.sa_flags = SA_RESETHAND;
  for (int signal : {SIGINT, SIGTERM, SIGHUP}) sigaction(signal, &action, nullptr);
}

void AddEstimateCommand(CLI::App& app, nphand::EstimateCommandOptions& o) {
  CLI::App* cmd = app.add_subcommand("estimate", "Estimate the hand's 3D pose in every frame of a video, image folder or camera");
  nphand::EstimatorOptions& e = o.estimator;
  AddEstimatorFileOptions(cmd, o);
  cmd->add_option("--input", o.input, "Video file, image folder (name order) or camera index")->required();
  cmd->add_option("--out", o.out, "JSON lines, one object per frame (docs/FORMAT.md)")->capture_default_str();
  cmd->add_option("--overlay", o.overlay, "Overlay video (.mp4): the skeleton, and the matched database view beside it");
  cmd->add_option("--bvh", o.bvh, "Motion as BVH (.bvh): the hand's skeleton, wrist place and joint angles per frame");
  cmd->add_option("--gltf", o.gltf, "Motion as binary glTF (.glb): the rigged hand mesh with the estimated animation");
  cmd->add_option("--hand", o.hand,
                  "right, left (mirrored into the right-hand database) or auto (both searched; the better side kept for the track)")
      ->capture_default_str();
  cmd->add_option("--k", e.k, "Neighbours searched per frame")->capture_default_str();
  cmd->add_option("--track-views", e.track_views,
                  "In a track, also measure the entries of this many viewpoints nearest the last best view's (0: none)")
      ->capture_default_str();
  cmd->add_option("--observation", o.observation, "Observation weight: fixed (the paper) or adaptive (the released code)")
      ->capture_default_str();
  cmd->add_option("--sigma-y", e.sigma_y, "Fixed observation weight's feature-distance scale")->capture_default_str();
  cmd->add_option("--prior", o.prior, "Temporal prior: none, product (the paper) or sum (the released code)")->capture_default_str();
  cmd->add_option("--sigma-x", e.sigma_x, "Prior kernel width, pose-vector units")->capture_default_str();
  cmd->add_option("--prior-share", e.prior_share, "The weighted sum's share of the prior")->capture_default_str();
  cmd->add_option("--carried", e.carried, "Hypotheses carried to the next frame (1 to --k)")->capture_default_str();
  cmd->add_option("--carry-apart", e.carry_apart_frames,
                  "In a track's first N frames, carry hypotheses at least --sigma-x apart in pose (one per mode; 0: never)")
      ->check(WholeNumber())
      ->capture_default_str();
  cmd->add_option("--prior-reset", e.prior_reset_frames, kPriorResetHelp)->check(WholeNumber())->capture_default_str();
  cmd->add_option("--prior-reset-margin", e.prior_reset_margin, kPriorResetMarginHelp)->capture_default_str();
  cmd->add_option("--top-n", e.top_n, "Hypotheses kept per frame")->capture_default_str();
  cmd->add_option("--mode-mean", e.mode_mean,
                  "The estimate: the weighted mean of the hypotheses within this pose distance of the best (0: the best alone)")
      ->capture_default_str();
  cmd->add_flag("--top", o.top, "Write the top-N hypotheses in each line");
  cmd->add_option("--max-distance", e.max_distance, "No hand when the nearest view is farther than this")->capture_default_str();
  cmd->add_option("--max-elongation", e.max_elongation, "No hand when the silhouette's principal axes differ more than this ratio")
      ->capture_default_str();
  cmd->add_option("--min-hand-px", e.min_hand_px, "No hand in a skin region spanning fewer pixels than this")->capture_default_str();
  cmd->add_option("--min-area-share", e.min_area_share,
                  "No hand in a skin region of fewer pixels than this share of the hand found last (within " +
                      std::to_string(nphand::EstimatorOptions::kAreaMemory) + " frames)")
      ->capture_default_str();
  cmd->add_option("--roll-ambiguity", e.roll_ambiguity,
                  "Search the half-turned crop too when the silhouette's skewness is below this (0: never)")
      ->capture_default_str();
  AddTiltOptions(cmd, e.tilts_deg);
  cmd->add_option("--tilt-above", e.tilt_above, "Search the crop's tilts where the nearest view lies this far or farther (0: on every frame)")
      ->capture_default_str();
  cmd->add_option("--focal", e.focal_px, "Focal length in pixels (0: from --fov)")->capture_default_str();
  cmd->add_option("--fov", e.fov_deg, "Horizontal field of view, degrees")->capture_default_str();
  cmd->add_option("--hand-length", e.hand_length_m, "Wrist to middle fingertip, metres")->capture_default_str();
  cmd->add_flag("!--no-faces", o.faces, "Do not look for faces");
  cmd->add_option("--face-chroma", e.skin.face_chroma, kFaceChromaHelp)->capture_default_str();
  cmd->add_flag("!--no-forearm-cut", e.cut_forearm, "Do not cut the forearm at the wrist");
  cmd->add_option("--arm-agreement", e.arm_agreement, kArmAgreementHelp)->capture_default_str();
  cmd->add_flag("!--no-object", e.objects, kNoObjectHelp);
  cmd->add_option("--roi", o.roi, "x,y,width,height: seek the hand in this part of the frame only (skin elsewhere is ignored)")
      ->delimiter(',')
      ->expected(4);
  cmd->add_flag("--refine,!--no-refine", e.refine, "Refine the best view's pose until its silhouette agrees with the hand's");
  cmd->add_option("--refine-sweeps", e.refinement.sweeps, "Refinement: passes over the wrist's and fingers' directions")
      ->capture_default_str();
  AddRefineMoveOption(cmd, o.refine_move);
  cmd->add_flag("--smooth,!--no-smooth", e.smooth, "Smooth the track's poses over time (a One Euro filter)")->capture_default_str();
  cmd->add_option("--smooth-cutoff", e.smoothing.min_cutoff_hz, "Smoothing: the cutoff of a still hand, Hz (the rotation has its own)")->capture_default_str();
  cmd->add_option("--smooth-beta", e.smoothing.beta, "Smoothing: the cutoff's rise with the hand's speed (not the rotation's)")->capture_default_str();
  cmd->add_option("--smooth-rotation-cutoff", e.rotation_smoothing.min_cutoff_hz, "Smoothing: the cutoff of a still wrist's rotation, Hz")
      ->capture_default_str();
  cmd->add_option("--smooth-rotation-trend", e.rotation_smoothing.trend,
                  "Smoothing: how far the rotation is predicted from its smoothed rate (0 to 1)")
      ->capture_default_str();
  cmd->add_option("--fps", o.fps, "Frame rate of an image folder")->capture_default_str();
  cmd->add_option("--max-frames", o.max_frames, "Stop after this many frames (0: all)")->check(WholeNumber())->capture_default_str();
  cmd->callback([&o]() {
    // A stop signal ends the run after the current frame, with complete files, and the
    // status says it was stopped: 128 + the signal's number (130 for Ctrl-C).
    CatchStopSignals();
    const nlohmann::json summary = nphand::RunEstimate(o, &std::cerr, &g_stop);
    std::cout << Dump(summary, 2) << "\n";
    if (summary["stopped"].get<bool>()) {
      std::cerr << "estimate: stopped by " << nphand::SignalName(g_stop) << " after " << summary["frames"] << " frames"
                << (summary["out"].is_null() ? "; nothing was written" : "") << "\n";
      g_exit_status = 128 + g_stop;
    }
  });
}

void AddBenchCommand(CLI::App& app, nphand::BenchRenderOptions& o, nphand::BenchPipelineOptions& p, bool& json) {
  CLI::App* bench = app.add_subcommand("bench", "Measure the speed of a pipeline stage");
  bench->require_subcommand(1);
  CLI::App* pipeline = bench->add_subcommand(
      "pipeline", "Frames per second of the whole estimator on one core, ms per stage, peak memory");
  AddEstimatorFileOptions(pipeline, p);
  pipeline->add_option("--frames", p.frames, "Frames to time")->capture_default_str();
  pipeline->add_option("--width", p.width, "Frame width")->capture_default_str();
  pipeline->add_option("--height", p.height, "Frame height")->capture_default_str();
  pipeline->add_option("--k", p.k, "Neighbours per frame")->capture_default_str();
  pipeline->add_option("--track-views", p.track_views, "Viewpoints of the track's views measured besides (0: none)")
      ->capture_default_str();
  pipeline->add_option("--hand", p.hand, "right, left or auto (both sides searched)")->capture_default_str();
  pipeline->add_flag("--refine", p.refine, "Refine the best view's pose (its cost is ms.refine)");
  AddTiltOptions(pipeline, p.tilts_deg);
  pipeline->add_flag("--face,!--no-face", p.face, "A face beside the hand in every frame (the face cascade and its skin gate timed too)")
      ->capture_default_str();
  pipeline->add_option("--seed", p.seed, "Seed of the rendered sequences")->check(WholeNumber())->capture_default_str();
  pipeline->add_option("--threads", p.threads, "OpenCV threads for the image work (1: one core)")->capture_default_str();
  pipeline->add_flag("--json", json, "Print one JSON object");
  pipeline->callback([&p, &json]() {
    PrintJson(nphand::RunBenchPipeline(p), json);
  });
  CLI::App* render = bench->add_subcommand("render", "Label images per second (hand + object, one core)");
  render->add_option("--images", o.images, "Images to time")->capture_default_str();
  render->add_option("--size", o.size, "Square image side, pixels")->capture_default_str();
  render->add_option("--seed", o.seed, "Seed of the viewpoints and articulations")->check(WholeNumber())->capture_default_str();
  render->add_option("--asset-dir", o.asset_dir, "Folder holding right.glb and left.glb")->capture_default_str();
  render->add_flag("--json", json, "Print one JSON object");
  render->callback([&o, &json]() {
    PrintJson(nphand::RunBenchRender(o), json);
  });
}

struct DbArgs {
  nphand::DbBuildCommandOptions build;
  std::vector<std::filesystem::path> shards;
  std::filesystem::path merge_out = "out/nphand.db";
  std::filesystem::path info_path = "out/nphand.db";
  bool json = false;
};

void AddDbCommand(CLI::App& app, DbArgs& a) {
  CLI::App* db = app.add_subcommand("db", "Build, merge and inspect the database of rendered hand views");
  db->require_subcommand(1);
  nphand::DatabaseBuildOptions& b = a.build.build;
  CLI::App* build = db->add_subcommand(
      "build", "Render every grasp, step, object/no object and viewpoint, then every gesture, step and viewpoint, into a database");
  build->add_option("--out", a.build.out, "Database file to write")->capture_default_str();
  AddGraspCheck(build->add_option("--grasps", b.grasps, "Taxonomy numbers to include (default: all 33)")->delimiter(','));
  build->add_option("--gestures", a.build.gestures,
                    "Gestures held without an object to include besides the grasps: all (the default), none, or "
                    "names (e.g. fist,peace)")
      ->delimiter(',');
  build->add_option("--directions", b.directions, "Viewing directions on the sphere")->capture_default_str();
  build->add_option("--image-size", b.image_size, "Rendered image side, pixels")->capture_default_str();
  build->add_option("--threads", b.threads, "Worker threads (0: all cores)")->capture_default_str();
  build->add_flag("!--raw-roll", b.descriptor.normalize_roll,
                  "Describe hands as rendered instead of turned by their principal axis");
  build->add_option("--shard", a.build.shard, "Build part i of N (i/N), to merge later with db merge");
  build->add_option("--asset-dir", a.build.asset_dir, "Folder holding right.glb")->capture_default_str();
  build->add_flag("--quiet", a.build.quiet, "No progress line");
  build->add_flag("--reuse", a.build.reuse, "Keep an existing --out built with the same options (after verifying it)");
  build->add_flag("--json", a.json, "Print the summary as one JSON object");
  build->callback([&a]() {
    const nlohmann::json summary = nphand::RunDbBuild(a.build);
    if (a.json) {
      PrintJson(summary, true);
    } else {
      std::cout << "wrote " << summary["entries"] << " entries to " << summary["path"].get<std::string>() << " in "
                << summary["seconds"].get<double>() << " s (" << summary["resumed"] << " resumed, "
                << summary["no_hand"] << " with the hand hidden)\n";
    }
  });
  CLI::App* merge = db->add_subcommand("merge", "Join the shards of one build into one database");
  merge->add_option("shards", a.shards, "Shard files")->required();
  merge->add_option("--out", a.merge_out, "Database file to write")->capture_default_str();
  merge->add_flag("--json", a.json, "Print one JSON object");
  merge->callback([&a]() { PrintJson(nphand::RunDbMerge(a.shards, a.merge_out), a.json); });
  CLI::App* info = db->add_subcommand("info", "What a database file holds (verifies it)");
  info->add_option("path", a.info_path, "Database file")->capture_default_str();
  info->add_flag("--json", a.json, "Print one JSON object");
  info->callback([&a]() { PrintJson(nphand::RunDbInfo(a.info_path), a.json); });
}

// The backend and its options (`--<backend>-<option>`); `seed` is every backend's seed.
void AddIndexOptions(CLI::App* cmd, nphand::IndexOptions& o, uint64_t& seed) {
  cmd->add_option("--backend", o.backend, "One of: " + CommaList(nphand::IndexBackends()))->capture_default_str();
  nphand::LshOptions& lsh = o.lsh;
  cmd->add_option("--lsh-tables", lsh.tables, "LSH: hash tables (L)")->capture_default_str();
  cmd->add_option("--lsh-probes", lsh.probes, "LSH: buckets probed per table (T)")->capture_default_str();
  cmd->add_option("--lsh-hashes", lsh.hashes, "LSH: hashes per table (M; 0: tuned)")->capture_default_str();
  cmd->add_option("--lsh-width", lsh.bucket_width, "LSH: bucket width (W; 0: tuned)")->capture_default_str();
  cmd->add_option("--lsh-recall", lsh.target_recall, "LSH: the recall of the true K nearest to tune for (R)")
      ->capture_default_str();
  cmd->add_option("--lsh-k", lsh.tune_k, "LSH: the K whose recall is tuned")->capture_default_str();
  cmd->add_option("--lsh-queries", lsh.tune_queries, "LSH: sampled queries the tuner measures on")->capture_default_str();
  cmd->add_option("--hnsw-m", o.hnsw.m, "HNSW (faiss-hnsw, hnswlib, hnswlib-sq8): links per node")->capture_default_str();
  cmd->add_option("--hnsw-ef-construction", o.hnsw.ef_construction, "HNSW: candidates while inserting")
      ->capture_default_str();
  cmd->add_option("--hnsw-ef", o.hnsw.ef_search, "HNSW: candidates while searching (at least K)")->capture_default_str();
  cmd->add_option("--hnsw-pca", o.hnsw.pca, "hnswlib: link and search this many principal components, re-rank exactly (0: off)")
      ->capture_default_str();
  cmd->add_option("--ivf-lists", o.ivf.lists, "IVF: k-means cells (0: 4 sqrt(n))")->capture_default_str();
  cmd->add_option("--ivf-probes", o.ivf.probes, "IVF: cells scanned per query")->capture_default_str();
  cmd->add_option("--ivf-encoding", o.ivf.encoding, "IVF: flat or sq8 (8-bit, re-ranked exactly)")->capture_default_str();
  cmd->add_option("--ivf-rerank", o.ivf.rerank, "IVF sq8: candidates re-ranked, as a multiple of K")->capture_default_str();
  cmd->add_option("--flann-algorithm", o.flann.algorithm, "FLANN: kdtree or kmeans")->capture_default_str();
  cmd->add_option("--flann-trees", o.flann.trees, "FLANN kdtree: randomised trees")->capture_default_str();
  cmd->add_option("--flann-branching", o.flann.branching, "FLANN kmeans: branching")->capture_default_str();
  cmd->add_option("--flann-checks", o.flann.checks, "FLANN: leaves checked per query (-1: all)")->capture_default_str();
  cmd->add_option("--seed", seed, "Seed of the backend's random choices (LSH, HNSW, IVF: below 2^31; FLANN takes none)")
      ->check(WholeNumber())->capture_default_str();
}

struct IndexArgs {
  nphand::IndexBuildCommandOptions build;
  uint64_t seed = 1;
  std::filesystem::path info_path = "out/nphand.db.idx";
  bool json = false;
};

void AddIndexCommand(CLI::App& app, IndexArgs& a) {
  CLI::App* index = app.add_subcommand("index", "Build and inspect the nearest-neighbour index of a database");
  index->require_subcommand(1);
  CLI::App* build = index->add_subcommand("build", "Index every database entry with a hand for K-nearest search");
  build->add_option("--db", a.build.db, "Database file")->capture_default_str();
  AddIndexOptions(build, a.build.index, a.seed);
  build->add_option("--out", a.build.out, "Index file to write (default: the database's path + .idx)");
  build->add_flag("--reuse", a.build.reuse, "Keep an existing index of this database with the same backend");
  build->add_flag("--json", a.json, "Print one JSON object");
  build->callback([&a]() {
    a.build.index.lsh.seed = a.build.index.hnsw.seed = a.build.index.ivf.seed = a.seed;
    PrintJson(nphand::RunIndexBuild(a.build), a.json);
  });
  CLI::App* info = index->add_subcommand("info", "What an index file holds (backend, parameters, its database)");
  info->add_option("path", a.info_path, "Index file")->capture_default_str();
  info->add_flag("--json", a.json, "Print one JSON object");
  info->callback([&a]() { PrintJson(nphand::RunIndexInfo(a.info_path), a.json); });
}

void AddEvalAnnCommand(CLI::App* eval, nphand::EvalAnnCommandOptions& o, bool& json) {
  CLI::App* ann = eval->add_subcommand("ann", "Nearest-neighbour study (paper Fig. 5): every backend against database size");
  nphand::AnnStudyOptions& s = o.study;
  ann->add_option("--db", o.db, "Database file")->capture_default_str();
  ann->add_option("--assets", o.asset_dir, "Folder of the hand asset (renders the held-out queries)")
      ->capture_default_str();
  ann->add_option("--queries", s.queries, "Held-out rendered queries")->capture_default_str();
  ann->add_option("--k", s.k, "Neighbours per query (K)")->capture_default_str();
  ann->add_option("--fractions", s.fractions, "Database fractions, in (0, 1]")->delimiter(',')->capture_default_str();
  std::vector<std::string> settings;
  for (const nphand::AnnConfig& c : nphand::StudyConfigs()) settings.push_back(c.name);
  ann->add_option("--backends", s.configs, "Backend settings (default all: " + CommaList(settings) + ")")->delimiter(',');
  ann->add_option("--seed", s.seed, "Seed of the queries and the fractions' samples")->check(WholeNumber())->capture_default_str();
  ann->add_option("--out", o.out_dir, "Folder for the JSON and the plot");
  ann->add_option("--name", o.name, "File name of the JSON and the plot")->capture_default_str();
  ann->add_flag("--json", json, "Print one JSON object instead of the table");
  ann->callback([&o, &json]() {
    const nphand::AnnStudyResult result = nphand::RunEvalAnn(o);
    if (json) {
      std::cout << Dump(nphand::ToJson(result)) << "\n";
    } else {
      std::cout << nphand::FormatTable(result);
    }
  });
}

void AddEvalEstimatorCommand(CLI::App* eval, nphand::EvalEstimatorCommandOptions& o, bool& json) {
  CLI::App* cmd = eval->add_subcommand(
      "estimator", "The estimator's validation sweep: observation weight, prior, carried hypotheses and K on rendered sequences");
  nphand::EstimatorStudyOptions& s = o.study;
  AddEstimatorFileOptions(cmd, o);
  cmd->add_option("--sequences", s.sequences, "Validation sequences")->capture_default_str();
  cmd->add_option("--frames", s.frames, "Frames per sequence")->capture_default_str();
  cmd->add_option("--width", s.width, "Frame width")->capture_default_str();
  cmd->add_option("--height", s.height, "Frame height")->capture_default_str();
  cmd->add_option("--seed", s.seed, "Sequence i uses seed + i")->check(WholeNumber())->capture_default_str();
  cmd->add_option("--settings", s.settings, "Settings to run (default: the whole sweep)")->delimiter(',');
  cmd->add_flag("--masks", s.masks, "Estimate from the rendered hand masks (the paper's input) instead of the RGB frames");
  cmd->add_flag("--adult-arm", s.adult_arm, "Sequences with a forearm render an adult's arm, not the cone sized to the mesh's wrist");
  cmd->add_option("--out", o.out_dir, "Folder for the JSON");
  cmd->add_option("--name", o.name, "File name of the JSON")->capture_default_str();
  cmd->add_flag("--json", json, "Print JSON instead of the table");
  cmd->callback([&o, &json]() {
    const std::vector<nphand::EstimatorScore> scores = nphand::RunEvalEstimator(o);
    if (json) {
      std::cout << Dump(nphand::ToJson(scores)) << "\n";
    } else {
      std::cout << nphand::FormatTable(scores);
    }
  });
}

void AddEvalPosesCommand(CLI::App* eval, nphand::EvalPosesCommandOptions& o, bool& json) {
  CLI::App* cmd = eval->add_subcommand("poses", "Errors of estimated poses (poses.jsonl) against ground truth (truth.jsonl)");
  cmd->add_option("--truth", o.truth, "truth.jsonl of nphand sequence")->required();
  cmd->add_option("--poses", o.poses, "poses.jsonl of nphand estimate")->required();
  cmd->add_option("--out", o.out_dir, "Folder for the JSON and the plot");
  cmd->add_option("--name", o.name, "File name of the JSON and the plot")->capture_default_str();
  cmd->add_flag("--json", json, "Print JSON (with every frame) instead of the table");
  cmd->callback([&o, &json]() {
    const nphand::PoseErrorSummary summary = nphand::RunEvalPoses(o);
    std::cout << (json ? Dump(nphand::ToJson(summary)) + "\n" : nphand::FormatTable(summary));
  });
}

void AddEvalMotionCommand(CLI::App* eval, nphand::EvalMotionCommandOptions& o, bool& json) {
  CLI::App* cmd = eval->add_subcommand(
      "motion", "Motion files (estimate --bvh, --gltf) read back: their keypoints against the estimate's (poses.jsonl)");
  cmd->add_option("--poses", o.poses, "poses.jsonl of nphand estimate")->required();
  cmd->add_option("--bvh", o.bvh, "The run's .bvh");
  cmd->add_option("--gltf", o.gltf, "The run's .glb");
  cmd->add_flag("--json", json, "Print JSON instead of the table");
  cmd->callback([&o, &json]() {
    const nphand::MotionCheck check = nphand::RunEvalMotion(o);
    std::cout << (json ? Dump(nphand::ToJson(check)) + "\n" : nphand::FormatTable(check));
  });
}

void AddEvalRealCommand(CLI::App* eval, nphand::EvalRealCommandOptions& o, bool& json) {
  CLI::App* cmd = eval->add_subcommand(
      "real", "The estimator on labelled real images and video (real-dev's labels.jsonl), scored as real-dev's reference does");
  cmd->add_option("--labels", o.labels, "labels.jsonl (its files are relative to its folder)")->required();
  AddEstimatorFileOptions(cmd, o);
  cmd->add_option("--out", o.out_dir, "Folder for real.json, real_predictions.jsonl and real_contact.png");
  cmd->add_flag("!--no-faces", o.faces, "Do not look for faces");
  cmd->add_flag("--refine", o.refine, "Refine each estimate's best view against the hand's silhouette");
  AddRefineMoveOption(cmd, o.refine_move);
  cmd->add_option("--max-distance", o.max_distance, "No hand when the nearest view is farther than this")->capture_default_str();
  cmd->add_option("--k", o.k, "Neighbours searched per frame")->capture_default_str();
  cmd->add_option("--track-views", o.track_views,
                  "In a track, also measure the entries of this many viewpoints nearest the last best view's (0: none)")
      ->capture_default_str();
  cmd->add_option("--carried", o.carried, "Hypotheses carried to the next frame (1 to --k)")->capture_default_str();
  cmd->add_option("--carry-apart", o.carry_apart_frames,
                  "In a track's first N frames, carry hypotheses at least sigma_x apart in pose (one per mode; 0: never)")
      ->check(WholeNumber())
      ->capture_default_str();
  cmd->add_option("--prior-reset", o.prior_reset_frames, kPriorResetHelp)->check(WholeNumber())->capture_default_str();
  cmd->add_option("--prior-reset-margin", o.prior_reset_margin, kPriorResetMarginHelp)->capture_default_str();
  cmd->add_option("--face-chroma", o.face_chroma, kFaceChromaHelp)->capture_default_str();
  cmd->add_option("--arm-agreement", o.arm_agreement, kArmAgreementHelp)->capture_default_str();
  cmd->add_flag("!--no-object", o.objects, kNoObjectHelp);
  AddTiltOptions(cmd, o.tilts_deg);
  cmd->add_flag("--given-box", o.given_box,
                "The hand's place given: each labelled hand estimated within its box grown by 25 % (its pose judged alone)");
  cmd->add_option("--max-side", o.max_side,
                  "Shrink every image and video frame whose longer side exceeds this many pixels until it does not "
                  "(320: a 320 x 240 webcam's frames; 0: as they are); the keypoints are scored in the labels' pixels")
      ->capture_default_str();
  cmd->add_option("--hand", o.hand, "given (each labelled side searched for) or auto (the estimator chooses, and is scored)")
      ->capture_default_str();
  cmd->add_flag("--json", json, "Print JSON instead of the table");
  cmd->callback([&o, &json]() {
    const nphand::EvalRealResult result = nphand::RunEvalReal(o, &std::cerr);
    std::cout << (json ? Dump(result.figures) + "\n" : result.table);
  });
}

void AddEvalPoseStudyCommands(CLI::App* eval, nphand::EvalPoseStudyCommandOptions& o, bool& json) {
  const auto add = [&](const char* name, const char* help) {
    CLI::App* cmd = eval->add_subcommand(name, help);
    nphand::PoseStudyOptions& s = o.study;
    AddEstimatorFileOptions(cmd, o);
    cmd->add_option("--out", o.out_dir, "Folder for the JSON and the plots");
    cmd->add_option("--frames", s.frames, "Frames per test sequence")->capture_default_str();
    cmd->add_option("--width", s.width, "Frame width")->capture_default_str();
    cmd->add_option("--height", s.height, "Frame height")->capture_default_str();
    cmd->add_option("--seed", s.seed, "Test sequences use seed..seed+4, the robustness variants seed+100")
        ->check(WholeNumber())->capture_default_str();
    cmd->add_option("--alphas", s.alphas, "Segmentation noise levels, % of hand pixels removed (noise)")
        ->delimiter(',')
        ->capture_default_str();
    cmd->add_flag("!--no-exact", s.exact, "Skip the estimator with exact search (the slowest method)");
    cmd->add_option("--lsq-rows", s.lsq_rows, "Database entries LSQ is fitted on")->capture_default_str();
    cmd->add_option("--gp-rows", s.gp_rows, "Database entries GP is fitted on")->capture_default_str();
    cmd->add_option("--rvm-rows", s.rvm_rows, "Database entries the RVM starts from")->capture_default_str();
    cmd->add_option("--fit-seed", s.fit_seed, "Seed of the regressions' entries")->check(WholeNumber())->capture_default_str();
    cmd->add_flag("--adult-arm", s.adult_arm, "The sequences' forearms are an adult's arm, not the cone sized to the mesh's wrist");
    cmd->add_flag("--json", json, "Print one JSON object instead of the tables");
    return cmd;
  };
  const auto print = [&json](const nphand::PoseStudyResult& r) {
    if (json) {
      std::cout << Dump(nphand::ToJson(r)) << "\n";
      return;
    }
    for (const nlohmann::json& sequence : r.sequences) {
      const std::string name = sequence["name"].get<std::string>();
      if (r.part != "robustness" && r.part != "baselines") break;
      std::cout << "# " << name << "\n" << nphand::FormatScores(r.scores, name) << "\n";
    }
    if (r.part != "robustness") std::cout << "# all sequences\n" << nphand::FormatScores(r.scores) << "\n";
    std::cout << "took " << static_cast<int>(r.seconds) << " s\n";
  };
  using Part = nphand::PoseStudyPart;
  add("baselines", "Every method of the paper's comparison on the test sequences (Fig. 6), clean masks")
      ->callback([&o, print]() { print(nphand::RunEvalPoseStudy(Part::kBaselines, o)); });
  add("noise", "The mask methods under segmentation noise (Fig. 7): alpha % of hand pixels removed, then eroded and dilated")
      ->callback([&o, print]() { print(nphand::RunEvalPoseStudy(Part::kNoise, o)); });
  add("robustness", "The estimator on variants of one sequence: skin tone, background, sleeve, hand proportions")
      ->callback([&o, print]() { print(nphand::RunEvalPoseStudy(Part::kRobustness, o)); });
  add("all", "The whole study: features, ann, baselines, noise, robustness (needs --out)")->callback([&o, &json]() {
    const nlohmann::json summary = nphand::RunEvalAll(o);
    PrintJson(summary, json);
  });
}

void AddEvalCommand(CLI::App& app, nphand::EvalFeaturesCommandOptions& o, nphand::EvalAnnCommandOptions& ann,
                    nphand::EvalEstimatorCommandOptions& estimator, nphand::EvalPosesCommandOptions& poses,
                    nphand::EvalPoseStudyCommandOptions& study, nphand::EvalRealCommandOptions& real,
                    nphand::EvalMotionCommandOptions& motion, bool& json) {
  CLI::App* eval = app.add_subcommand("eval", "The paper's experiments, and nphand on real images");
  eval->require_subcommand(1);
  AddEvalPosesCommand(eval, poses, json);
  AddEvalMotionCommand(eval, motion, json);
  AddEvalRealCommand(eval, real, json);
  AddEvalAnnCommand(eval, ann, json);
  AddEvalEstimatorCommand(eval, estimator, json);
  AddEvalPoseStudyCommands(eval, study, json);
  CLI::App* features = eval->add_subcommand("features", "Feature study (paper Fig. 4): pose error of feature-space neighbours");
  nphand::FeatureStudyOptions& s = o.study;
  features->add_option("--db", o.db, "Database file")->capture_default_str();
  features->add_option("--queries", s.queries, "Query entries (left out in turn)")->capture_default_str();
  features->add_option("--neighbours", s.neighbours, "Neighbours per query (K)")->capture_default_str();
  features->add_option("--seed", s.seed, "Seed of the query sample and rolls")->check(WholeNumber())->capture_default_str();
  features->add_option("--features", s.features,
                       "Features to compare (default all: joints, hog8x8x8, hog8x8x4, hog8x8x16, hog4x4x8, "
                       "hog16x16x8, hog8x8x8_pyr, hog8x8x8_nh, dist32)")->delimiter(',');
  features->add_flag("--roll-queries", s.roll_queries, "Turn each query by a random in-plane angle");
  features->add_flag("--normalize-roll", s.normalize_roll, "Crop every hand by its principal axis");
  features->add_option("--out", o.out_dir, "Folder for the JSON and the plot");
  features->add_option("--name", o.name, "File name of the JSON and the plot")->capture_default_str();
  features->add_flag("--json", json, "Print one JSON object instead of the table");
  features->callback([&o, &json]() {
    o.quiet = json;
    const nphand::FeatureStudyResult result = nphand::RunEvalFeatures(o);
    if (json) {
      std::cout << Dump(nphand::ToJson(result)) << "\n";
    } else {
      std::cout << nphand::FormatTable(result);
    }
  });
}

// CLI11 answers an unknown subcommand with "A subcommand is required"; this names it and
// lists the known ones. Walks the leading words of argv down the subcommand tree.
void CheckSubcommands(CLI::App& app, int argc, char** argv) {
  CLI::App* level = &app;
  std::string path = "nphand";
  for (int i = 1; i < argc && argv[i][0] != '-'; ++i) {
    std::vector<CLI::App*> known = level->get_subcommands([](CLI::App*) { return true; });
    if (known.empty()) return;
    const auto match = std::find_if(known.begin(), known.end(), [&](CLI::App* sub) { return sub->check_name(argv[i]); });
    if (match == known.end()) {
      std::string names;
      for (CLI::App* sub : known) names += (names.empty() ? "" : ", ") + sub->get_name();
      throw nphand::Error("'" + path + " " + argv[i] + "' is not a command; '" + path + "' takes: " + names);
    }
    level = *match;
    path += " " + level->get_name();
  }
}

}  // namespace

int main(int argc, char** argv) {
  // nphand reports what went wrong itself; OpenCV's warnings (a failed video back end) are noise.
  cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_ERROR);
  CLI::App app{"nphand: non-parametric hand pose estimation with object context"};
  app.set_version_flag("--version", std::string("nphand ") + nphand::kVersion);
  app.require_subcommand(1);
  nphand::RenderCommandOptions render_options;
  nphand::BenchRenderOptions bench_options;
  bool json = false;
  AddRenderCommand(app, render_options);
  nphand::SequenceCommandOptions sequence_options;
  AddSequenceCommand(app, sequence_options);
  nphand::EstimateCommandOptions estimate_options;
  AddEstimateCommand(app, estimate_options);
  nphand::BenchPipelineOptions pipeline_options;
  AddBenchCommand(app, bench_options, pipeline_options, json);
  DbArgs db_args;
  AddDbCommand(app, db_args);
  IndexArgs index_args;
  AddIndexCommand(app, index_args);
  nphand::EvalFeaturesCommandOptions eval_options;
  nphand::EvalAnnCommandOptions ann_options;
  nphand::EvalEstimatorCommandOptions estimator_study_options;
  nphand::EvalPosesCommandOptions poses_options;
  nphand::EvalPoseStudyCommandOptions pose_study_options;
  nphand::EvalRealCommandOptions real_options;
  nphand::EvalMotionCommandOptions motion_options;
  AddEvalCommand(app, eval_options, ann_options, estimator_study_options, poses_options, pose_study_options, real_options,
                 motion_options, json);
  try {
    CheckSubcommands(app, argc, argv);
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const nphand::Error& e) {
    std::fprintf(stderr, "nphand: error: %s\n", e.what());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "nphand: error: %s\n", e.what());
    return 1;
  }
  return g_exit_status;
}
