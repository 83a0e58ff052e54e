#include "nphand/render/renderer.h"

#include <cmath>
#include <numbers>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "nphand/scene/viewpoint.h"
#include "nphand/util/check.h"
#include "testing/testing.h"

namespace nphand {
namespace {

using testing::RightHand;

const Intrinsics kCamera = Intrinsics::FromFieldOfView(256, 256, 30.0 * std::numbers::pi / 180.0);

Scene HandScene(const Viewpoint& view, const JointAngles& angles) {
  Scene scene;
  scene.hand.angles = angles;
  scene.hand.camera_from_hand = CameraFromHand(view);
  scene.wrist_in_camera = CenteredWristPosition(scene.hand.camera_from_hand, RightHand().bind_centre(), 0.5);
  return scene;
}

int Count(const cv::Mat& labels, PixelLabel label) { return cv::countNonZero(labels == static_cast<int>(label)); }

TEST(RendererTest, SphereCoversItsAnalyticArea) {
  Renderer renderer(RightHand());
  for (double radius : {0.02, 0.05, 0.1}) {
    for (double distance : {0.4, 0.8}) {
      Scene scene;
      scene.wrist_in_camera = Eigen::Vector3d(0, 0, -1.0);  // the hand is behind the camera, not drawn
      SceneObject sphere;
      sphere.spec = {ObjectShape::kSphere, {radius, 0, 0}, 256};
      sphere.hand_from_object.translation() = Eigen::Vector3d(0, 0, 1.0 + distance);
      scene.objects = {sphere};
      cv::Mat labels;
      renderer.RenderLabels(scene, kCamera, &labels);
      // A sphere's silhouette from a centred pinhole is a disc of radius f r / sqrt(d^2 - r^2).
      const double rho = kCamera.fx * radius / std::sqrt(distance * distance - radius * radius);
      const double expected = std::numbers::pi * rho * rho;
      EXPECT_NEAR(Count(labels, PixelLabel::kObject), expected, 0.01 * expected) << radius << " at " << distance;
      EXPECT_EQ(Count(labels, PixelLabel::kHand), 0);
    }
  }
}

TEST(RendererTest, ObjectInFrontRemovesExactlyTheHandPixelsItCovers) {
  Renderer renderer(RightHand());
  Scene scene = HandScene({0.2, 0.1, 0.3}, NamedArticulation("relaxed"));
  cv::Mat alone;
  renderer.RenderLabels(scene, kCamera, &alone);

  // A box between the camera and the hand: 10 cm in front of the hand centre towards the camera.
  SceneObject box;
  box.spec = {ObjectShape::kBox, {0.05, 0.04, 0.01}, 32};
  const Eigen::Vector3d towards_camera = scene.hand.camera_from_hand.transpose() * Eigen::Vector3d(0, 0, -1);
  box.hand_from_object.translation() = RightHand().bind_centre() + 0.1 * towards_camera;
  box.hand_from_object.linear() = scene.hand.camera_from_hand.transpose();  // faces the camera
  scene.objects = {box};
  cv::Mat with_box;
  renderer.RenderLabels(scene, kCamera, &with_box);

  // The box's own coverage, rasterised alone.
  const TriangleMesh mesh = MakeObjectMesh(box.spec);
  std::vector<Eigen::Vector3f> vertices;
  for (const Eigen::Vector3f& v : mesh.vertices) {
    vertices.push_back((scene.hand.camera_from_hand * (box.hand_from_object * v.cast<double>()) + scene.wrist_in_camera).cast<float>());
  }
  RasterTarget box_only;
  box_only.Reset(kCamera.width, kCamera.height, false);
  RasterizeTriangles(kCamera, vertices, mesh.triangles, {}, 1, Faces::kBoth, &box_only);

  int hidden = 0;
  for (int i = 0; i < kCamera.width * kCamera.height; ++i) {
    const bool hand = alone.data[i] == static_cast<uint8_t>(PixelLabel::kHand);
    const bool covered = box_only.label[i] != 0;
    ASSERT_EQ(with_box.data[i], covered ? static_cast<uint8_t>(PixelLabel::kObject)
                                        : (hand ? static_cast<uint8_t>(PixelLabel::kHand) : 0))
        << "pixel " << i;
    hidden += hand && covered;
  }
  EXPECT_GT(hidden, 500) << "the box must hide part of the hand for this test to mean anything";
  EXPECT_GT(Count(with_box, PixelLabel::kHand), 1000);
}

TEST(RendererTest, ProjectedKeypointsLandOnTheRenderedHand) {
  Renderer renderer(RightHand());
  Random random(testing::kTestSeed);
  for (int trial = 0; trial < 20; ++trial) {
    const Scene scene = HandScene(RandomViewpoint(random), RandomArticulation(random));
    cv::Mat labels;
    renderer.RenderLabels(scene, kCamera, &labels);
    const Keypoints3d keypoints = RightHand().KeypointsOf(scene.hand);
    for (int k = 0; k < kNumKeypoints; ++k) {
      const Eigen::Vector2d p = Project(kCamera, keypoints[k] + scene.wrist_in_camera);
      // Joints lie inside the mesh, so they project onto it; a tip may sit on the silhouette.
      bool near_hand = false;
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          const int x = static_cast<int>(std::floor(p.x())) + dx, y = static_cast<int>(std::floor(p.y())) + dy;
          near_hand |= x >= 0 && y >= 0 && x < kCamera.width && y < kCamera.height &&
                       labels.at<uint8_t>(y, x) == static_cast<uint8_t>(PixelLabel::kHand);
        }
      }
      EXPECT_TRUE(near_hand) << KeypointName(k) << " in trial " << trial;
    }
  }
}

