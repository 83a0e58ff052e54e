// The estimator on real photographs: a subset of real-dev (when it is here) on which the
// hand must be found, not the face behind it, the forearm or the background. The database
// is small (every grasp, 24 views: seconds to build), so the subset is of hands it finds as
// the full database does; what is tested is where the estimator looks, not its pose.
#include "nphand/eval/real_eval.h"

#include <array>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include <fstream>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "nphand/db/builder.h"
#include "nphand/index/backends.h"
#include "nphand/sequence/sequence.h"
#include "nphand/util/check.h"
#include "testing/testing.h"
#include "testing/tiny_db.h"

namespace nphand {
namespace {

TEST(RealEvalTest, TheHandIsFoundOnRealPhotographs) {
  const std::filesystem::path dev = testing::RealDevDir();
  if (!std::filesystem::exists(dev / "labels.jsonl")) {
    GTEST_SKIP() << dev << " is not here (real-dev is not shipped with nphand)";
  }
  // One of each kind: a finger before the lips, hands before a wall (palm and back,
  // pointing, a grip), a thumbs-up cut out, and hands holding objects against a green
  // screen and a landscape.
  const std::set<std::string> subset = {
      "images/hagrid_mute.png",         "images/hagrid_stop.png",       "images/hagrid_palm.png",
      "images/hagrid_one.png",          "images/hagrid_grip.png",       "images/hagrid_point.png",
      "images/mediapipe_thumbs_up.png", "images/freihand_00000355.jpg", "images/freihand_00032915.jpg"};
  std::vector<RealLabel> labels;
  for (const RealLabel& label : ReadRealLabels(dev / "labels.jsonl")) {
    if (subset.contains(label.file)) labels.push_back(label);
  }
  ASSERT_EQ(labels.size(), subset.size()) << "real-dev's labels changed";

  const auto dir = testing::ScratchDir();
  DatabaseBuildOptions build;
  // 64 viewing directions of the default 648: with 24, the pointing fist (its knuckle
  // towards the camera joined by skin's rim) was read from a view too far off, and its
  // estimate left the hand's box; the default database finds it.
  build.directions = 64;
  build.threads = 2;
  BuildDatabase(testing::RightHand(), build, dir / "small.db", nullptr);
  const Database db = Database::Open(dir / "small.db");
  const std::unique_ptr<KnnIndex> index = BuildIndex(db, IndexOptions::Exact());
  EstimatorOptions options;
  Estimator right(db, *index, testing::RightHand(), options);
  options.hand = Handedness::kLeft;
  Estimator left(db, *index, testing::RightHand(), options);

  const RealScore score = ScoreReal(labels, EstimateReal(labels, dev, &right, &left, {}, nullptr));
  for (const RealHandScore& hand : score.hands) EXPECT_TRUE(hand.found) << hand.label->file;
}

// The tiny database's estimator options: no faces looked for, and "no hand" only far off
// (the tiny database's views are far apart).
EstimatorOptions TinyOptions(Handedness hand = Handedness::kRight) {
  EstimatorOptions options;
  options.skin.face_cascade.clear();
  options.max_distance = 2.0;
  options.hand = hand;
  return options;
}

// A rendered right hand in grasp 1's first frame, 0.4 m away, `width` x `height`.
SequenceFrame RenderedHand(int width, int height) {
  SequenceOptions settings;
  settings.frames = 1;
  settings.grasp = 1;
  settings.width = width;
  settings.height = height;
  settings.distance_m = 0.4;
  settings.seed = testing::kTestSeed;
  return Sequence(testing::RightHand(), settings).Render(0);
}

// A label line for `file`: a right hand at `keypoints` shifted by `shift` pixels along x.
std::string LabelLine(const std::string& file, const std::array<Eigen::Vector2d, kNumKeypoints>& keypoints, double shift = 0.0) {
  nlohmann::json points = nlohmann::json::array();
  for (const Eigen::Vector2d& k : keypoints) points.push_back({k.x() + shift, k.y()});
  return nlohmann::json({{"file", file}, {"hand", "right"}, {"keypoints_2d_px", points}}).dump() + "\n";
}

// With the box given, each labelled hand of a still is estimated alone, within its region:
// two hands side by side give two estimates, each on its own hand; without it, one search
// a labelled side finds one of them.
TEST(RealEvalTest, WithTheBoxGivenEachLabelledHandIsEstimatedInItsRegion) {
  const auto dir = testing::ScratchDir();
  const Database db = Database::Open(testing::BuildTinyDatabase(dir / "tiny.db"));
  const std::unique_ptr<KnnIndex> index = BuildIndex(db, IndexOptions::Exact());
  Estimator right(db, *index, testing::RightHand(), TinyOptions());
  Estimator left(db, *index, testing::RightHand(), TinyOptions(Handedness::kLeft));
  const SequenceFrame frame = RenderedHand(240, 180);
  cv::Mat two;
  cv::hconcat(frame.rgb, frame.rgb, two);
  std::filesystem::create_directories(dir / "images");
  ASSERT_TRUE(cv::imwrite((dir / "images" / "two.png").string(), two));
  {
    std::ofstream out(dir / "labels.jsonl");
    for (double shift : {0.0, 240.0}) out << LabelLine("images/two.png", frame.keypoints_2d, shift);
  }
  const std::vector<RealLabel> labels = ReadRealLabels(dir / "labels.jsonl");
  const std::vector<RealPrediction> one = EstimateReal(labels, dir, &right, &left, {}, nullptr);
  ASSERT_EQ(one.size(), 1u);
  EXPECT_LE(one[0].hands.size(), 1u);
  const std::vector<RealPrediction> given = EstimateReal(labels, dir, &right, &left, {.given_box = true}, nullptr);
  ASSERT_EQ(given.size(), 1u);
  ASSERT_EQ(given[0].hands.size(), 2u);
  for (int h = 0; h < 2; ++h) {
    Eigen::Vector2d centre = Eigen::Vector2d::Zero();
    for (const Eigen::Vector2d& k : given[0].hands[h].keypoints_2d) centre += k / kNumKeypoints;
    EXPECT_GE(centre.x(), labels[h].region[0]) << h;
    EXPECT_LE(centre.x(), labels[h].region[2]) << h;
  }

  // A labelled image without skin: no hand, and the estimate's word for it kept.
  ASSERT_TRUE(cv::imwrite((dir / "images" / "wall.png").string(), cv::Mat(180, 240, CV_8UC3, cv::Scalar(160, 90, 40))));
  {
    std::ofstream out(dir / "wall.jsonl");
    out << LabelLine("images/wall.png", frame.keypoints_2d);
  }
  const std::vector<RealLabel> wall = ReadRealLabels(dir / "wall.jsonl");
  const std::vector<RealPrediction> none = EstimateReal(wall, dir, &right, &left, {}, nullptr);
  ASSERT_EQ(none.size(), 1u);
  EXPECT_TRUE(none[0].hands.empty());
  ASSERT_EQ(none[0].missed.size(), 1u);
  EXPECT_EQ(none[0].missed[0].hand, "right");
  EXPECT_EQ(none[0].missed[0].status, "no_skin");
  EXPECT_FALSE(none[0].missed[0].reason.empty());
  EXPECT_EQ(ScoreReal(wall, none).hands[0].miss, "no_skin");
}

// A frame shrunk before the estimator sees it (a webcam's lower resolution): the hand is
// still found, also within its region given, its keypoints come back in the labels' pixels,
// near where the whole frame puts them; a longer side of the frame's own or more leaves the
// frame as it is, and one under 16 pixels is refused by name.
TEST(RealEvalTest, AShrunkFrameIsScoredInTheLabelsPixels) {
  const auto dir = testing::ScratchDir();
  const Database db = Database::Open(testing::BuildTinyDatabase(dir / "tiny.db"));
  const std::unique_ptr<KnnIndex> index = BuildIndex(db, IndexOptions::Exact());
  Estimator right(db, *index, testing::RightHand(), TinyOptions());
  const SequenceFrame frame = RenderedHand(320, 240);
  std::filesystem::create_directories(dir / "images");
  ASSERT_TRUE(cv::imwrite((dir / "images" / "hand.png").string(), frame.rgb));
  {
    std::ofstream out(dir / "labels.jsonl");
    out << LabelLine("images/hand.png", frame.keypoints_2d);
  }
  const std::vector<RealLabel> labels = ReadRealLabels(dir / "labels.jsonl");
  auto centre = [](const RealPrediction& p) {
    Eigen::Vector2d c = Eigen::Vector2d::Zero();
    for (const Eigen::Vector2d& k : p.hands.at(0).keypoints_2d) c += k / kNumKeypoints;
    return c;
  };
  Eigen::Vector2d low = frame.keypoints_2d[0], high = frame.keypoints_2d[0];
  for (const Eigen::Vector2d& k : frame.keypoints_2d) {
    low = low.cwiseMin(k);
    high = high.cwiseMax(k);
  }
  const double diagonal = (high - low).norm();
  const std::vector<RealPrediction> whole = EstimateReal(labels, dir, &right, nullptr, {}, nullptr);
  ASSERT_EQ(whole.size(), 1u);
  ASSERT_EQ(whole[0].hands.size(), 1u);
  for (const RealRunOptions run : {RealRunOptions{.max_side = 160}, RealRunOptions{.max_side = 80},
                                   RealRunOptions{.given_box = true, .max_side = 160}}) {
    const std::string name = std::to_string(run.max_side) + (run.given_box ? ", box given" : "");
    const std::vector<RealPrediction> shrunk = EstimateReal(labels, dir, &right, nullptr, run, nullptr);
    ASSERT_EQ(shrunk.size(), 1u);
    ASSERT_EQ(shrunk[0].hands.size(), 1u) << name;
    EXPECT_TRUE(ScoreReal(labels, shrunk).hands[0].found) << name;
    EXPECT_NE(shrunk[0].hands[0].keypoints_2d, whole[0].hands[0].keypoints_2d) << name << ": not shrunk";
    // Within a sixth of the hand's diagonal of the whole frame's estimate (measured: 0.006
    // of it at a half, 0.08 at a quarter, where the hand's keypoints span 39 pixels).
    EXPECT_LT((centre(shrunk[0]) - centre(whole[0])).norm(), diagonal / 6.0) << name;
  }
  for (int side : {320, 640}) {
    const std::vector<RealPrediction> as_is = EstimateReal(labels, dir, &right, nullptr, {.max_side = side}, nullptr);
    ASSERT_EQ(as_is.size(), 1u);
    ASSERT_EQ(as_is[0].hands.size(), 1u) << side;
    EXPECT_EQ(as_is[0].hands[0].keypoints_2d, whole[0].hands[0].keypoints_2d) << side;
  }
  // The smallest side taken: a 16 x 12 frame, estimated (no hand in it is an answer too).
  EXPECT_EQ(EstimateReal(labels, dir, &right, nullptr, {.max_side = 16}, nullptr).size(), 1u);
  for (int side : {-1, 8}) {
    try {
      EstimateReal(labels, dir, &right, nullptr, {.max_side = side}, nullptr);
      ADD_FAILURE() << side << " was taken";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("--max-side"), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace nphand
