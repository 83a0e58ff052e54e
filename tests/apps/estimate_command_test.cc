#include "apps/estimate_command.h"

#include <unistd.h>

#include <atomic>
#include <csignal>
#include <fstream>
#include <iostream>
#include <set>

#include <gtest/gtest.h>
#include <opencv2/core/utility.hpp>

#include "apps/bench_command.h"
#include "apps/db_command.h"
#include "apps/eval_command.h"
#include "apps/index_command.h"
#include "apps/sequence_command.h"
#include "nphand/db/database.h"
#include "nphand/util/check.h"
#include "testing/testing.h"
#include "tests/apps/command_fixture.h"
#include "testing/tiny_db.h"

namespace nphand {
namespace {

std::vector<nlohmann::json> Lines(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::vector<nlohmann::json> lines;
  std::string line;
  while (std::getline(in, line)) lines.push_back(nlohmann::json::parse(line));
  return lines;
}

// A tiny database with an exact index, and a short rendered sequence, shared by the suite.
class EstimateCommandTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new std::filesystem::path(testing::MakeCommandFixture("nphand_estimate_command", 5));
  }
  static void TearDownTestSuite() {
    std::filesystem::remove_all(*dir_);
    delete dir_;
  }
  static EstimateCommandOptions Options() {
    EstimateCommandOptions options;
    options.db = *dir_ / "tiny.db";
    options.input = (*dir_ / "sequence" / "frames").string();
    options.out = *dir_ / "poses.jsonl";
    options.faces = false;
    options.estimator.k = 40;
    options.estimator.max_distance = 2.0;  // the tiny database's views are far apart
    return options;
  }
  static inline std::filesystem::path* dir_ = nullptr;
};

TEST_F(EstimateCommandTest, SequenceFilesAreWritten) {
  for (const char* name : {"frames/000004.png", "labels/000004.png", "truth.jsonl", "sequence.json", "video.mp4"}) {
    EXPECT_TRUE(std::filesystem::exists(*dir_ / "sequence" / name)) << name;
  }
  EXPECT_EQ(Lines(*dir_ / "sequence" / "truth.jsonl").size(), 5u);
}

