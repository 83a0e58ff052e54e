#include "nphand/render/renderer.h"

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

#include "nphand/util/check.h"

namespace nphand {
namespace {

// Surface colours (BGR): a light skin tone for the hand; one colour per object in turn.
const cv::Vec3f kSkinColour(140, 170, 225);
const std::array<cv::Vec3f, 4> kObjectColours = {cv::Vec3f(200, 120, 60), cv::Vec3f(80, 170, 90),
                                                 cv::Vec3f(60, 90, 200), cv::Vec3f(170, 80, 170)};
constexpr size_t kMaxCachedMeshes = 64;

void CheckInputs(const Intrinsics& intrinsics, const RenderOptions* options) {
  std::string why;
  NPHAND_THROW_CHECK(intrinsics.Check(&why), "render: ", why);
  if (options != nullptr) NPHAND_THROW_CHECK(options->Check(&why), "render: ", why);
}

}  // namespace

bool RenderOptions::Check(std::string* why) const {
  if (!background.empty() && background.type() != CV_8UC3) {
    *why = "background must be an 8-bit 3-channel image";
    return false;
  }
  if (!(light_direction.allFinite() && light_direction.norm() > 0.0)) {
    *why = "light direction must be a non-zero finite vector";
    return false;
  }
  if (!(ambient >= 0.0 && ambient <= 1.0)) {
    *why = "ambient must be within [0, 1]";
    return false;
  }
  return true;
}

const TriangleMesh& Renderer::ObjectMesh(const ObjectSpec& spec) {
  for (const auto& [cached_spec, mesh] : mesh_cache_) {
    if (cached_spec == spec) return mesh;
  }
  if (mesh_cache_.size() >= kMaxCachedMeshes) mesh_cache_.clear();
  mesh_cache_.emplace_back(spec, MakeObjectMesh(spec));
  return mesh_cache_.back().second;
}

int Renderer::ObjectTriangleCount(const Scene& scene) {
  int count = 0;
  for (const SceneObject& object : scene.objects) count += static_cast<int>(ObjectMesh(object.spec).triangles.size());
  return count;
}

void Renderer::Rasterize(const Scene& scene, const Intrinsics& intrinsics, const RenderOptions* options) {
  const bool shading = options != nullptr;
  target_.Reset(intrinsics.width, intrinsics.height, shading);
  const Eigen::Vector3f light =
      shading ? Eigen::Vector3f(options->light_direction.normalized().cast<float>()) : Eigen::Vector3f::Zero();
  const float ambient = shading ? static_cast<float>(options->ambient) : 0.0f;
  // Two-sided Lambertian shading, per vertex.
  auto shade = [&](const std::vector<Eigen::Vector3f>& normals) {
    intensity_.resize(normals.size());
    for (size_t v = 0; v < normals.size(); ++v) {
      intensity_[v] = ambient + (1.0f - ambient) * std::abs(normals[v].dot(light));
    }
  };
  const Eigen::Vector3f wrist = scene.wrist_in_camera.cast<float>();

  hand_.Skin(scene.hand, &vertices_, shading ? &normals_ : nullptr);
  for (Eigen::Vector3f& v : vertices_) v += wrist;
  if (shading) shade(normals_);
  RasterizeTriangles(intrinsics, vertices_, hand_.triangles(), shading ? intensity_ : std::span<const float>(),
                     static_cast<uint8_t>(PixelLabel::kHand), Faces::kFrontOnly, &target_);

  for (size_t o = 0; o < scene.objects.size(); ++o) {
    const SceneObject& object = scene.objects[o];
    const TriangleMesh& mesh = ObjectMesh(object.spec);
    const Eigen::Matrix3f rotation = (scene.hand.camera_from_hand * object.hand_from_object.linear()).cast<float>();
    const Eigen::Vector3f translation =
        (scene.hand.camera_from_hand * object.hand_from_object.translation()).cast<float>() + wrist;
    vertices_.resize(mesh.vertices.size());
    for (size_t v = 0; v < mesh.vertices.size(); ++v) vertices_[v] = rotation * mesh.vertices[v] + translation;
    if (shading) {
      normals_.resize(mesh.normals.size());
      for (size_t v = 0; v < mesh.normals.size(); ++v) normals_[v] = rotation * mesh.normals[v];
      shade(normals_);
    }
    // Objects carry label kObject; the shading pass tells objects apart by drawing order.
    RasterizeTriangles(intrinsics, vertices_, mesh.triangles, shading ? intensity_ : std::span<const float>(),
                       static_cast<uint8_t>(static_cast<int>(PixelLabel::kObject) + (shading ? o : 0)),
                       Faces::kFrontOnly, &target_);
  }
}

void Renderer::RenderLabels(const Scene& scene, const Intrinsics& intrinsics, cv::Mat* labels) {
  CheckInputs(intrinsics, nullptr);
  Rasterize(scene, intrinsics, nullptr);
  labels->create(intrinsics.height, intrinsics.width, CV_8UC1);
  std::copy(target_.label.begin(), target_.label.end(), labels->ptr<uint8_t>());
}

RenderedImages Renderer::Render(const Scene& scene, const Intrinsics& intrinsics, const RenderOptions& options) {
  CheckInputs(intrinsics, &options);
  NPHAND_THROW_CHECK(scene.objects.size() < 250, "render: too many objects (", scene.objects.size(), ")");
  Rasterize(scene, intrinsics, &options);
  const int h = intrinsics.height, w = intrinsics.width;
  RenderedImages images;
  images.labels.create(h, w, CV_8UC1);
  for (int i = 0; i < h * w; ++i) {
    images.labels.ptr<uint8_t>()[i] = std::min<uint8_t>(target_.label[i], static_cast<uint8_t>(PixelLabel::kObject));
  }
  if (options.depth) {
    images.depth.create(h, w, CV_32FC1);
    float* depth = images.depth.ptr<float>();
    for (int i = 0; i < h * w; ++i) depth[i] = target_.inverse_depth[i] > 0.0f ? 1.0f / target_.inverse_depth[i] : 0.0f;
  }
  if (options.rgb) {
    if (options.background.empty()) {
      images.rgb = cv::Mat::zeros(h, w, CV_8UC3);
    } else {
      cv::resize(options.background, images.rgb, cv::Size(w, h), 0, 0, cv::INTER_AREA);
    }
    for (int i = 0; i < h * w; ++i) {
      const uint8_t label = target_.label[i];
      if (label == 0) continue;
      const cv::Vec3f colour = label == static_cast<uint8_t>(PixelLabel::kHand)
                                   ? kSkinColour
                                   : kObjectColours[(label - static_cast<int>(PixelLabel::kObject)) % kObjectColours.size()];
      images.rgb.ptr<cv::Vec3b>()[i] = cv::Vec3b(cv::saturate_cast<uchar>(colour[0] * target_.shade[i]),
                                                 cv::saturate_cast<uchar>(colour[1] * target_.shade[i]),
                                                 cv::saturate_cast<uchar>(colour[2] * target_.shade[i]));
    }
  }
  return images;
}

}  // namespace nphand
