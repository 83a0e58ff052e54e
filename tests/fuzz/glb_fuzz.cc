// Fuzzes the hand mesh loader on the glTF bytes themselves (HandModel::Load checks the
// pinned sha256 first, so only a changed pin would let other bytes through; FromGlb is the
// part that parses them): skins, joints, accessors and buffer views.
#include <cstddef>
#include <cstdint>

#include "nphand/model/hand_model.h"
#include "nphand/util/check.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    const nphand::HandModel model = nphand::HandModel::FromGlb({data, size}, nphand::Handedness::kRight, "fuzz.glb");
    nphand::HandPose pose;
    model.KeypointsOf(pose);
  } catch (const nphand::Error&) {
  }
  return 0;
}