TEST_F(EstimateCommandTest, AFolderGivesOneLinePerFrameWithEveryFieldAndAnOverlay) {
  EstimateCommandOptions options = Options();
  options.overlay = *dir_ / "overlay.mp4";
  options.top = true;
  const nlohmann::json summary = RunEstimate(options, nullptr, nullptr);
  EXPECT_EQ(summary["frames"], 5);
  EXPECT_EQ(summary["input_kind"], "folder");
  EXPECT_TRUE(std::filesystem::exists(options.overlay));
  EXPECT_FALSE(std::filesystem::exists(options.out.string() + ".partial"));
  const std::vector<nlohmann::json> lines = Lines(options.out);
  ASSERT_EQ(lines.size(), 5u);
  int detected = 0;
  for (size_t i = 0; i < lines.size(); ++i) {
    const nlohmann::json& line = lines[i];
    EXPECT_EQ(line["frame"], i);
    EXPECT_EQ(line["image"], cv::format("%06zu.png", i));
    for (const char* key : {"time_s", "detected", "status", "ms"}) EXPECT_TRUE(line.contains(key)) << key;
    if (!line["detected"].get<bool>()) continue;
    ++detected;
    for (const char* key : {"hand", "wrist_rotation", "wrist_quaternion_wxyz", "joint_angles_deg", "pose_vector",
                            "keypoints_2d_px", "keypoints_3d_hand_m", "keypoints_3d_camera_m", "depth_m", "box_px",
                            "grasps", "objects", "confidence", "effective_samples", "mean_of", "nearest_distance", "top"}) {
      EXPECT_TRUE(line.contains(key)) << key;
    }
    EXPECT_EQ(line["keypoints_2d_px"].size(), 21u);
    EXPECT_EQ(line["joint_angles_deg"].size(), 21u);
    EXPECT_EQ(line["pose_vector"].size(), 30u);
  }
  EXPECT_GE(detected, 4);
  // --hand auto says per line which side it chose and how surely.
  options.hand = "auto";
  options.overlay.clear();
  RunEstimate(options, nullptr, nullptr);
  for (const nlohmann::json& line : Lines(options.out)) {
    if (!line["detected"].get<bool>()) continue;
    EXPECT_TRUE(line["hand"] == "right" || line["hand"] == "left") << line["hand"];
    EXPECT_GE(line["hand_margin"].get<double>(), 0.0);
  }
  options.hand = "ambidextrous";
  testing::ExpectError([&] { RunEstimate(options, nullptr, nullptr); }, "choose right, left or auto");
  options.hand = "right";
  // What the refinement moves: the default keeps the lookup's joints, fingers moves them.
  options.estimator.refine = true;
  RunEstimate(options, nullptr, nullptr);
  const std::vector<nlohmann::json> placed = Lines(options.out);
  options.refine_move = {"place", "wrist", "fingers"};
  RunEstimate(options, nullptr, nullptr);
  const std::vector<nlohmann::json> fingers = Lines(options.out);
  ASSERT_EQ(placed.size(), fingers.size());
  int joints_moved = 0;
  for (size_t i = 0; i < placed.size(); ++i) {
    if (placed[i]["detected"].get<bool>()) joints_moved += placed[i]["joint_angles_deg"] != fingers[i]["joint_angles_deg"];
  }
  EXPECT_GE(joints_moved, 1);
  options.refine_move = {"place", "knuckles"};
  testing::ExpectError([&] { RunEstimate(options, nullptr, nullptr); }, "unknown refinement move 'knuckles'");
  options.refine_move = {"place", "wrist"};
  options.estimator.refine = false;
  RunEstimate(options, nullptr, nullptr);
  // And the errors against the truth.
  EvalPosesCommandOptions eval;
  eval.truth = *dir_ / "sequence" / "truth.jsonl";
  eval.poses = options.out;
  eval.out_dir = *dir_ / "errors";
  const PoseErrorSummary errors = RunEvalPoses(eval);
  EXPECT_EQ(errors.frames.size(), 5u);
  EXPECT_EQ(errors.detected, detected);
  EXPECT_TRUE(std::filesystem::exists(*dir_ / "errors" / "errors.png"));
  // --roi: a box over the whole frame changes nothing; one on a corner without skin finds
  // no hand, and says why; a box that is no box is refused.
  auto untimed = [&] {
    std::vector<nlohmann::json> lines = Lines(options.out);
    for (nlohmann::json& line : lines) line.erase("ms");
    return lines;
  };
  const std::vector<nlohmann::json> everywhere = untimed();
  options.roi = {-10, -10, 400, 400};
  RunEstimate(options, nullptr, nullptr);
  EXPECT_EQ(untimed(), everywhere);
  options.roi = {0, 0, 6, 6};
  RunEstimate(options, nullptr, nullptr);
  for (const nlohmann::json& line : Lines(options.out)) {
    EXPECT_EQ(line["reason"], "no skin-coloured region within the region of interest") << line.dump();
  }
  options.roi = {0, 0, 0, 10};
  testing::ExpectError([&] { RunEstimate(options, nullptr, nullptr); }, "--roi is x,y,width,height");
  // A box off the frame is refused at the first frame, and the last output stays whole.
  const std::vector<nlohmann::json> corner = untimed();
  options.roi = {1000, 0, 10, 10};
  testing::ExpectError([&] { RunEstimate(options, nullptr, nullptr); }, "does not meet the 240 x 180 frame");
  EXPECT_EQ(untimed(), corner);
}

TEST_F(EstimateCommandTest, AStopLeavesCompleteLinesAndMaxFramesStops) {
  EstimateCommandOptions options = Options();
  options.max_frames = 2;
  EXPECT_EQ(RunEstimate(options, nullptr, nullptr)["frames"], 2);
  EXPECT_EQ(Lines(options.out).size(), 2u);
  // Stopped before its first frame (while loading): the last run's file stays as it was.
  const std::atomic<int> stop{SIGINT};
  const nlohmann::json summary = RunEstimate(Options(), nullptr, &stop);
  EXPECT_TRUE(summary["stopped"].get<bool>());
  EXPECT_EQ(summary["signal"], "SIGINT");
  EXPECT_TRUE(summary["out"].is_null());
  EXPECT_EQ(Lines(Options().out).size(), 2u);
  EXPECT_FALSE(std::filesystem::exists(Options().out.string() + ".partial"));
}