TEST(RendererTest, SkippingBackFacesOfTheClosedHandChangesNoPixel) {
  Random random(testing::kTestSeed);
  std::vector<Eigen::Vector3f> vertices;
  for (int trial = 0; trial < 10; ++trial) {
    const Scene scene = HandScene(RandomViewpoint(random), RandomArticulation(random));
    RightHand().Skin(scene.hand, &vertices, nullptr);
    for (Eigen::Vector3f& v : vertices) v += scene.wrist_in_camera.cast<float>();
    RasterTarget both, front;
    both.Reset(kCamera.width, kCamera.height, false);
    front.Reset(kCamera.width, kCamera.height, false);
    RasterizeTriangles(kCamera, vertices, RightHand().triangles(), {}, 1, Faces::kBoth, &both);
    RasterizeTriangles(kCamera, vertices, RightHand().triangles(), {}, 1, Faces::kFrontOnly, &front);
    EXPECT_EQ(both.label, front.label) << "trial " << trial;
  }
}

TEST(RendererTest, FullRenderIsConsistentAndDeterministic) {
  Renderer renderer(RightHand());
  Scene scene = HandScene({0.0, 0.0, 0.0}, NamedArticulation("pinch"));
  SceneObject ball;
  ball.spec = {ObjectShape::kSphere, {0.03, 0, 0}, 32};
  ball.hand_from_object.translation() = Eigen::Vector3d(0.1, 0.02, -0.05);
  scene.objects = {ball};
  const RenderedImages a = renderer.Render(scene, kCamera);
  const RenderedImages b = renderer.Render(scene, kCamera);
  cv::Mat labels_only;
  renderer.RenderLabels(scene, kCamera, &labels_only);
  EXPECT_EQ(cv::norm(a.labels, labels_only, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(a.rgb, b.rgb, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(a.depth, b.depth, cv::NORM_INF), 0.0);
  EXPECT_GT(Count(a.labels, PixelLabel::kObject), 100);
  for (int i = 0; i < kCamera.width * kCamera.height; ++i) {
    const float depth = a.depth.ptr<float>()[i];
    const cv::Vec3b colour = a.rgb.ptr<cv::Vec3b>()[i];
    if (a.labels.data[i] == 0) {
      ASSERT_EQ(depth, 0.0f);
      ASSERT_EQ(colour, cv::Vec3b(0, 0, 0));
    } else {
      ASSERT_GT(depth, 0.35f);
      ASSERT_LT(depth, 0.65f);
      ASSERT_NE(colour, cv::Vec3b(0, 0, 0));
    }
  }
}

TEST(RendererTest, ForearmAddsItsOwnPixelsBehindTheWristAndIsClosed) {
  Renderer renderer(RightHand());
  // Looking at the palm, fingers up: the forearm goes down from the wrist.
  Scene scene = HandScene({0.0, 0.0, 0.0}, NamedArticulation("relaxed"));
  scene.wrist_in_camera = CenteredWristPosition(scene.hand.camera_from_hand, RightHand().bind_centre(), 0.9);
  const RenderedImages bare = renderer.Render(scene, kCamera);
  scene.forearm = Forearm{};
  RenderOptions sleeved;
  sleeved.sleeve_colour = cv::Vec3f(200, 60, 40);
  const RenderedImages with_arm = renderer.Render(scene, kCamera, sleeved);
  EXPECT_GT(Count(with_arm.labels, PixelLabel::kForearm), 2000);
  // The forearm starts inside the wrist: it hides at most a thin band of the hand.
  EXPECT_GT(Count(with_arm.labels, PixelLabel::kHand), 0.9 * Count(bare.labels, PixelLabel::kHand));
  const cv::Rect hand_box = cv::boundingRect(bare.labels == static_cast<int>(PixelLabel::kHand));
  const cv::Rect arm_box = cv::boundingRect(with_arm.labels == static_cast<int>(PixelLabel::kForearm));
  EXPECT_GT(arm_box.y + arm_box.height, hand_box.y + hand_box.height + 40);
  // Its mesh is closed and wound outward: drawing back faces too changes no label.
  const cv::Vec3b sleeve(200, 60, 40);
  int sleeve_pixels = 0;
  for (int i = 0; i < kCamera.width * kCamera.height; ++i) {
    if (with_arm.labels.data[i] == static_cast<uint8_t>(PixelLabel::kForearm)) {
      const cv::Vec3b c = with_arm.rgb.ptr<cv::Vec3b>()[i];
      sleeve_pixels += c[0] > c[2];
    }
  }
  EXPECT_EQ(sleeve_pixels, Count(with_arm.labels, PixelLabel::kForearm));
  cv::Mat labels_only;
  renderer.RenderLabels(scene, kCamera, &labels_only);
  EXPECT_EQ(cv::norm(with_arm.labels, labels_only, cv::NORM_INF), 0.0);
}

// An adult's forearm seen across the palm widens from the wrist to the elbow by its width's
// scale, seen edge-on by its thickness's (it is rounder at the elbow than the wrist); its
// upper arm goes on beyond the elbow as thick as the elbow.
TEST(RendererTest, AnAdultsArmWidensToARounderElbowAndGoesOn) {
  Renderer renderer(RightHand());
  const Forearm adult = Forearm::Adult();
  Forearm forearm_only = adult;
  forearm_only.upper_arm_length = 0.0;
  struct View {
    Viewpoint from;
    double widening;
  };
  for (const View& view : {View{{0.0, 0.0, 0.0}, adult.elbow_width_scale},
                           View{{0.0, std::numbers::pi / 2.0, 0.0}, adult.elbow_depth_scale}}) {
    Scene scene = HandScene(view.from, NamedArticulation("relaxed"));
    scene.wrist_in_camera = CenteredWristPosition(scene.hand.camera_from_hand, RightHand().bind_centre(), 2.0);
    auto arm_of = [&](const Forearm& forearm, cv::Rect* hand) {
      scene.forearm = forearm;
      cv::Mat labels;
      renderer.RenderLabels(scene, kCamera, &labels);
      *hand = cv::boundingRect(labels == static_cast<int>(PixelLabel::kHand));
      return cv::Mat(labels == static_cast<int>(PixelLabel::kForearm));
    };
    cv::Rect hand;
    const cv::Mat arm = arm_of(forearm_only, &hand);
    const cv::Rect elbow = cv::boundingRect(arm);
    ASSERT_GT(elbow.y + elbow.height, hand.y + hand.height + 25) << view.from.elevation;
    // The widths of the rows just below the hand and just short of the elbow's cap.
    const double wrist = cv::countNonZero(arm.row(hand.y + hand.height + 2));
    const double at_elbow = cv::countNonZero(arm.row(elbow.y + elbow.height - 3));
    // The wrist's row lies a little towards the elbow from the wrist end (inside the hand).
    EXPECT_GT(at_elbow / wrist, 0.8 * view.widening) << view.from.elevation;
    EXPECT_LT(at_elbow / wrist, 1.1 * view.widening) << view.from.elevation;
    // The upper arm, seen from further off to be whole: the arm below the hand (all but the
    // centimetre of the wrist end inside it) longer by the upper arm's length, as thick as the
    // elbow's end at its own.
    scene.wrist_in_camera = CenteredWristPosition(scene.hand.camera_from_hand, RightHand().bind_centre(), 4.0);
    const double forearm_rows = cv::boundingRect(arm_of(forearm_only, &hand)).br().y - hand.br().y;
    const cv::Mat whole = arm_of(adult, &hand);
    const cv::Rect upper = cv::boundingRect(whole);
    ASSERT_LT(upper.br().y, kCamera.height) << view.from.elevation;
    EXPECT_NEAR((upper.br().y - hand.br().y) / forearm_rows, (adult.length + adult.upper_arm_length - 0.01) / (adult.length - 0.01),
                0.15)
        << view.from.elevation;
    EXPECT_NEAR(cv::countNonZero(whole.row(upper.br().y - 2)), at_elbow / 2.0, 2.0) << view.from.elevation;
  }
}

TEST(RendererTest, BadInputsAreRefused) {
  Renderer renderer(RightHand());
  Scene scene = HandScene({}, {});
  Intrinsics bad = kCamera;
  bad.width = 0;
  cv::Mat labels;
  EXPECT_THROW(renderer.RenderLabels(scene, bad, &labels), Error);
  RenderOptions options;
  options.background = cv::Mat(4, 4, CV_32FC1);
  EXPECT_THROW(renderer.Render(scene, kCamera, options), Error);
  options = {};
  options.skin_colour = cv::Vec3f(300, 0, 0);
  EXPECT_THROW(renderer.Render(scene, kCamera, options), Error);
  scene.forearm = Forearm{-0.1, 1.0, 1.0};
  EXPECT_THROW(renderer.RenderLabels(scene, kCamera, &labels), Error);
  scene.forearm = Forearm{0.24, 1.6, 0.0};
  EXPECT_THROW(renderer.RenderLabels(scene, kCamera, &labels), Error);
  scene.forearm = Forearm{0.24, 1.6, 2.1, -0.3};
  EXPECT_THROW(renderer.RenderLabels(scene, kCamera, &labels), Error);
  scene.forearm.reset();
  scene.hand.handedness = Handedness::kLeft;
  EXPECT_THROW(renderer.RenderLabels(scene, kCamera, &labels), Error);
}

}  // namespace
}  // namespace nphand
