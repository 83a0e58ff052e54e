#include "nphand/eval/feature_study.h"

#include <cmath>

#include <gtest/gtest.h>

#include "nphand/util/check.h"
#include "testing/testing.h"
#include "testing/tiny_db.h"

namespace nphand {
namespace {

class FeatureStudyTest : public testing::TinyDatabaseTest {
 protected:
  static FeatureStudyOptions Options() {
    FeatureStudyOptions options;
    options.queries = 40;
    options.neighbours = 10;
    options.features = {"joints", "hog8x8x8", "dist32", "chamfer_rerank"};
    return options;
  }
};

TEST_F(FeatureStudyTest, CurvesHaveOneValuePerNeighbourAndAreDeterministic) {
  const FeatureStudyResult a = RunFeatureStudy(db(), Options(), nullptr);
  ASSERT_EQ(a.curves.size(), 4u);
  for (const FeatureCurve& c : a.curves) {
    ASSERT_EQ(c.joint_deg.size(), 10u);
    for (int k = 0; k < 10; ++k) {
      EXPECT_TRUE(std::isfinite(c.joint_deg[k]) && c.joint_deg[k] >= 0.0) << c.name;
      EXPECT_TRUE(std::isfinite(c.wrist_deg[k]) && c.wrist_deg[k] >= 0.0) << c.name;
    }
  }
  EXPECT_EQ(a.curves[1].dimension, 512);
  EXPECT_EQ(a.curves[2].dimension, 1024);
  const FeatureStudyResult b = RunFeatureStudy(db(), Options(), nullptr);
  EXPECT_EQ(a.curves[1].joint_deg, b.curves[1].joint_deg);
}

TEST_F(FeatureStudyTest, QueryAndItsTwinAreLeftOut) {
  // Every entry has a twin with the same pose (with/without the object): were it not left
  // out, pose-space neighbour 1 would always be exact.
  const FeatureStudyResult result = RunFeatureStudy(db(), Options(), nullptr);
  EXPECT_GT(result.curves[0].joint_deg[0] + result.curves[0].wrist_deg[0], 0.1);
}

TEST_F(FeatureStudyTest, PoseSpaceBoundsTheWristErrorOfFeatures) {
  const FeatureStudyResult result = RunFeatureStudy(db(), Options(), nullptr);
  EXPECT_LE(result.curves[0].wrist_deg[0], result.curves[1].wrist_deg[0]);
}

TEST_F(FeatureStudyTest, RollNormalisationMakesRolledQueriesFindTheirPose) {
  FeatureStudyOptions options = Options();
  options.features = {"hog8x8x8"};
  options.roll_queries = true;
  const double rolled = RunFeatureStudy(db(), options, nullptr).curves[0].wrist_deg[0];
  options.normalize_roll = true;
  const double normalized = RunFeatureStudy(db(), options, nullptr).curves[0].wrist_deg[0];
  // Unnormalised HOG cannot match a turned hand; normalised it recovers the roll.
  EXPECT_LT(normalized, 0.6 * rolled) << "rolled " << rolled << ", normalised " << normalized;
}

TEST_F(FeatureStudyTest, OutputsDescribeTheResult) {
  const FeatureStudyResult result = RunFeatureStudy(db(), Options(), nullptr);
  const nlohmann::json json = ToJson(result);
  EXPECT_EQ(json["curves"].size(), 4u);
  EXPECT_EQ(json["curves"][1]["paper_joint_deg"][0], 1.32);
  const std::string table = FormatTable(result);
  EXPECT_NE(table.find("hog8x8x8"), std::string::npos);
  EXPECT_NE(table.find("1.32 (2.04, 3.25, 4.19)"), std::string::npos);
  const cv::Mat plot = PlotCurves(result);
  EXPECT_EQ(plot.type(), CV_8UC3);
  EXPECT_GT(cv::countNonZero(plot.reshape(1) != 255), 1000);
}

TEST_F(FeatureStudyTest, BadOptionsAreRefused) {
  FeatureStudyOptions options = Options();
  options.features = {"sift"};
  EXPECT_THROW(RunFeatureStudy(db(), options, nullptr), Error);
  // More queries than entries used to be reported as asked, not as run.
  options = Options();
  options.queries = 99999999;
  try {
    RunFeatureStudy(db(), options, nullptr);
    ADD_FAILURE() << "ran 99999999 queries on 160 entries";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("only"), std::string::npos) << e.what();
  }
}

// The database is searched a chunk at a time (memory flat in its size); chunks of any size
// give the same study.
TEST_F(FeatureStudyTest, ChunkedSearchEqualsOneSearch) {
  FeatureStudyOptions options = Options();
  options.normalize_roll = true;
  const FeatureStudyResult whole = RunFeatureStudy(db(), options, nullptr);
  options.chunk = 7;
  const FeatureStudyResult chunked = RunFeatureStudy(db(), options, nullptr);
  for (size_t f = 0; f < whole.curves.size(); ++f) {
    for (size_t i = 0; i < whole.curves[f].joint_deg.size(); ++i) {
      EXPECT_NEAR(whole.curves[f].joint_deg[i], chunked.curves[f].joint_deg[i], 1e-9) << whole.curves[f].name;
      EXPECT_NEAR(whole.curves[f].wrist_deg[i], chunked.curves[f].wrist_deg[i], 1e-9) << whole.curves[f].name;
    }
  }
}

}  // namespace
}  // namespace nphand