TEST_F(EstimateCommandTest, BadInputsGiveTheirErrors) {
  EstimateCommandOptions options = Options();
  options.db = *dir_ / "missing.db";
  testing::ExpectError([&] { RunEstimate(options, nullptr, nullptr); }, "no database there");
  options = Options();
  options.index = *dir_ / "missing.idx";
  testing::ExpectError([&] { RunEstimate(options, nullptr, nullptr); }, "no index there");
  options = Options();
  options.input = (*dir_ / "nothing").string();
  testing::ExpectError([&] { RunEstimate(options, nullptr, nullptr); }, "no such file or folder");
  std::filesystem::create_directories(*dir_ / "empty");
  options.input = (*dir_ / "empty").string();
  testing::ExpectError([&] { RunEstimate(options, nullptr, nullptr); }, "no images in this folder");
  {
    std::ofstream(*dir_ / "not_a_video.mp4") << "hello";
  }
  options.input = (*dir_ / "not_a_video.mp4").string();
  testing::ExpectError([&] { RunEstimate(options, nullptr, nullptr); }, "not_a_video.mp4");
  options.input = "97";
  testing::ExpectError([&] { RunEstimate(options, nullptr, nullptr); }, "camera 97 is not there");
  // An index of another database.
  options = Options();
  const std::filesystem::path other = testing::BuildTinyDatabase(*dir_ / "other.db");
  DatabaseBuildOptions different = testing::TinyDatabaseOptions();
  different.directions = 12;
  BuildDatabase(testing::RightHand(), different, other, nullptr);
  IndexBuildCommandOptions index;
  index.db = other;
  index.index = IndexOptions::Exact();
  RunIndexBuild(index);
  options.index = other.string() + ".idx";
  testing::ExpectError([&] { RunEstimate(options, nullptr, nullptr); }, "another database");
  // Every command that estimates opens its files one way, with one set of messages.
  BenchPipelineOptions bench;
  bench.db = *dir_ / "missing.db";
  testing::ExpectError([&] { RunBenchPipeline(bench); }, "missing.db: no database there (make one with `nphand db build`)");
  EvalEstimatorCommandOptions sweep;
  sweep.db = *dir_ / "tiny.db";
  sweep.index = *dir_ / "missing.idx";
  testing::ExpectError([&] { RunEvalEstimator(sweep); }, "missing.idx: no index there (make one with `nphand index build --db");
  EvalPoseStudyCommandOptions study;
  study.db = *dir_ / "missing.db";
  testing::ExpectError([&] { RunEvalPoseStudy(PoseStudyPart::kNoise, study); }, "no database there");
  options = Options();
  options.prior = "max";
  testing::ExpectError([&] { RunEstimate(options, nullptr, nullptr); }, "none, product or sum");
  options = Options();
  options.estimator.skin.face_chroma = 12.0;
  testing::ExpectError([&] { RunEstimate(options, nullptr, nullptr); }, "face's chroma reach must be within 0..10");
  // Truth and poses that do not belong together.
  {
    std::ofstream broken(*dir_ / "broken.jsonl");
    for (int frame = 0; frame < 5; ++frame) broken << "{\"frame\": " << frame << ", \"detected\": true}\n";
  }
  EvalPosesCommandOptions eval;
  eval.truth = *dir_ / "sequence" / "truth.jsonl";
  eval.poses = *dir_ / "broken.jsonl";
  testing::ExpectError([&] { RunEvalPoses(eval); }, "has no valid 'joint_angles_deg'");
}

