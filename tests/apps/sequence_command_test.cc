// The sequence command: a hand of other proportions than the database's, said in
// sequence.json and seen in the truth's keypoints; proportions out of range refused.
#include "apps/sequence_command.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "testing/testing.h"

namespace nphand {
namespace {

SequenceCommandOptions Small(const std::filesystem::path& out) {
  SequenceCommandOptions options;
  options.sequence.frames = 2;
  options.sequence.width = 160;
  options.sequence.height = 120;
  options.sequence.grasp = 1;
  options.out_dir = out;
  return options;
}

nlohmann::json FirstTruth(const std::filesystem::path& dir) {
  std::ifstream in(dir / "truth.jsonl");
  std::string line;
  std::getline(in, line);
  return nlohmann::json::parse(line);
}

double Distance(const nlohmann::json& points, int a, int b) {
  double squares = 0.0;
  for (int i = 0; i < 3; ++i) {
    const double d = points[a][i].get<double>() - points[b][i].get<double>();
    squares += d * d;
  }
  return std::sqrt(squares);
}

TEST(SequenceCommandTest, AHandOfOtherProportionsIsRenderedAndSaidSo) {
  const auto dir = testing::ScratchDir();
  const nlohmann::json base = RunSequence(Small(dir / "base"), nullptr);
  SequenceCommandOptions options = Small(dir / "narrow");
  options.proportions = {1.1, 0.9};
  const nlohmann::json narrow = RunSequence(options, nullptr);
  EXPECT_EQ(base["hand_proportions"], (nlohmann::json{{"length", 1.0}, {"width", 1.0}}));
  EXPECT_EQ(narrow["hand_proportions"], (nlohmann::json{{"length", 1.1}, {"width", 0.9}}));
  EXPECT_NEAR(narrow["hand_length_m"].get<double>() / base["hand_length_m"].get<double>(), 1.1, 0.01);
  // The index and little fingers' knuckles (keypoints 5 and 17) lie 0.9 times as far apart.
  const nlohmann::json a = FirstTruth(dir / "base")["keypoints_3d_hand_m"], b = FirstTruth(dir / "narrow")["keypoints_3d_hand_m"];
  EXPECT_NEAR(Distance(b, 5, 17) / Distance(a, 5, 17), 0.9, 0.03);
  options.proportions = {1.1, 2.5};
  testing::ExpectError([&] { RunSequence(options, nullptr); }, "length and width factors must be within [0.5, 2]");
  options.proportions = {1.1};
  testing::ExpectError([&] { RunSequence(options, nullptr); }, "--proportions takes two factors");
}

TEST(SequenceCommandTest, AGestureReplacesTheGraspAndItsObject) {
  const auto dir = testing::ScratchDir();
  SequenceCommandOptions options = Small(dir / "gesture");
  options.sequence.grasp = 0;
  options.gesture = "Thumbs Up";
  const nlohmann::json gesture = RunSequence(options, nullptr);
  EXPECT_EQ(gesture["grasp"]["name"], "thumbs_up");
  EXPECT_TRUE(gesture["object"].is_null());
  EXPECT_EQ(gesture["object_scale"], 0.0);
  EXPECT_FALSE(FirstTruth(dir / "gesture")["object_in_view"].get<bool>());
  options.sequence.grasp = 1;
  testing::ExpectError([&] { RunSequence(options, nullptr); }, "--grasp and --gesture exclude each other");
}

}  // namespace
}  // namespace nphand
