#include "testing/testing.h"

#include <unistd.h>

#include <cstdlib>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "nphand/util/check.h"

namespace nphand::testing {

const HandModel& RightHand() {
  static const HandModel model = HandModel::Load(Handedness::kRight);
  return model;
}

cv::Mat Greyscale(const cv::Mat& bgr) {
  cv::Mat grey, out;
  cv::cvtColor(bgr, grey, cv::COLOR_BGR2GRAY);
  cv::cvtColor(grey, out, cv::COLOR_GRAY2BGR);
  return out;
}

SequenceOptions DemoSequence(uint64_t seed) {
  SequenceOptions options;
  options.frames = 120;
  options.grasp = 1;
  options.object_scale = 0.8;
  options.forearm = ForearmKind::kBare;
  options.background = BackgroundKind::kClutter;
  options.face = true;
  options.seed = seed;
  return options;
}

const HandModel& LeftHand() {
  static const HandModel model = HandModel::Load(Handedness::kLeft);
  return model;
}

std::filesystem::path ScratchDir() {
  const ::testing::TestInfo* info = ::testing::UnitTest::GetInstance()->current_test_info();
  std::string name = std::string(info->test_suite_name()) + "." + info->name();
  for (char& c : name) {
    if (c == '/') c = '_';
  }
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("nphand_test_" + std::to_string(::getpid())) / name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

std::filesystem::path RealDevDir() {
  if (const char* env = std::getenv("NPHAND_REAL_DEV"); env != nullptr && *env != '\0') return env;
  return NPHAND_REAL_DEV;
}

void ExpectError(const std::function<void()>& call, const std::string& needle) {
  try {
    call();
    ADD_FAILURE() << "no error (expected: " << needle << ")";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
  }
}

}  // namespace nphand::testing
