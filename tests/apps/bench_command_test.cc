#include "apps/bench_command.h"

#include <gtest/gtest.h>

#include "nphand/util/check.h"

namespace nphand {
namespace {

TEST(BenchCommandTest, ReportsTheRateAndWhatItMeasured) {
  BenchRenderOptions options;
  options.images = 20;
  const nlohmann::json report = RunBenchRender(options);
  EXPECT_GT(report.at("label_images_per_s").get<double>(), 0.0);
  EXPECT_EQ(report.at("width").get<int>(), 128);
  EXPECT_EQ(report.at("hand_triangles").get<int>(), 2314);
  EXPECT_GT(report.at("object_triangles").get<int>(), 0);
  EXPECT_GT(report.at("mean_hand_pixels").get<double>(), 100.0) << "the hand must be in view";
  EXPECT_FALSE(report.at("machine").get<std::string>().empty());
  options.images = 0;
  EXPECT_THROW(RunBenchRender(options), Error);
}

}  // namespace
}  // namespace nphand