TEST_F(EstimateCommandTest, MotionFilesHoldTheEstimatesKeypointsAndNeedAHand) {
  EstimateCommandOptions options = Options();
  options.bvh = *dir_ / "motion.bvh";
  options.gltf = *dir_ / "motion.glb";
  const nlohmann::json summary = RunEstimate(options, nullptr, nullptr);
  ASSERT_GT(summary["detected"].get<int>(), 0);
  EXPECT_EQ(summary["bvh"], options.bvh.string());
  EXPECT_EQ(summary["gltf"], options.gltf.string());
  EXPECT_EQ(summary["motion"]["frames"], 5);
  EXPECT_EQ(summary["motion"]["with_hand"], summary["detected"]);
  EXPECT_EQ(summary["motion"]["hand"], "right");

  // Read back (the BVH through forward kinematics), they give the estimate's keypoints.
  EvalMotionCommandOptions check;
  check.poses = options.out;
  check.bvh = options.bvh;
  check.gltf = options.gltf;
  const MotionCheck result = RunEvalMotion(check);
  EXPECT_EQ(result.frames, 5u);
  EXPECT_EQ(result.compared, summary["detected"].get<size_t>());
  ASSERT_TRUE(result.bvh.has_value() && result.gltf.has_value());
  EXPECT_LT(result.bvh->max_mm, 1.0);
  EXPECT_LT(result.gltf->max_mm, 1.0);
  std::cout << FormatTable(result);

  // Wrong names, and outputs that are inputs, are refused before any work.
  options = Options();
  options.bvh = *dir_ / "motion.txt";
  testing::ExpectError([&] { RunEstimate(options, nullptr, nullptr); }, "name the motion file .bvh");
  options = Options();
  options.gltf = *dir_ / "motion.gltf";
  testing::ExpectError([&] { RunEstimate(options, nullptr, nullptr); }, "nphand writes binary glTF; name it .glb");
  options = Options();
  options.gltf = options.db;
  testing::ExpectError([&] { RunEstimate(options, nullptr, nullptr); }, "--gltf");
  EXPECT_NO_THROW(Database::Open(options.db));
  check.bvh.clear();
  check.gltf.clear();
  testing::ExpectError([&] { RunEvalMotion(check); }, "give --bvh, --gltf or both");

  // Frames without any hand: the poses are written, the motion files are not, and the error
  // says why.
  const std::filesystem::path dark = *dir_ / "dark";
  std::filesystem::create_directories(dark);
  for (const char* name : {"000000.png", "000001.png"}) {
    std::filesystem::copy_file(*dir_ / "sequence" / "labels" / "000000.png", dark / name,
                               std::filesystem::copy_options::overwrite_existing);
  }
  options = Options();
  options.input = dark.string();
  options.out = *dir_ / "dark.jsonl";
  options.bvh = *dir_ / "dark.bvh";
  testing::ExpectError([&] { RunEstimate(options, nullptr, nullptr); },
                       "none of the 2 frames had a right hand, so there is no motion to write");
  testing::ExpectError([&] { RunEstimate(options, nullptr, nullptr); }, "(the poses are complete in");
  EXPECT_EQ(Lines(options.out).size(), 2u);
  EXPECT_FALSE(std::filesystem::exists(options.bvh));
}

