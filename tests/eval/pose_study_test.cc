#include "nphand/eval/pose_study.h"

#include <algorithm>
#include <cmath>
#include <iostream>
#include <set>

#include <unistd.h>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "nphand/db/builder.h"
#include "nphand/eval/pose_methods.h"
#include "nphand/eval/pose_report.h"
#include "nphand/index/exact_index.h"
#include "testing/testing.h"

namespace nphand {
namespace {

using testing::RightHand;

TEST(SegmentationNoiseTest, RemovesTheShareAskedThenOpensTheMask) {
  cv::Mat mask = cv::Mat::zeros(200, 200, CV_8UC1);
  cv::circle(mask, {100, 100}, 60, cv::Scalar(1), cv::FILLED);
  const double pixels = cv::countNonZero(mask);
  EXPECT_EQ(cv::countNonZero(SegmentationNoise(mask, 0.0, 1) != (mask != 0)), 0) << "alpha 0: the mask itself";
  double previous = pixels;
  for (double alpha : {1.0, 3.0, 5.0}) {
    const cv::Mat noisy = SegmentationNoise(mask, alpha, 7);
    EXPECT_EQ(cv::countNonZero(noisy & ~(mask != 0)), 0) << "an opening only removes";
    const double kept = cv::countNonZero(noisy);
    // Erosion grows each removed pixel to 3 x 3 and dilation gives back most of it.
    EXPECT_LT(kept, pixels * (1.0 - alpha / 100.0) + 1.0) << alpha;
    EXPECT_LT(kept, previous) << alpha;
    previous = kept;
  }
  EXPECT_EQ(cv::countNonZero(SegmentationNoise(mask, 3.0, 7) != SegmentationNoise(mask, 3.0, 7)), 0) << "seeded";
  EXPECT_GT(cv::countNonZero(SegmentationNoise(mask, 3.0, 7) != SegmentationNoise(mask, 3.0, 8)), 0);
  testing::ExpectError([&] { SegmentationNoise(mask, -1.0, 1); }, "alpha");
  testing::ExpectError([&] { SegmentationNoise(cv::Mat(), 1.0, 1); }, "mask");
}

TEST(StudySequencesTest, HeldOutAndEachVariantChangesOneThing) {
  const std::vector<StudySequence> tests = TestSequences(100, 640, 480, 9000, false);
  ASSERT_GE(tests.size(), 4u);
  std::set<uint64_t> seeds;
  for (const StudySequence& s : tests) {
    seeds.insert(s.options.seed);
    EXPECT_TRUE(s.options.seed < 7000 || s.options.seed > 7023) << "not the validation sweep's";
    EXPECT_NE(s.options.object_scale, 1.0) << s.name << ": an object size the database lacks";
    EXPECT_TRUE(s.options.object) << s.name;
    EXPECT_NE(s.options.forearm, ForearmKind::kNone) << s.name << ": a forearm in view";
    EXPECT_GT(s.options.roll_deg, 0.0) << s.name;
    std::string why;
    EXPECT_TRUE(s.options.Check(&why)) << why;
  }
  EXPECT_EQ(seeds.size(), tests.size());

  const std::vector<StudySequence> variants = RobustnessSequences(100, 640, 480, 9100, false);
  ASSERT_GE(variants.size(), 5u);
  const StudySequence& base = variants[0];
  for (size_t v = 1; v < variants.size(); ++v) {
    const StudySequence& s = variants[v];
    const int changed = (s.options.skin != base.options.skin) + (s.options.background != base.options.background) +
                        (s.options.forearm != base.options.forearm) + (s.length != base.length || s.width != base.width);
    EXPECT_EQ(changed, 1) << s.name;
    EXPECT_EQ(s.options.seed, base.options.seed) << s.name << ": the same motion";
    EXPECT_EQ(s.options.grasp, base.options.grasp);
  }
}

// With `adult_arm` every sequence's forearm is an adult's; otherwise none is.
TEST(StudySequencesTest, AdultArmsWhenAsked) {
  for (const bool adult : {false, true}) {
    std::vector<StudySequence> all = TestSequences(100, 640, 480, 9000, adult);
    const std::vector<StudySequence> variants = RobustnessSequences(100, 640, 480, 9100, adult);
    all.insert(all.end(), variants.begin(), variants.end());
    for (const StudySequence& s : all) {
      EXPECT_EQ(s.options.adult_arm, adult) << s.name;
      std::string why;
      EXPECT_TRUE(s.options.Check(&why)) << s.name << ": " << why;
    }
  }
}

// A database of the test sequences' grasps only, small enough to build in seconds, and
// the test sequences at a quarter of the pixels.
class PoseStudyTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    path_ = new std::filesystem::path(std::filesystem::temp_directory_path() /
                                      ("nphand_pose_study_" + std::to_string(::getpid()) + ".db"));
    DatabaseBuildOptions options;
    for (const StudySequence& s : TestSequences(2, 64, 64, 1, false)) options.grasps.push_back(s.options.grasp);
    std::sort(options.grasps.begin(), options.grasps.end());
    options.gestures = {};
    options.directions = 96;
    options.image_size = 96;
    options.threads = 2;
    BuildDatabase(RightHand(), options, *path_, nullptr);
    db_ = new Database(Database::Open(*path_));
    index_ = new ExactIndex(DatabaseDescriptors(*db_));
    sequences_ = new std::vector<RenderedSequence>(RenderSequences(RightHand(), TestSequences(24, 320, 240, 9000, false), nullptr));
  }
  static void TearDownTestSuite() {
    delete sequences_;
    delete index_;
    delete db_;
    std::filesystem::remove(*path_);
    delete path_;
  }
  static const MethodScore& Find(const std::vector<MethodScore>& scores, const std::string& method,
                                 const std::string& sequence, double alpha) {
    const auto it = std::find_if(scores.begin(), scores.end(), [&](const MethodScore& s) {
      return s.method == method && s.sequence == sequence && s.alpha == alpha;
    });
    EXPECT_NE(it, scores.end()) << method << " " << sequence << " " << alpha;
    return *it;
  }

