// The estimator on real photographs: a subset of real-dev (when it is here) on which the
// hand must be found, not the face behind it, the forearm or the background. The database
// is small (every grasp, 24 views: seconds to build), so the subset is of hands it finds as
// the full database does; what is tested is where the estimator looks, not its pose.
#include "nphand/eval/real_eval.h"

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

  const RealScore score = ScoreReal(labels, EstimateReal(labels, dev, &right, &left, false, nullptr));
  for (const RealHandScore& hand : score.hands) EXPECT_TRUE(hand.found) << hand.label->file;
}

// With the box given, each labelled hand of a still is estimated alone, within its region:
// two hands side by side give two estimates, each on its own hand; without it, one search
// a labelled side finds one of them.
TEST(RealEvalTest, WithTheBoxGivenEachLabelledHandIsEstimatedInItsRegion) {
  const auto dir = testing::ScratchDir();
  const Database db = Database::Open(testing::BuildTinyDatabase(dir / "tiny.db"));
  const std::unique_ptr<KnnIndex> index = BuildIndex(db, IndexOptions::Exact());
  EstimatorOptions options;
  options.skin.face_cascade.clear();
  options.max_distance = 2.0;  // the tiny database's views are far apart
  Estimator right(db, *index, testing::RightHand(), options);
  options.hand = Handedness::kLeft;
  Estimator left(db, *index, testing::RightHand(), options);

  SequenceOptions settings;
  settings.frames = 1;
  settings.grasp = 1;
  settings.width = 240;
  settings.height = 180;
  settings.distance_m = 0.4;
  settings.seed = testing::kTestSeed;
  const SequenceFrame frame = Sequence(testing::RightHand(), settings).Render(0);
  cv::Mat two;
  cv::hconcat(frame.rgb, frame.rgb, two);
  std::filesystem::create_directories(dir / "images");
  ASSERT_TRUE(cv::imwrite((dir / "images" / "two.png").string(), two));
  {
    std::ofstream out(dir / "labels.jsonl");
    for (double shift : {0.0, 240.0}) {
      nlohmann::json keypoints = nlohmann::json::array();
      for (const Eigen::Vector2d& k : frame.keypoints_2d) keypoints.push_back({k.x() + shift, k.y()});
      out << nlohmann::json({{"file", "images/two.png"}, {"hand", "right"}, {"keypoints_2d_px", keypoints}}).dump() << "\n";
    }
  }
  const std::vector<RealLabel> labels = ReadRealLabels(dir / "labels.jsonl");
  const std::vector<RealPrediction> one = EstimateReal(labels, dir, &right, &left, false, nullptr);
  ASSERT_EQ(one.size(), 1u);
  EXPECT_LE(one[0].hands.size(), 1u);
  const std::vector<RealPrediction> given = EstimateReal(labels, dir, &right, &left, true, nullptr);
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
    nlohmann::json keypoints = nlohmann::json::array();
    for (const Eigen::Vector2d& k : frame.keypoints_2d) keypoints.push_back({k.x(), k.y()});
    std::ofstream out(dir / "wall.jsonl");
    out << nlohmann::json({{"file", "images/wall.png"}, {"hand", "right"}, {"keypoints_2d_px", keypoints}}).dump() << "\n";
  }
  const std::vector<RealLabel> wall = ReadRealLabels(dir / "wall.jsonl");
  const std::vector<RealPrediction> none = EstimateReal(wall, dir, &right, &left, false, nullptr);
  ASSERT_EQ(none.size(), 1u);
  EXPECT_TRUE(none[0].hands.empty());
  ASSERT_EQ(none[0].missed.size(), 1u);
  EXPECT_EQ(none[0].missed[0].hand, "right");
  EXPECT_EQ(none[0].missed[0].status, "no_skin");
  EXPECT_FALSE(none[0].missed[0].reason.empty());
  EXPECT_EQ(ScoreReal(wall, none).hands[0].miss, "no_skin");
}

}  // namespace
}  // namespace nphand