// `nphand eval real` end to end, on labels in real-dev's format made from the rendered
// sequence's truth: three frames as stills and the video's frames in order.
TEST_F(EstimateCommandTest, EvalRealEstimatesEveryLabelledImageAndWritesItsFiles) {
  const std::filesystem::path root = *dir_ / "real";
  std::filesystem::create_directories(root / "images");
  std::filesystem::create_directories(root / "videos");
  std::filesystem::copy_file(*dir_ / "sequence" / "video.mp4", root / "videos" / "clip.mp4",
                             std::filesystem::copy_options::overwrite_existing);
  const std::vector<nlohmann::json> truth = Lines(*dir_ / "sequence" / "truth.jsonl");
  {
    std::ofstream labels(root / "labels.jsonl");
    for (int i = 0; i < 3; ++i) {
      const std::string name = cv::format("images/freihand_%d.png", i);
      std::filesystem::copy_file(*dir_ / "sequence" / "frames" / cv::format("%06d.png", i), root / name,
                                 std::filesystem::copy_options::overwrite_existing);
      labels << nlohmann::json({{"file", name}, {"hand", "right"}, {"hand_side_by", "source"},
                                {"keypoints_2d_px", truth[i]["keypoints_2d_px"]}}).dump() << "\n";
    }
    for (int i = 0; i < 5; ++i) {
      labels << nlohmann::json({{"file", "videos/clip.mp4"}, {"frame", i}, {"hand", "right"},
                                {"keypoints_2d_px", truth[i]["keypoints_2d_px"]}}).dump() << "\n";
    }
  }
  EvalRealCommandOptions options;
  options.labels = root / "labels.jsonl";
  options.db = *dir_ / "tiny.db";
  options.out_dir = *dir_ / "real_out";
  options.faces = false;
  const EvalRealResult result = RunEvalReal(options, nullptr);
  EXPECT_EQ(result.figures["per_source"]["freihand"]["hands"], 3);
  EXPECT_EQ(result.figures["per_source"]["asl_video"]["hands"], 5);
  EXPECT_EQ(result.figures["per_hand"].size(), 8u);
  EXPECT_EQ(result.figures["hand"], "given");
  EXPECT_EQ(result.figures["refine"], false);
  EXPECT_NE(result.table.find("GT overall"), std::string::npos);
  for (const char* file : {"real.json", "real_predictions.jsonl", "real_contact.png"}) {
    EXPECT_TRUE(std::filesystem::exists(options.out_dir / file)) << file;
  }
  EXPECT_EQ(Lines(options.out_dir / "real_predictions.jsonl").size(), 8u) << "a line per labelled image and frame";
  // --hand auto: one search a still, its chosen side scored against the labels'.
  EvalRealCommandOptions chosen = options;
  chosen.hand = "auto";
  chosen.out_dir.clear();
  const EvalRealResult auto_side = RunEvalReal(chosen, nullptr);
  EXPECT_EQ(auto_side.figures["hand"], "auto");
  const nlohmann::json& video = auto_side.figures["per_source"]["asl_video"];
  EXPECT_EQ(video["handedness_n"], video["found"]);
  EXPECT_GT(video["handedness_n"], 0);
  EvalRealCommandOptions refined = options;
  refined.refine = true;
  refined.out_dir.clear();
  EXPECT_EQ(RunEvalReal(refined, nullptr).figures["refine"], true);
  // --refine-move: what the refinement moves, reported; an unknown move refused.
  EvalRealCommandOptions fingers = refined;
  fingers.refine_move = {"place", "wrist", "fingers"};
  EXPECT_EQ(RunEvalReal(fingers, nullptr).figures["refine_move"], nlohmann::json({"place", "wrist", "fingers"}));
  fingers.refine_move = {"palm"};
  testing::ExpectError([&] { RunEvalReal(fingers, nullptr); }, "unknown refinement move 'palm'");
  // --given-box: each labelled hand estimated within its found region.
  EvalRealCommandOptions boxed = options;
  boxed.given_box = true;
  boxed.out_dir.clear();
  const EvalRealResult given = RunEvalReal(boxed, nullptr);
  EXPECT_EQ(given.figures["given_box"], true);
  // --k: the neighbours searched, reported; fewer than the hypotheses carried is refused.
  EvalRealCommandOptions wider = boxed;
  wider.k = 800;
  EXPECT_EQ(RunEvalReal(wider, nullptr).figures["k"], 800);
  wider.k = 3;
  testing::ExpectError([&] { RunEvalReal(wider, nullptr); }, "within 1..k");
  // --track-views: reported; beyond 64 refused.
  EvalRealCommandOptions views = boxed;
  views.track_views = 0;
  EXPECT_EQ(RunEvalReal(views, nullptr).figures["track_views"], 0);
  views.track_views = 65;
  testing::ExpectError([&] { RunEvalReal(views, nullptr); }, "track's views");
  // --face-chroma: reported; beyond 10 standard deviations refused.
  EvalRealCommandOptions ungated = boxed;
  ungated.face_chroma = 0.0;
  EXPECT_EQ(RunEvalReal(ungated, nullptr).figures["face_chroma"], 0.0);
  ungated.face_chroma = 11.0;
  testing::ExpectError([&] { RunEvalReal(ungated, nullptr); }, "face's chroma reach");
  // --max-distance: so strict that no view is near enough, every hand is missed.
  EvalRealCommandOptions strict = refined;
  strict.refine = false;
  strict.max_distance = 0.01;
  const EvalRealResult none = RunEvalReal(strict, nullptr);
  EXPECT_EQ(none.figures["max_distance"], 0.01);
  EXPECT_EQ(none.figures["per_source"]["asl_video"]["found"], 0);
  EXPECT_EQ(none.figures["per_source"]["freihand"]["found"], 0);
  strict.max_distance = 0.0;
  testing::ExpectError([&] { RunEvalReal(strict, nullptr); }, "largest distance");
  chosen.hand = "both";
  testing::ExpectError([&] { RunEvalReal(chosen, nullptr); }, "--hand is given or auto");
  // A label naming a missing image is refused by name before any work; so is an output
  // folder that holds the labels.
  {
    std::ofstream(root / "labels.jsonl", std::ios::app)
        << nlohmann::json({{"file", "images/gone.png"}, {"bbox_px", {0, 0, 10, 10}}}).dump() << "\n";
  }
  testing::ExpectError([&] { RunEvalReal(options, nullptr); }, "labels line 9: " + (root / "images" / "gone.png").string() + ": no such file");
  std::filesystem::copy_file(root / "labels.jsonl", options.out_dir / "labels.jsonl");
  options.labels = options.out_dir / "labels.jsonl";
  testing::ExpectError([&] { RunEvalReal(options, nullptr); }, "lies in eval real --out");
}