  static std::filesystem::path* path_;
  static Database* db_;
  static KnnIndex* index_;
  static std::vector<RenderedSequence>* sequences_;
};

std::filesystem::path* PoseStudyTest::path_ = nullptr;
Database* PoseStudyTest::db_ = nullptr;
KnnIndex* PoseStudyTest::index_ = nullptr;
std::vector<RenderedSequence>* PoseStudyTest::sequences_ = nullptr;

// The paper's central orderings (Fig. 6) on a reduced study: clean masks, the estimator
// with exact search, the regressions fitted on the same database.
TEST_F(PoseStudyTest, TheEstimatorBeatsTheBaselinesAndNearsTheBound) {
  EstimatorOptions pnp;
  pnp.hand_length_m = ModelHandLength(*db_);
  EstimatorOptions nn = pnp;
  nn.prior = PriorCombination::kNone;
  std::vector<std::unique_ptr<PoseMethod>> methods;
  methods.push_back(MakeEstimatorMethod("PNP", *db_, *index_, RightHand(), pnp, false));
  methods.push_back(MakeEstimatorMethod("NN feature", *db_, *index_, RightHand(), nn, false));
  methods.push_back(MakeNearestPoseMethod(*db_));
  methods.push_back(MakeMeanPoseMethod(*db_));
  methods.push_back(MakeRegressionMethod(*db_, MakeLinearRegressor(), 3000, 1, nullptr));
  methods.push_back(MakeRegressionMethod(*db_, MakeGaussianProcess(), 600, 1, nullptr));
  methods.push_back(MakeRegressionMethod(*db_, MakeRvm(), 300, 1, nullptr));
  EXPECT_EQ(methods[0]->Describe()["mode_mean"], pnp.mode_mean);
  const std::vector<MethodScore> scores = RunMethods(methods, *sequences_, {0.0, 2.0}, RightHand(), 5, nullptr);
  ASSERT_EQ(scores.size(), methods.size() * 2 * (sequences_->size() + 1));

  std::cout << FormatScores(scores);
  const MethodScore& estimator = Find(scores, "PNP", "all", 0.0);
  const MethodScore& bound = Find(scores, "NN pose", "all", 0.0);
  EXPECT_GE(estimator.detected, estimator.frames * 9 / 10);
  EXPECT_DOUBLE_EQ(bound.keypoint_norm, 1.0);
  for (const MethodScore& s : scores) {
    EXPECT_EQ(s.frames, s.sequence == "all" ? 24 * static_cast<int>(sequences_->size()) : 24) << s.method;
    EXPECT_EQ(s.lag_frames.has_value(), s.detected > 0) << s.method;
    if (s.detected == 0) continue;
    EXPECT_TRUE(std::isfinite(s.keypoint_mm) && std::isfinite(s.pa_mpjpe_mm) && std::isfinite(s.auc_0_50)) << s.method;
    EXPECT_LE(s.pa_mpjpe_mm, s.keypoint_mm + 1e-9) << s.method << ": alignment can only help";
    EXPECT_EQ(std::isfinite(s.keypoint_px), s.method == "PNP" || s.method == "NN feature") << s.method << ": who places the hand";
  }
  EXPECT_EQ(bound.lag_frames, 0) << "the truth's nearest pose, frame by frame, does not trail it";
  EXPECT_EQ(ToJson(bound)["lag_frames"], 0);
  // Frames turned about a half turn are counted: never the truth's nearest pose, but the mean
  // pose, whose rotation is every view's average, often.
  for (const MethodScore& s : scores) EXPECT_LE(s.turned, s.detected) << s.method;
  EXPECT_EQ(bound.turned, 0);
  EXPECT_EQ(ToJson(bound)["turned"], 0);
  EXPECT_GT(Find(scores, "mean pose", "all", 0.0).turned, 0);
  EXPECT_NE(FormatScores(scores).find(" turned "), std::string::npos);
  for (const char* metric : {"pose", "keypoints"}) {
    const auto value = [&](const MethodScore& s) { return std::string(metric) == "pose" ? s.pose_error : s.keypoint_mm; };
    EXPECT_LE(value(bound), value(estimator)) << metric << ": the database's resolution bounds the estimator";
    for (const char* baseline : {"NN feature", "LSQ", "GP", "RVM", "mean pose"}) {
      EXPECT_LT(value(estimator), value(Find(scores, baseline, "all", 0.0))) << metric << ": PNP against " << baseline;
    }
    EXPECT_LT(value(estimator), 3.0 * value(bound)) << metric << ": PNP within 3x the NN-pose bound";
  }
  // The regressions learned something: each beats the mean pose.
  for (const char* regression : {"LSQ", "GP", "RVM"}) {
    EXPECT_LT(Find(scores, regression, "all", 0.0).keypoint_mm, Find(scores, "mean pose", "all", 0.0).keypoint_mm) << regression;
  }
}

TEST_F(PoseStudyTest, BadOptionsAreNamed) {
  PoseStudyOptions options;
  std::string why;
  EXPECT_TRUE(options.Check(&why));
  options.alphas = {1.0, -2.0};
  EXPECT_FALSE(options.Check(&why));
  EXPECT_NE(why.find("alpha"), std::string::npos);
  options = {};
  options.frames = 1;
  testing::ExpectError([&] { RunPoseStudy(PoseStudyPart::kBaselines, *db_, *index_, RightHand(), {}, options, nullptr); },
                       "frames");
  testing::ExpectError([&] { MakeRegressionMethod(*db_, MakeLinearRegressor(), 1, 1, nullptr); }, "rows");
}

}  // namespace
}  // namespace nphand
