// The real-image scorer: its measures on labels and predictions written here, its refusals
// of malformed files, and (when ../shared/real-dev and python3 are there) the same figures
// as real-dev's reference scorer, score_realdev.py, on the same predictions.
#include "nphand/eval/real_score.h"

#include <cstdlib>
#include <fstream>

#include <gtest/gtest.h>

#include "nphand/util/random.h"
#include "testing/testing.h"

namespace nphand {
namespace {

std::filesystem::path Write(const std::filesystem::path& path, const std::vector<nlohmann::json>& lines) {
  std::ofstream out(path);
  for (const nlohmann::json& line : lines) out << line.dump() << "\n";
  return path;
}

// A hand of 21 keypoints spread over a 100 x 100 box at (x, y).
nlohmann::json Keypoints(double x, double y) {
  nlohmann::json points = nlohmann::json::array();
  for (int k = 0; k < kNumKeypoints; ++k) points.push_back({x + 5.0 * k, y + 100.0 * (k % 2)});
  return points;
}

nlohmann::json Shifted(const nlohmann::json& points, double dx, double dy) {
  nlohmann::json out = nlohmann::json::array();
  for (const nlohmann::json& p : points) out.push_back({p[0].get<double>() + dx, p[1].get<double>() + dy});
  return out;
}

TEST(RealScoreTest, FoundPckAndHandednessFollowTheDefinitions) {
  const auto dir = testing::ScratchDir();
  const nlohmann::json a = Keypoints(100, 100), b = Keypoints(400, 100);
  const double diag = std::hypot(100.0, 100.0);
  Write(dir / "labels.jsonl",
        {{{"file", "images/freihand_1.jpg"}, {"hand", "right"}, {"hand_side_by", "source"}, {"keypoints_2d_px", a}},
         {{"file", "images/onehand10k_2.jpg"}, {"hand", "left"}, {"keypoints_2d_px", a}},
         {{"file", "images/panoptic_3.jpg"}, {"hand", "left"}, {"keypoints_2d_px", a}},
         {{"file", "images/panoptic_3.jpg"}, {"hand", "right"}, {"keypoints_2d_px", b}},
         {{"file", "images/hagrid_call.png"}, {"hand", "right"}, {"bbox_px", {0, 0, 100, 100}}}});
  const std::vector<RealLabel> labels = ReadRealLabels(dir / "labels.jsonl");
  ASSERT_EQ(labels.size(), 5u);
  EXPECT_EQ(labels[0].source, "freihand");
  EXPECT_NEAR(labels[0].diag, diag, 1e-9);
  // freihand: every joint 0.15 diag off (PCK@0.1 0, PCK@0.2 1); onehand10k: off the
  // grown box (not found); panoptic: one hand, the right one, exact and on the wrong side;
  // hagrid: a hand near the box with an extra hand far away.
  const double off = 0.15 * diag / std::sqrt(2.0);
  Write(dir / "predictions.jsonl",
        {{{"file", "freihand_1.png"}, {"hands", {{{"keypoints_2d_px", Shifted(a, off, off)}, {"hand", "right"}}}}, {"ms", 4.0}},
         {{"file", "images/onehand10k_2.jpg"}, {"hands", {{{"keypoints_2d_px", Shifted(a, 500, 0)}}}}, {"ms", 6.0}},
         {{"file", "images/panoptic_3.jpg"}, {"hands", {{{"keypoints_2d_px", b}, {"hand", "left"}}}}},
         {{"file", "images/hagrid_call.png"},
          {"hands", {{{"keypoints_2d_px", Shifted(a, -70, -70)}}, {{"keypoints_2d_px", Shifted(a, 900, 900)}}}}}});
  const RealScore score = ScoreReal(labels, ReadRealPredictions(dir / "predictions.jsonl", labels));
  ASSERT_EQ(score.hands.size(), 5u);
  EXPECT_TRUE(score.hands[0].found);
  EXPECT_DOUBLE_EQ(*score.hands[0].pck_01, 0.0);
  EXPECT_DOUBLE_EQ(*score.hands[0].pck_02, 1.0);
  EXPECT_NEAR(*score.hands[0].mean_norm_err, 0.15, 1e-9);
  EXPECT_TRUE(*score.hands[0].handedness_ok);
  EXPECT_FALSE(score.hands[1].found);
  EXPECT_FALSE(score.hands[2].found) << "the one predicted hand goes to the labelled hand it lies on";
  EXPECT_TRUE(score.hands[3].found);
  EXPECT_FALSE(*score.hands[3].handedness_ok);
  EXPECT_TRUE(score.hands[4].found);
  EXPECT_EQ(score.extras.size(), 2u) << "onehand10k's hand off its box and hagrid's far one";
  EXPECT_EQ(score.gt_all.hands, 5);
  EXPECT_EQ(score.gt_all.found, 3);
  EXPECT_EQ(score.gt_all.kp_hands, 4);
  EXPECT_NEAR(*score.gt_all.pck_02_found, 1.0, 1e-12) << "0.15 and 0 off";
  EXPECT_NEAR(*score.gt_all.pck_02_all, 0.5, 1e-12) << "two of four hands with keypoints found";
  EXPECT_EQ(score.gt_one_hand.hands, 3);
  EXPECT_EQ(score.gt_two_hand.hands, 2);
  EXPECT_EQ(score.gt_two_hand.found, 1);
  EXPECT_EQ(score.gt_all.handedness_n, 2);
  EXPECT_EQ(score.gt_all.handedness_correct, 1);
  EXPECT_EQ(score.gt_all.handedness_source_n, 1);
  EXPECT_DOUBLE_EQ(*score.stills_median_ms, 5.0);
  EXPECT_NE(FormatTable(score).find("GT overall"), std::string::npos);
  EXPECT_EQ(ToJson(score)["overall"]["gt_all"]["found"], 3);
}

TEST(RealScoreTest, AHandNotFoundSaysWhy) {
  const auto dir = testing::ScratchDir();
  const nlohmann::json a = Keypoints(100, 100), b = Keypoints(400, 100);
  std::vector<nlohmann::json> lines;
  for (int i = 1; i <= 4; ++i) {
    lines.push_back({{"file", "images/freihand_" + std::to_string(i) + ".jpg"}, {"hand", "right"}, {"keypoints_2d_px", a}});
  }
  for (int i = 5; i <= 6; ++i) {
    const std::string file = "images/panoptic_" + std::to_string(i) + ".jpg";
    lines.push_back({{"file", file}, {"hand", "right"}, {"keypoints_2d_px", a}});
    lines.push_back({{"file", file}, {"hand", "left"}, {"keypoints_2d_px", b}});
  }
  Write(dir / "labels.jsonl", lines);
  const std::vector<RealLabel> labels = ReadRealLabels(dir / "labels.jsonl");
  ASSERT_EQ(labels.size(), 8u);
  PredictedHand far, on_a;
  for (int k = 0; k < kNumKeypoints; ++k) {
    far.keypoints_2d[k] = Eigen::Vector2d(900.0 + k, 900.0);
    on_a.keypoints_2d[k] = Eigen::Vector2d(a[k][0].get<double>(), a[k][1].get<double>());
  }
  on_a.hand = "right";
  std::vector<RealPrediction> predictions(5);
  for (size_t p = 0; p < 3; ++p) predictions[p].file = labels[p].file;
  // 1: a hand off the labelled one, and the other side's estimate found none (no answer
  // for a right hand); 2: the right side's estimate said why; 3: nothing said (another
  // tool's predictions); 4: never run.
  predictions[0].hands.push_back(far);
  predictions[0].missed = {{"left", "no_skin", "the left side's"}};
  predictions[1].missed = {{"right", "no_skin", "the frame has no colour (greyscale)"}};
  // 5: the right hand found, the left side's estimate found nothing: its own word, not
  // "elsewhere"; 6: both sides found nothing, each answering for its own side.
  predictions[3].file = labels[4].file;
  predictions[3].hands.push_back(on_a);
  predictions[3].missed = {{"left", "not_a_hand", "the left hand's"}};
  predictions[4].file = labels[6].file;
  predictions[4].missed = {{"left", "not_a_hand", "the left hand's"}, {"right", "no_skin", "the right hand's"}};
  const RealScore score = ScoreReal(labels, predictions);
  ASSERT_EQ(score.hands.size(), 8u);
  std::vector<std::pair<std::string, std::string>> got;
  for (const RealHandScore& r : score.hands) got.emplace_back(r.found ? "found" : r.miss, r.miss_reason);
  const std::vector<std::pair<std::string, std::string>> expected = {
      {"elsewhere", ""}, {"no_skin", "the frame has no colour (greyscale)"}, {"no_hand", ""},
      {"not_run", ""},   {"found", ""},
      {"not_a_hand", "the left hand's"},  // panoptic_5's left
      {"no_skin", "the right hand's"},    // panoptic_6's right
      {"not_a_hand", "the left hand's"}};
  EXPECT_EQ(got, expected);
  using Counts = std::map<std::string, int>;
  EXPECT_EQ(score.gt_all.misses, (Counts{{"elsewhere", 1}, {"no_hand", 1}, {"no_skin", 2}, {"not_a_hand", 2}, {"not_run", 1}}));
  EXPECT_EQ(score.gt_one_hand.misses, (Counts{{"elsewhere", 1}, {"no_hand", 1}, {"no_skin", 1}, {"not_run", 1}}));
  const nlohmann::json json = ToJson(score);
  EXPECT_EQ(json["overall"]["gt_all"]["misses"]["no_skin"], 2);
  EXPECT_EQ(json["per_hand"][1]["miss"], "no_skin");
  EXPECT_EQ(json["per_hand"][1]["miss_reason"], "the frame has no colour (greyscale)");
  EXPECT_FALSE(json["per_hand"][0].contains("miss_reason"));
  EXPECT_FALSE(json["per_hand"][4].contains("miss"));
  const std::string table = FormatTable(score);
  EXPECT_NE(table.find("not found, GT overall: elsewhere 1, no_hand 1, no_skin 2, not_a_hand 2, not_run 1\n"), std::string::npos)
      << table;
  EXPECT_NE(table.find("not found, 1-hand images: elsewhere 1, no_hand 1, no_skin 1, not_run 1\n"), std::string::npos) << table;
}

TEST(RealScoreTest, PaMpjpeAndFingerStatesCompareTheShapeOnly) {
  const auto dir = testing::ScratchDir();
  Random random(testing::kTestSeed);
  nlohmann::json truth = nlohmann::json::array(), moved = nlohmann::json::array();
  const Eigen::Matrix3d turn = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  for (int k = 0; k < kNumKeypoints; ++k) {
    const Eigen::Vector3d p(random.Uniform(-0.1, 0.1), random.Uniform(-0.1, 0.1), random.Uniform(0.4, 0.5));
    const Eigen::Vector3d q = 2.0 * turn * p + Eigen::Vector3d(1, 2, 3);
    truth.push_back({p.x(), p.y(), p.z()});
    moved.push_back({q.x(), q.y(), q.z()});
  }
  const nlohmann::json points = Keypoints(50, 50);
  Write(dir / "labels.jsonl", {{{"file", "images/interhand_1.jpg"}, {"hand", "left"}, {"keypoints_2d_px", points},
                                {"keypoints_3d_camera_m", truth}}});
  Write(dir / "predictions.jsonl", {{{"file", "images/interhand_1.jpg"},
                                     {"hands", {{{"keypoints_2d_px", points}, {"keypoints_3d", moved}}}}}});
  const std::vector<RealLabel> labels = ReadRealLabels(dir / "labels.jsonl");
  const RealScore score = ScoreReal(labels, ReadRealPredictions(dir / "predictions.jsonl", labels));
  EXPECT_NEAR(*score.hands[0].pa_mpjpe_mm, 0.0, 1e-6);
  EXPECT_EQ(*score.hands[0].finger_agree, 4);
  EXPECT_EQ(ToJson(score)["per_hand"][0]["pa_ref"], "keypoints_3d_camera_m");
  EXPECT_EQ(score.gt_all.finger_total, 4);
  EXPECT_FALSE(score.hands[0].handedness_ok.has_value()) << "no side predicted";
}

// 3D keypoints whose index, middle, ring and little finger are straight (true) or folded.
nlohmann::json HandShowing(const std::array<bool, 4>& straight) {
  nlohmann::json points = nlohmann::json::array();
  for (int k = 0; k < 5; ++k) points.push_back({0.01 * k, -0.01, 0.0});  // wrist, thumb
  for (int f = 0; f < 4; ++f) {
    const double x = 0.02 * f;
    points.push_back({x, 0.0, 0.0});
    points.push_back({x, 0.04, 0.0});
    points.push_back(straight[f] ? nlohmann::json{x, 0.065, 0.0} : nlohmann::json{x, 0.04, 0.025});
    points.push_back(straight[f] ? nlohmann::json{x, 0.085, 0.0} : nlohmann::json{x, 0.02, 0.025});
  }
  return points;
}

// A labelled gesture whose fingers are plain is the truth of the prediction's finger states;
// one that leaves them open (a claw) is not scored.
TEST(RealScoreTest, AGesturesClassFixesItsFingerStates) {
  EXPECT_EQ(*RealGestureFingers("peace"), (std::array<bool, 4>{true, true, false, false}));
  EXPECT_EQ(*RealGestureFingers("Thumb_Up"), (std::array<bool, 4>{false, false, false, false}));
  EXPECT_FALSE(RealGestureFingers("grabbing").has_value());
  EXPECT_FALSE(RealGestureFingers("holy").has_value());
  const auto dir = testing::ScratchDir();
  const nlohmann::json box = {10, 10, 90, 90}, points = Keypoints(50, 50);
  Write(dir / "labels.jsonl", {{{"file", "images/hagrid_peace.png"}, {"hand", "right"}, {"bbox_px", box}, {"gesture", "peace"}},
                               {{"file", "images/hagrid_fist.png"}, {"hand", "right"}, {"bbox_px", box}, {"gesture", "fist"}},
                               {{"file", "images/hagrid_grabbing.png"}, {"hand", "right"}, {"bbox_px", box}, {"gesture", "grabbing"}}});
  const nlohmann::json peace = {{"keypoints_2d_px", points}, {"keypoints_3d", HandShowing({true, true, false, false})}};
  Write(dir / "predictions.jsonl", {{{"file", "images/hagrid_peace.png"}, {"hands", {peace}}},
                                    {{"file", "images/hagrid_fist.png"}, {"hands", {peace}}},
                                    {{"file", "images/hagrid_grabbing.png"}, {"hands", {peace}}}});
  const std::vector<RealLabel> labels = ReadRealLabels(dir / "labels.jsonl");
  const RealScore score = ScoreReal(labels, ReadRealPredictions(dir / "predictions.jsonl", labels));
  EXPECT_EQ(*score.hands[0].gesture_finger_agree, 4);
  EXPECT_EQ(*score.hands[1].gesture_finger_agree, 2) << "a victory sign read where the fist is";
  EXPECT_FALSE(score.hands[2].gesture_finger_agree.has_value());
  EXPECT_EQ(score.gt_all.gesture_finger_agree, 6);
  EXPECT_EQ(score.gt_all.gesture_finger_total, 8);
  EXPECT_EQ(ToJson(score)["per_source"]["hagrid"]["gesture_finger_total"], 8);
  EXPECT_NE(FormatTable(score).find("6/8"), std::string::npos);
}

// A right palm towards the camera, fingers up: the thumb's side (index MCP) on the right.
TEST(RealScoreTest, WhichSideFacesTheCameraFollowsTheTurnAndTheHandsSide) {
  const Eigen::Vector2d wrist(100, 200), index(120, 160), little(80, 160);
  EXPECT_EQ(FacingOf(wrist, index, little, "right"), Facing::kPalm);
  EXPECT_EQ(FacingOf(wrist, index, little, "left"), Facing::kBack);
  EXPECT_EQ(FacingOf(wrist, little, index, "right"), Facing::kBack) << "the mirror image";
  const Eigen::Rotation2Dd turn(2.5);
  EXPECT_EQ(FacingOf(turn * wrist, turn * index, turn * little, "right"), Facing::kPalm) << "any roll";
  EXPECT_EQ(FacingOf(wrist, index, Eigen::Vector2d(118, 160), "right"), Facing::kUnknown) << "edge-on";
  EXPECT_EQ(FacingOf(wrist, std::nullopt, little, "right"), Facing::kUnknown) << "an MCP unlabelled";
  EXPECT_EQ(FacingOf(wrist, index, little, ""), Facing::kUnknown) << "no side";

  const auto dir = testing::ScratchDir();
  nlohmann::json palm = Keypoints(0, 0);
  palm[0] = {wrist.x(), wrist.y()};
  palm[5] = {index.x(), index.y()};
  palm[17] = {little.x(), little.y()};
  nlohmann::json back = palm;
  back[5] = palm[17];
  back[17] = palm[5];
  Write(dir / "labels.jsonl", {{{"file", "images/freihand_1.jpg"}, {"hand", "right"}, {"keypoints_2d_px", palm}},
                               {{"file", "images/freihand_2.jpg"}, {"hand", "right"}, {"keypoints_2d_px", palm}},
                               {{"file", "images/freihand_3.jpg"}, {"hand", "right"}, {"keypoints_2d_px", palm}}});
  Write(dir / "predictions.jsonl", {{{"file", "images/freihand_1.jpg"}, {"hands", {{{"keypoints_2d_px", palm}}}}},
                                    {{"file", "images/freihand_2.jpg"}, {"hands", {{{"keypoints_2d_px", back}}}}},
                                    {{"file", "images/freihand_3.jpg"}, {"hands", {{{"keypoints_2d_px", back}, {"hand", "left"}}}}}});
  const std::vector<RealLabel> labels = ReadRealLabels(dir / "labels.jsonl");
  const RealScore score = ScoreReal(labels, ReadRealPredictions(dir / "predictions.jsonl", labels));
  EXPECT_TRUE(*score.hands[0].facing_ok);
  EXPECT_FALSE(*score.hands[1].facing_ok);
  EXPECT_TRUE(*score.hands[2].facing_ok) << "a left hand's mirror image shows the palm as the right one does";
  EXPECT_EQ(score.gt_all.facing_n, 3);
  EXPECT_EQ(score.gt_all.facing_correct, 2);
  EXPECT_EQ(ToJson(score)["overall"]["gt_all"]["palm_back_correct"], 2);
  EXPECT_NE(FormatTable(score).find("2/3"), std::string::npos);
}

// Steadiness on video: a hand whose labels move steadily and whose estimate shakes 3 px up
// and down about them; a frame off its hand ends the run of found frames.
TEST(RealScoreTest, AVideosJitterIsMeasuredOverRunsOfFoundFramesBesideTheLabels) {
  const auto dir = testing::ScratchDir();
  std::vector<nlohmann::json> labels_lines, prediction_lines;
  for (int t = 0; t < 7; ++t) {
    const nlohmann::json label = Keypoints(100 + 10 * t, 100);
    labels_lines.push_back({{"file", "videos/asl_hand.mp4"}, {"frame", t}, {"hand", "right"}, {"keypoints_2d_px", label}});
    const nlohmann::json estimate = t == 5 ? Shifted(label, 900, 0) : Shifted(label, 0, t % 2 == 0 ? 3.0 : -3.0);
    prediction_lines.push_back({{"file", "videos/asl_hand.mp4"}, {"frame", t}, {"hands", {{{"keypoints_2d_px", estimate}}}}});
  }
  Write(dir / "labels.jsonl", labels_lines);
  Write(dir / "predictions.jsonl", prediction_lines);
  const std::vector<RealLabel> labels = ReadRealLabels(dir / "labels.jsonl");
  const RealScore score = ScoreReal(labels, ReadRealPredictions(dir / "predictions.jsonl", labels));
  ASSERT_EQ(score.videos.size(), 1u);
  const RealSteadiness& s = score.videos[0];
  EXPECT_EQ(s.file, "videos/asl_hand.mp4");
  EXPECT_EQ(s.hand, "right");
  EXPECT_EQ(s.frames, 7);
  EXPECT_EQ(s.second_differences, 3) << "centred on frames 1-3: frame 5 was not found";
  // |3 - 2 (-3) + 3| = 12 px, over the box's diagonal.
  EXPECT_NEAR(*s.jitter, 12.0 / std::hypot(100.0, 100.0), 1e-12);
  EXPECT_NEAR(*s.label_jitter, 0.0, 1e-12);
  EXPECT_NEAR(ToJson(score)["videos"][0]["jitter_diag"].get<double>(), *s.jitter, 1e-12);
  EXPECT_NE(FormatTable(score).find("steadiness, videos/asl_hand.mp4 (right): 2D jitter 0.0849"), std::string::npos)
      << FormatTable(score);
}

TEST(RealScoreTest, MalformedLabelsAndPredictionsAreRefusedByLine) {
  const auto dir = testing::ScratchDir();
  const nlohmann::json good = {{"file", "images/freihand_1.jpg"}, {"hand", "right"}, {"keypoints_2d_px", Keypoints(0, 0)}};
  const auto refused = [&](const std::vector<nlohmann::json>& lines, const std::string& needle) {
    Write(dir / "labels.jsonl", lines);
    testing::ExpectError([&] { ReadRealLabels(dir / "labels.jsonl"); }, needle);
  };
  refused({good, {{"hand", "right"}}}, "labels.jsonl: line 2: no 'file'");
  refused({good, good, {{"file", "x.jpg"}, {"keypoints_2d_px", {{1, 2}}}}}, "line 3: keypoints_2d_px must hold 21");
  refused({{{"file", "x.jpg"}, {"hand", "both"}, {"keypoints_2d_px", Keypoints(0, 0)}}}, "line 1: hand must be");
  refused({{{"file", "x.jpg"}}}, "line 1: has neither keypoints_2d_px nor bbox_px");
  refused({{{"file", "x.jpg"}, {"frame", -3}, {"bbox_px", {0, 0, 1, 1}}}}, "line 1: 'frame' must be a frame number");
  {
    std::ofstream(dir / "labels.jsonl") << good.dump() << "\n{not json\n";
  }
  testing::ExpectError([&] { ReadRealLabels(dir / "labels.jsonl"); }, "line 2 is not a JSON object");
  Write(dir / "labels.jsonl", {good});
  const std::vector<RealLabel> labels = ReadRealLabels(dir / "labels.jsonl");
  Write(dir / "p.jsonl", {{{"file", "images/other.jpg"}, {"hands", nlohmann::json::array()}}});
  testing::ExpectError([&] { ReadRealPredictions(dir / "p.jsonl", labels); }, "p.jsonl: line 1: file 'images/other.jpg' matches no labelled image");
  Write(dir / "p.jsonl", {{{"file", "freihand_1"}}, {{"file", "images/freihand_1.jpg"}}});
  testing::ExpectError([&] { ReadRealPredictions(dir / "p.jsonl", labels); }, "line 2: a second prediction");
}

// Predictions made from the labels themselves, deterministically spoiled: joints moved by
// noise of several sizes, some hands dropped, some moved off, sides flipped, an extra hand,
// 3D bent; so that every measure and every matching rule has work.
std::vector<RealPrediction> SpoiledPredictions(const std::vector<RealLabel>& labels) {
  Random random(testing::kTestSeed);
  std::map<std::pair<std::string, int>, RealPrediction> by_key;
  for (const RealLabel& label : labels) {
    RealPrediction& p = by_key[label.key()];
    p.file = label.file;
    p.frame = label.frame;
    p.ms = random.Uniform(1.0, 9.0);
    if (random.Uniform() < 0.15) continue;  // not found
    PredictedHand hand;
    const double noise = label.diag * std::vector<double>{0.02, 0.08, 0.15, 0.4}[random.UniformIndex(4)];
    const Eigen::Vector2d centre((label.box[0] + label.box[2]) / 2, (label.box[1] + label.box[3]) / 2);
    const Eigen::Vector2d away = random.Uniform() < 0.1 ? Eigen::Vector2d(3.0 * label.diag, 0.0) : Eigen::Vector2d::Zero();
    for (int k = 0; k < kNumKeypoints; ++k) {
      const Eigen::Vector2d base = label.keypoints_2d[k].value_or(centre);
      hand.keypoints_2d[k] = base + away + noise * Eigen::Vector2d(random.Normal(), random.Normal());
    }
    if (label.keypoints_3d.has_value()) {
      Keypoints3d k3 = *label.keypoints_3d;
      for (Eigen::Vector3d& q : k3) q += 0.01 * Eigen::Vector3d(random.Normal(), random.Normal(), random.Normal());
      hand.keypoints_3d = k3;
    }
    if (random.Uniform() < 0.8) hand.hand = random.Uniform() < 0.8 ? label.hand : (label.hand == "left" ? "right" : "left");
    p.hands.push_back(hand);
    if (random.Uniform() < 0.05) {
      PredictedHand extra = hand;
      for (Eigen::Vector2d& q : extra.keypoints_2d) q += Eigen::Vector2d(5.0 * label.diag, 5.0 * label.diag);
      p.hands.push_back(extra);
    }
  }
  std::vector<RealPrediction> predictions;
  for (auto& [key, p] : by_key) {
    if (random.Uniform() < 0.03) continue;  // not run
    predictions.push_back(std::move(p));
  }
  return predictions;
}

void ExpectSame(const nlohmann::json& ours, const nlohmann::json& reference, const std::string& where) {
  for (const auto& [key, value] : reference.items()) {
    if (!ours.contains(key)) continue;  // the reference reports more than these figures
    const nlohmann::json& mine = ours[key];
    if (value.is_null() || value.is_string() || value.is_boolean()) {
      EXPECT_EQ(mine, value) << where << " " << key;
    } else if (value.is_number()) {
      // The reference rounds per-hand figures (errors to 1e-6, pixels and mm to 1e-3).
      EXPECT_NEAR(mine.get<double>(), value.get<double>(), key.find("px") != std::string::npos || key.find("mm") != std::string::npos ? 2e-3 : 2e-6)
          << where << " " << key;
    }
  }
}

TEST(RealScoreTest, FiguresAreTheReferenceScorersOnTheSamePredictions) {
  const std::filesystem::path dev = testing::RealDevDir();
  if (!std::filesystem::exists(dev / "labels.jsonl") || !std::filesystem::exists(dev / "score_realdev.py")) {
    GTEST_SKIP() << dev << " is not here (real-dev is not shipped with nphand)";
  }
  if (std::system("python3 -c 'import statistics' >/dev/null 2>&1") != 0) GTEST_SKIP() << "no python3 for the reference";
  const auto dir = testing::ScratchDir();
  const std::vector<RealLabel> labels = ReadRealLabels(dev / "labels.jsonl");
  EXPECT_EQ(labels.size(), 390u);
  // The fingerspelling video shows a right palm throughout: the facing's sense on a real hand.
  for (const RealLabel& label : labels) {
    if (label.source != "asl_video") continue;
    EXPECT_EQ(FacingOf(label.keypoints_2d, label.hand), Facing::kPalm)
        << "frame " << *label.frame;
  }
  const std::vector<RealPrediction> predictions = SpoiledPredictions(labels);
  {
    std::ofstream out(dir / "predictions.jsonl");
    for (const RealPrediction& p : predictions) out << ToJson(p).dump() << "\n";
  }
  const std::string command = "python3 '" + (dev / "score_realdev.py").string() + "' --labels '" + (dev / "labels.jsonl").string() +
                              "' --pred '" + (dir / "predictions.jsonl").string() + "' --out-json '" +
                              (dir / "reference.json").string() + "' --out-table /dev/null";
  ASSERT_EQ(std::system(command.c_str()), 0) << command;
  nlohmann::json reference;
  std::ifstream(dir / "reference.json") >> reference;
  const nlohmann::json run = reference["runs"][0];
  const nlohmann::json ours = ToJson(ScoreReal(labels, ReadRealPredictions(dir / "predictions.jsonl", labels)));
  for (const auto& [source, figures] : run["per_source"].items()) {
    ASSERT_TRUE(ours["per_source"].contains(source)) << source;
    ExpectSame(ours["per_source"][source], figures, source);
  }
  for (const char* part : {"gt_all", "gt_one_hand_images", "gt_two_hand_images"}) {
    ExpectSame(ours["overall"][part], run["overall"][part], part);
  }
  EXPECT_NEAR(ours["timing"]["stills_median_ms"].get<double>(), run["timing"]["stills"]["median_ms"].get<double>(), 1e-9);
  EXPECT_NEAR(ours["timing"]["video_median_ms"].get<double>(), run["timing"]["video_frames"]["median_ms"].get<double>(), 1e-9);
  ASSERT_EQ(ours["per_hand"].size(), run["per_hand"].size());
  for (size_t i = 0; i < run["per_hand"].size(); ++i) {
    EXPECT_EQ(ours["per_hand"][i]["found"], run["per_hand"][i]["found"]) << i;
  }
}

}  // namespace
}  // namespace nphand
