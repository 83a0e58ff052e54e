// A z-buffered triangle rasteriser on fixed-point (1/256 pixel) coordinates with the
// top-left fill rule: triangles that share an edge never both cover a pixel centre on it,
// and never leave a gap, so coverage counts are exact and results are bit-for-bit
// deterministic. Perspective-correct depth (1/z is interpolated).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include <Eigen/Core>

#include "nphand/render/camera.h"

namespace nphand {

// Triangles closer than this to the camera plane (metres) are not drawn.
inline constexpr float kNearPlane = 1e-3f;

struct RasterTarget {
  int width = 0;
  int height = 0;
  std::vector<float> inverse_depth;  // 1/z of the nearest surface; 0 where nothing was drawn
  std::vector<uint8_t> label;        // label of the nearest surface; 0 where nothing was drawn
  std::vector<float> shade;          // interpolated vertex intensity; filled only when shading

  // Resizes to width x height and clears every pixel.
  void Reset(int width, int height, bool shading);
};

enum class Faces : uint8_t {
  kBoth,       // draw every triangle
  kFrontOnly,  // skip triangles whose counter-clockwise normal faces away from the camera;
               // exact (and about twice as fast) for closed meshes wound outward
};

// Draws `triangles` over `vertices` (camera frame) with `label` into `target`, keeping the
// nearest surface per pixel. `intensity` (one per vertex) is interpolated into
// target->shade when it is not empty.
void RasterizeTriangles(const Intrinsics& intrinsics, std::span<const Eigen::Vector3f> vertices,
                        std::span<const Eigen::Vector3i> triangles, std::span<const float> intensity,
                        uint8_t label, Faces faces, RasterTarget* target);

}  // namespace nphand
