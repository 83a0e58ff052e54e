#include "apps/render_command.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "nphand/render/draw.h"
#include "nphand/render/renderer.h"
#include "nphand/scene/gesture.h"
#include "nphand/scene/viewpoint.h"
#include "nphand/util/check.h"
#include "nphand/util/file.h"

namespace nphand {
namespace {

constexpr double kRadPerDeg = std::numbers::pi / 180.0;

JointAngles ArticulationOf(const RenderCommandOptions& options) {
  JointAngles angles = NamedArticulation(options.pose);
  for (const std::string& assignment : options.angles) {
    const size_t eq = assignment.find('=');
    NPHAND_THROW_CHECK(eq != std::string::npos, "--angle '", assignment, "': expected NAME=DEGREES");
    const int dof = DofFromString(assignment.substr(0, eq));
    double degrees = 0.0;
    try {
      size_t used = 0;
      degrees = std::stod(assignment.substr(eq + 1), &used);
      NPHAND_THROW_CHECK(used == assignment.size() - eq - 1, "--angle '", assignment, "': not a number");
    } catch (const std::logic_error&) {
      NPHAND_THROW("--angle '", assignment, "': not a number");
    }
    angles[dof] = degrees * kRadPerDeg;
  }
  const JointAngles clamped = ClampToLimits(angles);
  for (int i = 0; i < kNumDofs; ++i) {
    NPHAND_THROW_CHECK(clamped[i] == angles[i], "--angle ", Dofs()[i].name, "=", angles[i] / kRadPerDeg,
                       " is outside its limits [", Dofs()[i].min_rad / kRadPerDeg, ", ",
                       Dofs()[i].max_rad / kRadPerDeg, "] degrees");
  }
  return angles;
}

}  // namespace

bool RenderCommandOptions::Check(std::string* why) const {
  const auto finite = [](const std::vector<double>& values) {
    return std::all_of(values.begin(), values.end(), [](double v) { return std::isfinite(v); });
  };
  if (!finite({azimuth_deg, elevation_deg, roll_deg}) || !finite(object_at) || !finite(object_rotate_deg) ||
      !finite(object_size)) {
    *why = "--azimuth, --elevation, --roll and the --object-* values must be finite numbers";
    return false;
  }
  if (!(distance > 0.05 && distance < 100.0)) {
    *why = "--distance must be between 0.05 and 100 metres";
    return false;
  }
  if (!(fov_deg > 1.0 && fov_deg < 170.0)) {
    *why = "--fov must be between 1 and 170 degrees";
    return false;
  }
  if (object_at.size() != 3 || object_rotate_deg.size() != 3) {
    *why = "--object-at and --object-rotate take three values";
    return false;
  }
  if (!grasp.empty() && !gesture.empty()) {
    *why = "--grasp and --gesture exclude each other";
    return false;
  }
  if (step < 0 || step >= kGraspSteps) {
    *why = "--step must be between 0 and " + std::to_string(kGraspSteps - 1);
    return false;
  }
  if (!object.empty() && static_cast<int>(object_size.size()) != ObjectSizeCount(ObjectShapeFromString(object))) {
    *why = "--object-size for a " + object + " takes " + ObjectSizeMeaning(ObjectShapeFromString(object));
    return false;
  }
  return Intrinsics::FromFieldOfView(width, height, fov_deg * kRadPerDeg).Check(why);
}

namespace {

Scene SceneOf(const RenderCommandOptions& options, const HandModel& model, const Viewpoint& view) {
  std::string why;
  Scene scene;
  scene.hand.handedness = model.handedness();
  scene.hand.camera_from_hand = CameraFromHand(view);
  if (!options.grasp.empty()) {
    const Grasp grasp = MakeGrasp(model, GraspByName(options.grasp));
    scene.hand.angles = grasp.steps[options.step];
    scene.objects = {grasp.object};
  } else if (!options.gesture.empty()) {
    scene.hand.angles = GestureSteps(GestureByName(options.gesture))[options.step];
  } else {
    scene.hand.angles = ArticulationOf(options);
    if (!options.object.empty()) {
      SceneObject object;
      object.spec.shape = ObjectShapeFromString(options.object);
      std::copy(options.object_size.begin(), options.object_size.end(), object.spec.size.begin());
      NPHAND_THROW_CHECK(object.spec.Check(&why), "render: ", why);
      object.hand_from_object.translation() =
          Eigen::Vector3d(options.object_at[0], options.object_at[1], options.object_at[2]);
      object.hand_from_object.linear() =
          AxisAngle(Eigen::Vector3d::UnitZ(), options.object_rotate_deg[2] * kRadPerDeg) *
          AxisAngle(Eigen::Vector3d::UnitY(), options.object_rotate_deg[1] * kRadPerDeg) *
          AxisAngle(Eigen::Vector3d::UnitX(), options.object_rotate_deg[0] * kRadPerDeg);
      scene.objects.push_back(object);
    }
  }
  scene.wrist_in_camera = CenteredWristPosition(scene.hand.camera_from_hand, model.bind_centre(), options.distance);
  return scene;
}

// All 33 grasps (or all gestures), one tile each, named and numbered, in their order.
RenderCommandResult RunSheet(const RenderCommandOptions& options, const HandModel& model, const Viewpoint& view,
                             bool gestures) {
  const int count = gestures ? kNumGestures : kNumGrasps;
  const int tile = 256, columns = 6, rows = (count + columns - 1) / columns;
  cv::Mat sheet(rows * tile, columns * tile, CV_8UC3, cv::Scalar(40, 40, 40));
  const Intrinsics intrinsics = Intrinsics::FromFieldOfView(tile, tile, options.fov_deg * kRadPerDeg);
  Renderer renderer(model);
  RenderCommandOptions one = options;
  for (int i = 0; i < count; ++i) {
    const int shape = gestures ? kFirstGestureId + i : i + 1;
    (gestures ? one.gesture : one.grasp) = HandShapeKey(shape);
    const RenderedImages images = renderer.Render(SceneOf(one, model, view), intrinsics);
    cv::Mat cell = sheet(cv::Rect((i % columns) * tile, (i / columns) * tile, tile, tile));
    images.rgb.copyTo(cell);
    cv::putText(cell, std::to_string(shape) + " " + HandShapeKey(shape), {6, 18}, cv::FONT_HERSHEY_SIMPLEX, 0.45,
                cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
  }
  const std::filesystem::path path = options.out_dir / (options.name + (gestures ? "_gestures" : "_grasps") + "_step" +
                                                        std::to_string(options.step) + ".png");
  WriteImageAtomic(path, sheet);
  RenderCommandResult result;
  result.files.push_back(path);
  return result;
}

}  // namespace

RenderCommandResult RunRender(const RenderCommandOptions& options) {
  std::string why;
  NPHAND_THROW_CHECK(options.Check(&why), "render: ", why);
  CheckFileName(options.name, "render --name");
  CheckOutputFolder(options.out_dir, "render --out");
  CheckOutputsApart({{options.background, "--background"}}, {{options.out_dir, "render --out", {".png"}}});
  const HandModel model = HandModel::Load(HandednessFromString(options.hand), options.asset_dir);
  const Viewpoint view{options.azimuth_deg * kRadPerDeg, options.elevation_deg * kRadPerDeg, options.roll_deg * kRadPerDeg};
  if (options.grasp == "all" || options.gesture == "all") {
    return RunSheet(options, model, view, options.gesture == "all");
  }
  const Scene scene = SceneOf(options, model, view);

  RenderOptions render_options;
  if (!options.background.empty()) {
    render_options.background = cv::imread(options.background, cv::IMREAD_COLOR);
    NPHAND_THROW_CHECK(!render_options.background.empty(), options.background, ": cannot read the background image");
  }
  const Intrinsics intrinsics = Intrinsics::FromFieldOfView(options.width, options.height, options.fov_deg * kRadPerDeg);
  Renderer renderer(model);
  const RenderedImages images = renderer.Render(scene, intrinsics, render_options);

  Keypoints3d keypoints = model.KeypointsOf(scene.hand);
  for (Eigen::Vector3d& k : keypoints) k += scene.wrist_in_camera;
  cv::Mat overlay = images.rgb.clone();
  DrawKeypoints(intrinsics, keypoints, &overlay);
  cv::Mat depth_mm;
  images.depth.convertTo(depth_mm, CV_16UC1, 1000.0);

  RenderCommandResult result;
  const auto write = [&](const std::string& suffix, const cv::Mat& image) {
    const std::filesystem::path path = options.out_dir / (options.name + "_" + suffix + ".png");
    WriteImageAtomic(path, image);
    result.files.push_back(path);
  };
  write("rgb", images.rgb);
  write("labels", LabelsForDisplay(images.labels));
  write("depth", depth_mm);
  write("keypoints", overlay);
  result.hand_pixels = cv::countNonZero(images.labels == static_cast<int>(PixelLabel::kHand));
  result.object_pixels = cv::countNonZero(images.labels == static_cast<int>(PixelLabel::kObject));
  return result;
}

}  // namespace nphand
