// Errors of poses against the truth, on lines written here: an exact copy has no error,
// every keypoint within 20 mm and an AUC of 1; a turned copy keeps no error after the
// Procrustes alignment; jitter is measured over runs of detected frames only; a copy a frame
// late lags by one.
#include "nphand/eval/pose_errors.h"

#include <fstream>
#include <numbers>

#include <gtest/gtest.h>

#include "nphand/util/random.h"
#include "testing/testing.h"

namespace nphand {
namespace {

// A line of poses.jsonl / truth.jsonl for `frame` with hand keypoints `hand` (metres).
nlohmann::json Line(int frame, bool detected, const std::vector<Eigen::Vector3d>& hand) {
  nlohmann::json line = {{"frame", frame}, {"detected", detected}};
  if (!detected) return line;
  nlohmann::json h = nlohmann::json::array(), c = nlohmann::json::array(), p = nlohmann::json::array();
  for (const Eigen::Vector3d& k : hand) {
    h.push_back({k.x(), k.y(), k.z()});
    c.push_back({k.x(), k.y(), k.z() + 0.5});
    p.push_back({320.0 + 1000.0 * k.x(), 240.0 + 1000.0 * k.y()});
  }
  line["keypoints_3d_hand_m"] = h;
  line["keypoints_3d_camera_m"] = c;
  line["keypoints_2d_px"] = p;
  line["joint_angles_deg"] = {{"index_pip_flex", 30.0}, {"thumb_ip_flex", 10.0}};
  line["wrist_rotation"] = {{1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, {0.0, 0.0, 1.0}};
  return line;
}

std::filesystem::path Write(const std::filesystem::path& path, const std::vector<nlohmann::json>& lines) {
  std::ofstream out(path);
  for (const nlohmann::json& line : lines) out << line.dump() << "\n";
  return path;
}

class PoseErrorsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    Random random(testing::kTestSeed);
    for (int f = 0; f < 8; ++f) {
      std::vector<Eigen::Vector3d> hand(kNumKeypoints, Eigen::Vector3d::Zero());
      for (int k = 1; k < kNumKeypoints; ++k) {
        hand[k] = Eigen::Vector3d(random.Uniform(-0.09, 0.09), random.Uniform(-0.09, 0.09), random.Uniform(-0.03, 0.03));
      }
      hands_.push_back(hand);
    }
  }
  std::vector<std::vector<Eigen::Vector3d>> hands_;  // per frame, the wrist at the origin
};

TEST_F(PoseErrorsTest, AnExactCopyHasNoErrorAndATurnedOneNoneAfterAlignment) {
  const auto dir = testing::ScratchDir();
  std::vector<nlohmann::json> truth, turned;
  const Eigen::Matrix3d turn = Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  for (int f = 0; f < 8; ++f) {
    truth.push_back(Line(f, true, hands_[f]));
    std::vector<Eigen::Vector3d> t = hands_[f];
    for (Eigen::Vector3d& k : t) k = turn * k;
    turned.push_back(Line(f, true, t));
  }
  const PoseErrorSummary same = ComparePoses(Write(dir / "truth.jsonl", truth), dir / "truth.jsonl");
  EXPECT_EQ(same.detected, 8);
  for (double v : same.mean) EXPECT_NEAR(v, 0.0, 1e-9);
  EXPECT_DOUBLE_EQ(same.within_20mm, 1.0);
  EXPECT_DOUBLE_EQ(same.auc_0_50, 1.0);
  EXPECT_NEAR(same.jitter_mm, same.truth_jitter_mm, 1e-9);
  EXPECT_GT(same.truth_jitter_mm, 0.0);
  EXPECT_EQ(same.lag_frames, 0);

  const PoseErrorSummary other = ComparePoses(dir / "truth.jsonl", Write(dir / "turned.jsonl", turned));
  EXPECT_GT(other.mean[2], 5.0) << "keypoint_mm sees the turn";
  EXPECT_NEAR(other.mean[5], 0.0, 1e-6) << "pa_mpjpe_mm does not";
  EXPECT_LT(other.within_20mm, 1.0);
  EXPECT_LT(other.auc_0_50, 1.0);
  const nlohmann::json json = ToJson(other);
  EXPECT_TRUE(json["mean"].contains("pa_mpjpe_mm"));
  EXPECT_TRUE(json.contains("auc_0_50"));
  EXPECT_TRUE(json["per_frame"][0].contains("pa_mpjpe_mm"));
  EXPECT_NE(FormatTable(other).find("AUC 0-50 mm"), std::string::npos);
}

// A wrist 135 degrees or more from the truth's is turned about a half turn, and counted;
// one 134.5 degrees off is merely wrong.
TEST_F(PoseErrorsTest, AWristTurnedAboutAHalfTurnIsCounted) {
  const auto dir = testing::ScratchDir();
  std::vector<nlohmann::json> truth, poses;
  for (int f = 0; f < 8; ++f) {
    truth.push_back(Line(f, true, hands_[f]));
    nlohmann::json line = Line(f, f != 7, hands_[f]);
    const double deg = f < 3 ? 170.0 : f == 3 ? 135.5 : f == 4 ? 134.5 : 0.0;
    const Eigen::Matrix3d r = Eigen::AngleAxisd(deg * std::numbers::pi / 180.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    if (f != 7) line["wrist_rotation"] = {{r(0, 0), r(0, 1), r(0, 2)}, {r(1, 0), r(1, 1), r(1, 2)}, {r(2, 0), r(2, 1), r(2, 2)}};
    poses.push_back(line);
  }
  const PoseErrorSummary s = ComparePoses(Write(dir / "truth.jsonl", truth), Write(dir / "poses.jsonl", poses));
  EXPECT_EQ(s.detected, 7);
  EXPECT_EQ(s.turned, 4);
  EXPECT_EQ(ToJson(s)["turned"], 4);
  EXPECT_NE(FormatTable(s).find("half turn (135 degrees or more off) in 4 of 7 detected frames"), std::string::npos)
      << FormatTable(s);
}

TEST_F(PoseErrorsTest, JitterSkipsTheGapsOfUndetectedFrames) {
  const auto dir = testing::ScratchDir();
  std::vector<nlohmann::json> truth, poses;
  for (int f = 0; f < 8; ++f) {
    truth.push_back(Line(f, true, hands_[0]));  // a still hand
    // Detected on 0-2 and 5-7; on frames 3 and 4 "no hand". A still estimate on each run,
    // the two runs far apart: no jitter unless a window spans the gap.
    std::vector<Eigen::Vector3d> moved = hands_[f < 4 ? 0 : 1];
    poses.push_back(Line(f, f < 3 || f > 4, moved));
  }
  const PoseErrorSummary s = ComparePoses(Write(dir / "truth.jsonl", truth), Write(dir / "poses.jsonl", poses));
  EXPECT_EQ(s.detected, 6);
  EXPECT_NEAR(s.jitter_mm, 0.0, 1e-9);
  EXPECT_NEAR(s.truth_jitter_mm, 0.0, 1e-9);
}
TEST_F(PoseErrorsTest, ACopyAFrameLateLagsByOne) {
  const auto dir = testing::ScratchDir();
  std::vector<nlohmann::json> truth, late;
  for (int f = 0; f < 8; ++f) {
    truth.push_back(Line(f, true, hands_[f]));
    late.push_back(Line(f, f > 0, hands_[std::max(f - 1, 0)]));
  }
  const PoseErrorSummary s = ComparePoses(Write(dir / "truth.jsonl", truth), Write(dir / "late.jsonl", late));
  EXPECT_EQ(s.lag_frames, 1);
  EXPECT_EQ(ToJson(s)["lag_frames"], 1);
  EXPECT_NE(FormatTable(s).find("lag behind the truth 1 frame ("), std::string::npos) << FormatTable(s);
  // Across a gap in the frame numbers the truth before the gap is not one frame back.
  std::vector<nlohmann::json> gapped_truth, gapped;
  for (int i = 0; i < 8; ++i) {
    const int f = i < 4 ? i : i + 6;
    gapped_truth.push_back(Line(f, true, hands_[i]));
    gapped.push_back(Line(f, i == 4, hands_[3]));
  }
  const PoseErrorSummary g = ComparePoses(Write(dir / "gapped_truth.jsonl", gapped_truth), Write(dir / "gapped.jsonl", gapped));
  EXPECT_EQ(g.lag_frames, 0);
}

TEST_F(PoseErrorsTest, APartRunOrAnotherSequenceIsRefused) {
  const auto dir = testing::ScratchDir();
  std::vector<nlohmann::json> truth, poses;
  for (int f = 0; f < 8; ++f) truth.push_back(Line(f, true, hands_[f]));
  for (int f = 0; f < 5; ++f) poses.push_back(Line(f, true, hands_[f]));
  Write(dir / "truth.jsonl", truth);
  testing::ExpectError([&] { ComparePoses(dir / "truth.jsonl", Write(dir / "part.jsonl", poses)); },
                       "part.jsonl has 5 frames and " + (dir / "truth.jsonl").string() + " 8: a run is scored whole");
  for (int f = 5; f < 10; ++f) poses.push_back(Line(f, true, hands_[f % 8]));
  testing::ExpectError([&] { ComparePoses(dir / "truth.jsonl", Write(dir / "long.jsonl", poses)); }, "has 10 frames");
}

// The side of the hand towards the camera: an estimate mirrored left to right shows the
// other side; an edge-on truth, or lines without a side, are not judged.
TEST_F(PoseErrorsTest, ThePalmOrBackTowardsTheCameraIsJudgedFromTheKeypointsAndTheSide) {
  const auto dir = testing::ScratchDir();
  std::vector<Eigen::Vector3d> palm(kNumKeypoints, Eigen::Vector3d::Zero()), mirrored, edge_on;
  for (int k = 1; k < kNumKeypoints; ++k) palm[k] = Eigen::Vector3d(0.002 * k, -0.09, 0.0);
  palm[5] = Eigen::Vector3d(0.02, -0.08, 0.0);    // index MCP on the right of the screen: a right palm
  palm[17] = Eigen::Vector3d(-0.02, -0.07, 0.0);  // little MCP on the left
  for (const Eigen::Vector3d& k : palm) mirrored.push_back(Eigen::Vector3d(-k.x(), k.y(), k.z()));
  edge_on = palm;
  edge_on[17] = Eigen::Vector3d(0.019, -0.07, 0.0);
  std::vector<nlohmann::json> truth, poses;
  const std::vector<std::pair<const std::vector<Eigen::Vector3d>*, const std::vector<Eigen::Vector3d>*>> frames = {
      {&palm, &palm}, {&palm, &mirrored}, {&edge_on, &mirrored}, {&palm, &palm}};
  for (size_t f = 0; f < frames.size(); ++f) {
    truth.push_back(Line(static_cast<int>(f), true, *frames[f].first));
    poses.push_back(Line(static_cast<int>(f), true, *frames[f].second));
    if (f < 3) truth.back()["hand"] = poses.back()["hand"] = "right";
  }
  const PoseErrorSummary s = ComparePoses(Write(dir / "truth.jsonl", truth), Write(dir / "poses.jsonl", poses));
  EXPECT_TRUE(*s.frames[0].palm_back_ok);
  EXPECT_FALSE(*s.frames[1].palm_back_ok);
  EXPECT_FALSE(s.frames[2].palm_back_ok.has_value()) << "the truth edge-on";
  EXPECT_FALSE(s.frames[3].palm_back_ok.has_value()) << "no side";
  EXPECT_EQ(s.palm_back_judged, 2);
  EXPECT_EQ(s.palm_back_right, 1);
  EXPECT_EQ(ToJson(s)["palm_back_right"], 1);
  EXPECT_NE(FormatTable(s).find("right in 1 of 2"), std::string::npos);
}

TEST_F(PoseErrorsTest, NothingDetectedReadsAsNothingMeasuredNotAsPerfect) {
  const auto dir = testing::ScratchDir();
  std::vector<nlohmann::json> truth, poses;
  for (int f = 0; f < 4; ++f) {
    truth.push_back(Line(f, true, hands_[f]));
    poses.push_back(Line(f, false, hands_[f]));
  }
  const PoseErrorSummary s = ComparePoses(Write(dir / "truth.jsonl", truth), Write(dir / "poses.jsonl", poses));
  EXPECT_EQ(s.detected, 0);
  const nlohmann::json json = ToJson(s);
  for (const char* key : {"within_20mm", "auc_0_50", "jitter_mm", "truth_jitter_mm", "lag_frames"}) {
    EXPECT_TRUE(json[key].is_null()) << key;
  }
  for (const auto& [name, value] : json["mean"].items()) EXPECT_TRUE(value.is_null()) << name;
  const std::string table = FormatTable(s);
  EXPECT_NE(table.find("detected 0 of 4 frames"), std::string::npos);
  EXPECT_EQ(table.find("0.00"), std::string::npos) << table;
  EXPECT_NE(table.find("n/a"), std::string::npos);
}

}  // namespace
}  // namespace nphand
