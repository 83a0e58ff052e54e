#include "apps/render_command.h"

#include <opencv2/imgcodecs.hpp>
#include <gtest/gtest.h>

#include <cmath>

#include "nphand/util/check.h"
#include "nphand/util/io.h"
#include "testing/testing.h"

namespace nphand {
namespace {

TEST(RenderCommandTest, WritesTheFourImages) {
  RenderCommandOptions options;
  options.out_dir = testing::ScratchDir();
  options.width = options.height = 96;
  options.pose = "pinch";
  options.angles = {"index_pip_flex=30"};
  options.object = "cylinder";
  options.object_size = {0.02, 0.1};
  options.object_at = {0.09, 0.0, -0.05};
  const RenderCommandResult result = RunRender(options);
  ASSERT_EQ(result.files.size(), 4u);
  for (const auto& path : result.files) {
    const cv::Mat image = cv::imread(path.string(), cv::IMREAD_UNCHANGED);
    ASSERT_FALSE(image.empty()) << path;
    EXPECT_EQ(image.cols, 96);
  }
  EXPECT_GT(result.hand_pixels, 200);
  EXPECT_GT(result.object_pixels, 50);
}

TEST(RenderCommandTest, BadOptionsGiveErrorsThatNameThem) {
  const auto expect_error = [](RenderCommandOptions options, const std::string& needle) {
    options.out_dir = testing::ScratchDir();
    try {
      RunRender(options);
      ADD_FAILURE() << "no error for " << needle;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    }
  };
  RenderCommandOptions options;
  options.angles = {"index_pip_flex=170"};
  expect_error(options, "outside its limits");
  options.angles = {"wrist_flex=10"};
  expect_error(options, "wrist_flex");
  options.angles = {"index_pip_flex=ten"};
  expect_error(options, "not a number");
  options.angles = {};
  options.object = "cylinder";
  options.object_size = {0.02};
  expect_error(options, "radius,length");
  options.object = "";
  options.hand = "middle";
  expect_error(options, "handedness");
  // Not-a-number viewpoints and placements used to render blank images and succeed.
  for (const double bad : {std::nan(""), HUGE_VAL, -HUGE_VAL}) {
    RenderCommandOptions view;
    view.azimuth_deg = bad;
    expect_error(view, "finite");
    view = {};
    view.elevation_deg = bad;
    expect_error(view, "finite");
    view = {};
    view.roll_deg = bad;
    expect_error(view, "finite");
    view = {};
    view.object = "sphere";
    view.object_size = {0.03};
    view.object_at = {bad, 0, 0};
    expect_error(view, "finite");
    view.object_at = {0, 0, 0};
    view.object_rotate_deg = {0, bad, 0};
    expect_error(view, "finite");
  }
  // A name is a file name: "../x" used to write outside --out.
  for (const std::string name : {"../x", "a/b", "..", ""}) {
    RenderCommandOptions named;
    named.name = name;
    expect_error(named, "must be a file name");
  }
}

TEST(RenderCommandTest, OutputFolderThatIsAFileIsRefused) {
  const auto dir = testing::ScratchDir();
  WriteFileAtomic(dir / "file", std::string("x"));
  RenderCommandOptions options;
  options.out_dir = dir / "file";
  EXPECT_THROW(RunRender(options), Error);
}

}  // namespace
}  // namespace nphand
