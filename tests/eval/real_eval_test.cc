// The estimator on real photographs: a subset of real-dev (when it is here) on which the
// hand must be found, not the face behind it, the forearm or the background. The database
// is small (every grasp, 24 views: seconds to build), so the subset is of hands it finds as
// the full database does; what is tested is where the estimator looks, not its pose.
#include "nphand/eval/real_eval.h"

#include <memory>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "nphand/db/builder.h"
#include "nphand/index/backends.h"
#include "testing/testing.h"

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
  build.directions = 24;
  build.threads = 2;
  BuildDatabase(testing::RightHand(), build, dir / "small.db", nullptr);
  const Database db = Database::Open(dir / "small.db");
  const std::unique_ptr<KnnIndex> index = BuildIndex(db, IndexOptions::Exact());
  EstimatorOptions options;
  Estimator right(db, *index, testing::RightHand(), options);
  options.hand = Handedness::kLeft;
  Estimator left(db, *index, testing::RightHand(), options);

  const RealScore score = ScoreReal(labels, EstimateReal(labels, dev, &right, &left, nullptr));
  for (const RealHandScore& hand : score.hands) EXPECT_TRUE(hand.found) << hand.label->file;
}

}  // namespace
}  // namespace nphand
