// Test support shared by every test binary.
#pragma once

#include <filesystem>
#include <functional>
#include <string>

#include <opencv2/core.hpp>

#include "nphand/model/hand_model.h"
#include "nphand/sequence/sequence.h"

namespace nphand::testing {

// The hand models, loaded once per test binary from the set-up cache.
const HandModel& RightHand();
const HandModel& LeftHand();

// The demo's sequence (scripts/demo.sh) with `seed`: a hand with a bare forearm closing
// onto a cylinder 0.8 times the database's, 120 frames before clutter and a face.
SequenceOptions DemoSequence(uint64_t seed);

// `bgr` as a greyscale or infrared camera gives it: grey, in three equal channels.
cv::Mat Greyscale(const cv::Mat& bgr);

// A fresh empty folder for the running test, under the system's temporary folder.
std::filesystem::path ScratchDir();

// real-dev's folder (real labelled hand images, never shipped): $NPHAND_REAL_DEV, or
// ../shared/real-dev beside the clone, as CI has it. Tests that read it skip when it is absent.
std::filesystem::path RealDevDir();

// Expects `call` to throw nphand::Error with `needle` in its message.
void ExpectError(const std::function<void()>& call, const std::string& needle);

// The seed each test should use: fixed, and printed by the test main on failure.
inline constexpr uint64_t kTestSeed = 20131108;

}  // namespace nphand::testing