TEST_F(EstimateCommandTest, ReuseKeepsAMatchingDatabaseAndIndex) {
  DbBuildCommandOptions db;
  db.out = *dir_ / "tiny.db";
  db.build = testing::TinyDatabaseOptions();
  db.reuse = true;
  db.quiet = true;
  EXPECT_TRUE(RunDbBuild(db)["reused"].get<bool>());
  db.build.directions = 9;
  db.out = *dir_ / "reuse.db";
  std::filesystem::copy_file(*dir_ / "tiny.db", db.out);
  const nlohmann::json rebuilt = RunDbBuild(db);
  EXPECT_FALSE(rebuilt["reused"].get<bool>());
  EXPECT_EQ(rebuilt["reuse_note"], "the existing file was built with other options");
  IndexBuildCommandOptions index;
  index.db = *dir_ / "tiny.db";
  index.index = IndexOptions::Exact();
  index.reuse = true;
  EXPECT_TRUE(RunIndexBuild(index)["reused"].get<bool>());
}

TEST_F(EstimateCommandTest, BenchPipelineReportsEveryFigure) {
  BenchPipelineOptions options;
  options.db = *dir_ / "tiny.db";
  options.frames = 3;
  options.width = 240;
  options.height = 180;
  options.k = 20;
  const int threads_before = cv::getNumThreads();
  const nlohmann::json report = RunBenchPipeline(options);
  for (const char* key : {"fps", "ms", "peak_rss_mb", "db_entries", "backend", "k", "machine"}) {
    EXPECT_TRUE(report.contains(key)) << key;
  }
  for (const char* stage : {"segment", "describe", "search", "weigh", "refine", "place", "total"}) {
    EXPECT_TRUE(report["ms"].contains(stage)) << stage;
  }
  EXPECT_EQ(report["refine"], false);
  EXPECT_EQ(report["face"], true) << "a face beside the hand by default, as before a webcam";
  EXPECT_EQ(report["ms"]["refine"]["median"], 0.0) << "no refinement, no time";
  EXPECT_EQ(report["backend"], "exact");
  EXPECT_GT(report["fps"].get<double>(), 0.0);
  // One OpenCV thread while it runs; the process's own count afterwards.
  EXPECT_EQ(report["threads"], 1);
  EXPECT_EQ(cv::getNumThreads(), threads_before);
  options.refine = true;
  options.face = false;
  const nlohmann::json refined = RunBenchPipeline(options);
  EXPECT_EQ(refined["refine"], true);
  EXPECT_EQ(refined["face"], false);
  ASSERT_GT(refined["detected"].get<int>(), 0);
  EXPECT_GT(refined["ms"]["refine"]["mean"].get<double>(), 0.0);
  options.threads = 0;
  testing::ExpectError([&] { RunBenchPipeline(options); }, "1..256 threads");
}

