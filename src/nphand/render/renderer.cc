#include "nphand/render/renderer.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "nphand/util/check.h"

namespace nphand {
namespace {

// Object colours (BGR), one per object in turn.
const std::array<cv::Vec3f, 4> kObjectColours = {cv::Vec3f(200, 120, 60), cv::Vec3f(80, 170, 90),
                                                 cv::Vec3f(60, 90, 200), cv::Vec3f(170, 80, 170)};
constexpr size_t kMaxCachedMeshes = 64;
// Raster labels of the shading pass: objects are told apart by drawing order from here on.
constexpr int kFirstShadedObjectLabel = 4;
constexpr int kForearmSegments = 32;

bool IsColour(const cv::Vec3f& c) {
  return std::isfinite(c[0]) && std::isfinite(c[1]) && std::isfinite(c[2]) && c[0] >= 0 && c[1] >= 0 && c[2] >= 0 &&
         c[0] <= 255 && c[1] <= 255 && c[2] <= 255;
}

// The arm along -x: an elliptic truncated cone from the ring at x0 (the wrist end, inside the
// mesh) to the ring at x1 (the elbow end, its radii `elbow_scale` times the wrist end's), and
// with `upper` > 0 a cylinder on from the elbow's ring to a ring at x1 - upper (the upper
// arm); centred on (y, z) = centre, with caps; wound outward. The sequences' cameras never
// look from the arm's side (sequence.cc), so no ring lies behind the camera.
TriangleMesh MakeArmMesh(const Eigen::Vector2f& centre, const Eigen::Vector2f& wrist_radii, double x0, double x1,
                         const Eigen::Vector2f& elbow_scale, double upper) {
  struct Ring {
    double x;
    Eigen::Vector2f scale;  // its radii over the wrist end's
  };
  std::vector<Ring> rings = {{x0, Eigen::Vector2f::Ones()}, {x1, elbow_scale}};
  if (upper > 0.0) rings.push_back({x1 - upper, elbow_scale});
  TriangleMesh mesh;
  const int n = kForearmSegments;
  for (const Ring& ring : rings) {
    // Across an elliptic ring of radii (sx rx, sy ry) the normal runs along (cy / rx, (sx / sy) sz / ry).
    const float aspect = ring.scale.x() / ring.scale.y();
    for (int i = 0; i < n; ++i) {
      const float a = static_cast<float>(2.0 * std::numbers::pi * i / n);
      const float cy = std::cos(a), sz = std::sin(a);
      mesh.vertices.emplace_back(static_cast<float>(ring.x), centre.x() + ring.scale.x() * wrist_radii.x() * cy,
                                 centre.y() + ring.scale.y() * wrist_radii.y() * sz);
      mesh.normals.push_back(Eigen::Vector3f(0.0f, cy / wrist_radii.x(), aspect * sz / wrist_radii.y()).normalized());
    }
  }
  mesh.vertices.emplace_back(static_cast<float>(rings.front().x), centre.x(), centre.y());
  mesh.normals.emplace_back(1.0f, 0.0f, 0.0f);
  mesh.vertices.emplace_back(static_cast<float>(rings.back().x), centre.x(), centre.y());
  mesh.normals.emplace_back(-1.0f, 0.0f, 0.0f);
  const int count = static_cast<int>(rings.size());
  const int cap0 = count * n, cap1 = count * n + 1, last = (count - 1) * n;
  for (int i = 0; i < n; ++i) {
    const int j = (i + 1) % n;
    // Sides: each ring lies on +x of the next.
    for (int ring = 0; ring + 1 < count; ++ring) {
      const int near = ring * n, far = near + n;
      mesh.triangles.emplace_back(near + i, far + i, far + j);
      mesh.triangles.emplace_back(near + i, far + j, near + j);
    }
    mesh.triangles.emplace_back(cap0, i, j);
    mesh.triangles.emplace_back(cap1, last + j, last + i);
  }
  return mesh;
}

void CheckInputs(const Scene& scene, const Intrinsics& intrinsics, const RenderOptions* options) {
  std::string why;
  NPHAND_THROW_CHECK(intrinsics.Check(&why), "render: ", why);
  NPHAND_THROW_CHECK(!scene.forearm.has_value() || scene.forearm->Check(&why), "render: ", why);
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
  if (!IsColour(skin_colour) || (sleeve_colour.has_value() && !IsColour(*sleeve_colour))) {
    *why = "colours must be BGR values within [0, 255]";
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

const TriangleMesh& Renderer::ForearmMesh(const Forearm& forearm) {
  if (forearm_cache_.has_value() && forearm_cache_->first == forearm) return forearm_cache_->second;
  // The wrist's cross-section: the bind-pose vertices within 1 cm of the mesh's proximal end.
  float min_x = std::numeric_limits<float>::max();
  for (const Eigen::Vector3f& v : hand_.bind_vertices()) min_x = std::min(min_x, v.x());
  Eigen::Vector2f low(std::numeric_limits<float>::max(), std::numeric_limits<float>::max());
  Eigen::Vector2f high = -low;
  for (const Eigen::Vector3f& v : hand_.bind_vertices()) {
    if (v.x() > min_x + 0.01f) continue;
    low = low.cwiseMin(v.tail<2>());
    high = high.cwiseMax(v.tail<2>());
  }
  const Eigen::Vector2f elbow_scale(static_cast<float>(forearm.elbow_width_scale), static_cast<float>(forearm.elbow_depth_scale));
  forearm_cache_.emplace(forearm, MakeArmMesh(0.5f * (low + high), 0.5f * (high - low), min_x + 0.01, min_x - forearm.length,
                                              elbow_scale, forearm.upper_arm_length));
  return forearm_cache_->second;
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

  // A mesh placed in the hand frame by `hand_from_mesh`, drawn with `label`.
  auto draw = [&](const TriangleMesh& mesh, const Eigen::Isometry3d& hand_from_mesh, uint8_t label) {
    const Eigen::Matrix3f rotation = (scene.hand.camera_from_hand * hand_from_mesh.linear()).cast<float>();
    const Eigen::Vector3f translation =
        (scene.hand.camera_from_hand * hand_from_mesh.translation()).cast<float>() + wrist;
    vertices_.resize(mesh.vertices.size());
    for (size_t v = 0; v < mesh.vertices.size(); ++v) vertices_[v] = rotation * mesh.vertices[v] + translation;
    if (shading) {
      normals_.resize(mesh.normals.size());
      for (size_t v = 0; v < mesh.normals.size(); ++v) normals_[v] = rotation * mesh.normals[v];
      shade(normals_);
    }
    RasterizeTriangles(intrinsics, vertices_, mesh.triangles, shading ? intensity_ : std::span<const float>(), label,
                       Faces::kFrontOnly, &target_);
  };
  if (scene.forearm.has_value()) {
    draw(ForearmMesh(*scene.forearm), Eigen::Isometry3d::Identity(), static_cast<uint8_t>(PixelLabel::kForearm));
  }
  for (size_t o = 0; o < scene.objects.size(); ++o) {
    // Objects carry label kObject; the shading pass tells objects apart by drawing order.
    draw(ObjectMesh(scene.objects[o].spec), scene.objects[o].hand_from_object,
         static_cast<uint8_t>(shading ? kFirstShadedObjectLabel + static_cast<int>(o) : static_cast<int>(PixelLabel::kObject)));
  }
}

void Renderer::RenderLabels(const Scene& scene, const Intrinsics& intrinsics, cv::Mat* labels) {
  CheckInputs(scene, intrinsics, nullptr);
  Rasterize(scene, intrinsics, nullptr);
  labels->create(intrinsics.height, intrinsics.width, CV_8UC1);
  std::copy(target_.label.begin(), target_.label.end(), labels->ptr<uint8_t>());
}

RenderedImages Renderer::Render(const Scene& scene, const Intrinsics& intrinsics, const RenderOptions& options) {
  CheckInputs(scene, intrinsics, &options);
  NPHAND_THROW_CHECK(scene.objects.size() < 250 - kFirstShadedObjectLabel, "render: too many objects (",
                     scene.objects.size(), ")");
  Rasterize(scene, intrinsics, &options);
  const int h = intrinsics.height, w = intrinsics.width;
  RenderedImages images;
  images.labels.create(h, w, CV_8UC1);
  for (int i = 0; i < h * w; ++i) {
    const uint8_t label = target_.label[i];
    images.labels.ptr<uint8_t>()[i] = label >= kFirstShadedObjectLabel ? static_cast<uint8_t>(PixelLabel::kObject) : label;
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
      const cv::Vec3f colour =
          label == static_cast<uint8_t>(PixelLabel::kHand)      ? options.skin_colour
          : label == static_cast<uint8_t>(PixelLabel::kForearm) ? options.sleeve_colour.value_or(options.skin_colour)
                                                                : kObjectColours[(label - kFirstShadedObjectLabel) % kObjectColours.size()];
      images.rgb.ptr<cv::Vec3b>()[i] = cv::Vec3b(cv::saturate_cast<uchar>(colour[0] * target_.shade[i]),
                                                 cv::saturate_cast<uchar>(colour[1] * target_.shade[i]),
                                                 cv::saturate_cast<uchar>(colour[2] * target_.shade[i]));
    }
  }
  return images;
}

}  // namespace nphand
