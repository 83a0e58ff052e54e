#include "nphand/eval/estimator_study.h"

#include <algorithm>
#include <set>

#include <gtest/gtest.h>

#include "nphand/index/exact_index.h"
#include "testing/testing.h"
#include "testing/tiny_db.h"

namespace nphand {
namespace {

class EstimatorStudyTest : public testing::TinyDatabaseTest {
 protected:
  // Two sequences of four 160x120 frames.
  static EstimatorStudyOptions Small() {
    EstimatorStudyOptions options;
    options.sequences = 2;
    options.frames = 4;
    options.width = 160;
    options.height = 120;
    return options;
  }
};

TEST_F(EstimatorStudyTest, EverySettingIsNamedOnceAndVariesWhatItSays) {
  const EstimatorOptions base;
  const std::vector<EstimatorSetting> sweep = EstimatorSweep(base);
  for (const EstimatorSetting& s : sweep) {
    EXPECT_EQ(std::count_if(sweep.begin(), sweep.end(), [&](const EstimatorSetting& o) { return o.name == s.name; }), 1)
        << s.name;
    std::string why;
    EXPECT_TRUE(s.options.Check(&why)) << s.name << ": " << why;
  }
  const auto find = [&](const std::string& name) {
    return *std::find_if(sweep.begin(), sweep.end(), [&](const EstimatorSetting& s) { return s.name == name; });
  };
  EXPECT_EQ(find("nn").options.prior, PriorCombination::kNone);
  EXPECT_EQ(find("turns0").options.roll_ambiguity, 0.0);
  EXPECT_EQ(find("mode-mean0").options.mode_mean, 0.0);
  EXPECT_EQ(find("mode-mean2").options.mode_mean, 2.0);
  EXPECT_EQ(find("k50").options.k, 50);
  EXPECT_EQ(find("k250").options.k, 250);
  EXPECT_EQ(find("k2000").options.k, 2000);
  EXPECT_EQ(find("track-views0").options.track_views, 0);
  EXPECT_EQ(find("track-views8").options.track_views, 8);
  EXPECT_EQ(find("carried20").options.carried, 20);
  EXPECT_EQ(find("carry-apart30").options.carry_apart_frames, 30);
  EXPECT_EQ(EstimatorOptions{}.carry_apart_frames, 0);
  EXPECT_EQ(find("reset3-m0.1").options.prior_reset_frames, 3);
  EXPECT_EQ(find("reset3-m0.1").options.prior_reset_margin, 0.1);
  EXPECT_EQ(find("reset10-m0.05").options.prior_reset_frames, 10);
  EXPECT_FALSE(find("nn").options.refine);
  EXPECT_TRUE(find("refine").options.refine);
  EXPECT_FALSE(find("refine").options.refinement.move_fingers);
  EXPECT_TRUE(find("refine-fingers4").options.refinement.move_fingers);
  EXPECT_EQ(find("refine-fingers4").options.refinement.joint_step_deg, 4.0);
  EXPECT_FALSE(find("refine-place").options.refinement.move_wrist);
  EXPECT_EQ(find("refine-render128-sweeps6").options.refinement.render_side, 128);
  EXPECT_EQ(find("max-distance0.9").options.max_distance, 0.9);
}

// On the rendered masks (the paper's input) hands are found, and refinement is reported as
// part of a setting's options.
TEST_F(EstimatorStudyTest, MasksAreTheRenderedHandsOwn) {
  const ExactIndex index(DatabaseDescriptors(db()));
  EstimatorStudyOptions options = Small();
  options.masks = true;
  options.settings = {"nn", "refine"};
  const std::vector<EstimatorScore> scores = RunEstimatorStudy(db(), index, testing::RightHand(), {}, options, nullptr);
  ASSERT_EQ(scores.size(), 2u);
  EXPECT_EQ(scores[0].options["refine"], false);
  EXPECT_EQ(scores[1].options["refine"]["render_side"], 64);
  for (const EstimatorScore& s : scores) EXPECT_GT(s.detected, 0) << s.name;
}

// The validation sequences vary the forearm (none, bare, sleeved), the background and a
// face; asked for, the sequences with a forearm render an adult's arm.
TEST(ValidationSequencesTest, VaryTheSceneAndTakeAnAdultArmWhenAsked) {
  EstimatorStudyOptions options;
  const std::vector<SequenceOptions> cone = ValidationSequences(options);
  options.adult_arm = true;
  const std::vector<SequenceOptions> adult = ValidationSequences(options);
  ASSERT_EQ(cone.size(), 24u);
  ASSERT_EQ(adult.size(), cone.size());
  std::set<int> forearms, backgrounds;
  int faces = 0;
  for (size_t i = 0; i < cone.size(); ++i) {
    EXPECT_EQ(cone[i].seed, options.seed + i);
    forearms.insert(static_cast<int>(cone[i].forearm));
    backgrounds.insert(static_cast<int>(cone[i].background));
    faces += cone[i].face;
    EXPECT_FALSE(cone[i].adult_arm);
    EXPECT_EQ(adult[i].adult_arm, cone[i].forearm != ForearmKind::kNone) << i;
    EXPECT_EQ(adult[i].forearm, cone[i].forearm);
    std::string why;
    EXPECT_TRUE(adult[i].Check(&why)) << why;
  }
  EXPECT_EQ(forearms.size(), 3u);
  EXPECT_EQ(backgrounds.size(), 3u);
  EXPECT_EQ(faces, 6);
}

TEST_F(EstimatorStudyTest, RunsTheNamedSettingsOverTheSequences) {
  const ExactIndex index(DatabaseDescriptors(db()));
  EstimatorStudyOptions options = Small();
  options.settings = {"nn", "turns0", "turns0.3"};
  const std::vector<EstimatorScore> scores = RunEstimatorStudy(db(), index, testing::RightHand(), {}, options, nullptr);
  ASSERT_EQ(scores.size(), 3u);
  for (const EstimatorScore& s : scores) {
    EXPECT_EQ(s.frames, 8) << s.name;
    EXPECT_LE(s.detected, s.frames);
    EXPECT_LE(s.both_turns, s.detected);
    EXPECT_LE(s.flipped, s.detected);
    EXPECT_GE(s.keypoint_mm, 0.0);
  }
  EXPECT_EQ(scores[1].name, "turns0");
  EXPECT_EQ(scores[1].both_turns, 0) << "never the half turn";
  EXPECT_EQ(scores[1].options["roll_ambiguity"], 0.0);
  EXPECT_EQ(scores[1].options["mode_mean"], EstimatorOptions{}.mode_mean);
  EXPECT_GE(scores[2].both_turns, scores[1].both_turns);
  const nlohmann::json json = ToJson(scores);
  EXPECT_EQ(json.size(), 3u);
  EXPECT_TRUE(json[0].contains("both_turns"));
  EXPECT_TRUE(json[0].contains("jitter_mm"));
  EXPECT_TRUE(json[0].contains("flipped"));
  EXPECT_NE(FormatTable(scores).find("turns0.3"), std::string::npos);

  options.settings = {"nonesuch"};
  testing::ExpectError([&] { RunEstimatorStudy(db(), index, testing::RightHand(), {}, options, nullptr); }, "nonesuch");
  options.settings.clear();
  options.frames = 1;
  testing::ExpectError([&] { RunEstimatorStudy(db(), index, testing::RightHand(), {}, options, nullptr); }, "frames");
}

}  // namespace
}  // namespace nphand