// `nphand eval noise` (the figures for checking): every alpha and method, the
// paper's and today's measures and the errors normalised by the NN-pose bound; JSON and
// plots written. On the tiny database, with short small sequences.
TEST_F(EstimateCommandTest, EvalNoiseReportsEveryFigureForEveryAlphaAndMethod) {
  EvalPoseStudyCommandOptions options;
  options.db = *dir_ / "tiny.db";
  options.out_dir = *dir_ / "eval";
  std::filesystem::create_directories(options.out_dir);
  options.study.frames = 3;
  options.study.width = 240;
  options.study.height = 180;
  options.study.alphas = {0.0, 5.0};
  options.study.lsq_rows = 100;
  options.study.gp_rows = 60;
  options.study.rvm_rows = 40;
  const nlohmann::json json = ToJson(RunEvalPoseStudy(PoseStudyPart::kNoise, options));
  std::set<std::pair<std::string, double>> seen;
  for (const nlohmann::json& row : json["rows"]) {
    if (row["sequence"] != "all") continue;
    seen.insert({row["method"].get<std::string>(), row["alpha"].get<double>()});
    for (const char* key : {"pose_error", "keypoint_error_mm", "pa_mpjpe_mm", "auc_0_50", "within_20mm",
                            "pose_error_normalised", "keypoint_error_normalised", "detected", "ms_median"}) {
      EXPECT_TRUE(row.contains(key)) << key;
    }
  }
  for (const char* method : {"PNP exact", "PNP", "PNP + refine", "NN feature", "NN pose", "mean pose", "LSQ", "GP", "RVM"}) {
    EXPECT_TRUE(seen.count({method, 0.0}) && seen.count({method, 5.0})) << method;
  }
  for (const char* method : {"PNP RGB", "PNP RGB + refine"}) {
    EXPECT_TRUE(seen.count({method, 0.0}) && !seen.count({method, 5.0})) << method << ": noise is for masks";
  }
  for (const nlohmann::json& row : json["rows"]) {
    if (row["sequence"] != "all") continue;
    // Frames without a hand: frame 0's empty view of each of the 5 sequences, for RGB methods.
    EXPECT_EQ(row["no_hand_frames"], row["method"].get<std::string>().starts_with("PNP RGB") ? 5 : 0) << row["method"];
    EXPECT_LE(row["false_detections"].get<int>(), row["no_hand_frames"].get<int>());
  }
  EXPECT_EQ(json["sequences"].size(), 5u);
  for (const char* file : {"noise.json", "noise_errors.png", "noise_curves.png", "noise_alpha.png"}) {
    EXPECT_TRUE(std::filesystem::exists(options.out_dir / file)) << file;
  }
  options.db = *dir_ / "missing.db";
  testing::ExpectError([&] { RunEvalPoseStudy(PoseStudyPart::kRobustness, options); }, "missing.db");
  options.out_dir.clear();
  testing::ExpectError([&] { RunEvalAll(options); }, "--out is required");
  // Checked before the long feature and nearest-neighbour studies run.
  options.out_dir = *dir_ / "eval";
  options.db = *dir_ / "tiny.db";
  options.index = *dir_ / "missing.idx";
  testing::ExpectError([&] { RunEvalAll(options); }, "missing.idx");
  options.index.clear();
  options.study.frames = 1;
  testing::ExpectError([&] { RunEvalAll(options); }, "frames");
}

}  // namespace
}  // namespace nphand
