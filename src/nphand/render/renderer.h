// The renderer: a scene of one hand and its objects to a label image (background / hand /
// object, with mutual occlusion), a depth image and a shaded RGB image.
//
// A software rasteriser (rasterizer.h): deterministic to the bit, no GPU or display, and
// fast enough for the database (see `nphand bench render`). The hand mesh and the object
// meshes are closed and wound outward (tests check both), so back faces are skipped.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "nphand/model/hand_model.h"
#include "nphand/render/camera.h"
#include "nphand/render/rasterizer.h"
#include "nphand/scene/scene.h"

namespace nphand {

// Values of the label image.
enum class PixelLabel : uint8_t { kBackground = 0, kHand = 1, kObject = 2, kForearm = 3 };

// The default skin colour (BGR, 0..255): a light tone.
inline const cv::Vec3f kDefaultSkinColour(140, 170, 225);

struct RenderOptions {
  bool depth = true;  // fill RenderedImages::depth
  bool rgb = true;    // fill RenderedImages::rgb
  // Optional BGR background (CV_8UC3) for the RGB image, resized to the output; black if empty.
  cv::Mat background;
  // Where the light comes from, in the camera frame (towards the light).
  Eigen::Vector3d light_direction = Eigen::Vector3d(-0.4, -0.6, -1.0);
  double ambient = 0.35;  // light on surfaces facing away from the light, 0..1
  cv::Vec3f skin_colour = kDefaultSkinColour;  // BGR, 0..255, of the hand (and a bare forearm)
  std::optional<cv::Vec3f> sleeve_colour;      // BGR of the forearm if it is sleeved

  bool Check(std::string* why) const;
};

struct RenderedImages {
  cv::Mat labels;  // CV_8UC1, PixelLabel values
  cv::Mat depth;   // CV_32FC1, metres along the optical axis; 0 on the background
  cv::Mat rgb;     // CV_8UC3, BGR (OpenCV's order)
};

class Renderer {
 public:
  // Keeps a reference to `hand`, which must outlive the renderer. Scenes must hold a pose
  // of the same handedness.
  explicit Renderer(const HandModel& hand) : hand_(hand) {}

  // Renders everything asked for in `options`. Throws nphand::Error for invalid
  // intrinsics, options or objects.
  RenderedImages Render(const Scene& scene, const Intrinsics& intrinsics, const RenderOptions& options = {});
  // The label image only, into `labels` (reallocated to CV_8UC1 of the camera's size if
  // needed): the fast path that the database uses.
  void RenderLabels(const Scene& scene, const Intrinsics& intrinsics, cv::Mat* labels);

  // Triangles of the hand mesh and of `scene`'s objects, for reports.
  int HandTriangleCount() const { return static_cast<int>(hand_.triangles().size()); }
  int ObjectTriangleCount(const Scene& scene);

 private:
  // Rasterises the scene into target_; intensities are computed when `options` is given.
  void Rasterize(const Scene& scene, const Intrinsics& intrinsics, const RenderOptions* options);
  const TriangleMesh& ObjectMesh(const ObjectSpec& spec);
  const TriangleMesh& ForearmMesh(const Forearm& forearm);

  const HandModel& hand_;
  RasterTarget target_;
  // Scratch buffers and a cache of object meshes by spec, reused across calls.
  std::vector<Eigen::Vector3f> vertices_, normals_;
  std::vector<float> intensity_;
  std::vector<std::pair<ObjectSpec, TriangleMesh>> mesh_cache_;
  std::optional<std::pair<Forearm, TriangleMesh>> forearm_cache_;
};

}  // namespace nphand
