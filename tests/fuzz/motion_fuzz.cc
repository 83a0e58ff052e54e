// Fuzzes the motion readers of `nphand eval motion`: the first byte chooses the BVH parser
// (with forward kinematics and the generic hand's keypoints of every frame) or the glTF
// animation reader (with every key's keypoints); the rest is the file.
#include <cstddef>
#include <cstdint>
#include <string>

#include "nphand/motion/bvh.h"
#include "nphand/motion/gltf_motion.h"
#include "nphand/util/check.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  try {
    if (data[0] % 2 == 0) {
      const nphand::Bvh bvh = nphand::ParseBvh(std::string(data + 1, data + size), "fuzz.bvh");
      for (size_t f = 0; f < bvh.frames.size(); ++f) {
        bvh.Positions(f);
        nphand::BvhKeypoints(bvh, f);
      }
    } else {
      const nphand::GltfMotion motion = nphand::ReadGltfMotion({data + 1, size - 1}, "fuzz.glb");
      for (size_t f = 0; f < motion.frames.size(); ++f) nphand::GltfKeypoints(motion, f);
    }
  } catch (const nphand::Error&) {
  }
  return 0;
}
