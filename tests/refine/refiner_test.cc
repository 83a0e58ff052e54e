// Refinement: a silhouette's pose recovered from a start off it, the objective never worse
// than the start's, joint limits kept, the same bytes for the same input, bad targets refused.
#include "nphand/refine/refiner.h"

#include <cmath>
#include <numbers>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "nphand/scene/viewpoint.h"
#include "nphand/util/random.h"
#include "testing/testing.h"

namespace nphand {
namespace {

using testing::RightHand;

constexpr double kDistance = 0.5;
constexpr double kDeg = std::numbers::pi / 180.0;

// The database's camera: 128 pixels, 30 degrees.
Intrinsics Camera() { return Intrinsics::FromFieldOfView(128, 128, 30.0 * kDeg); }

CropOptions Crop() { return {64, 0.1, true}; }

Scene SceneOf(const JointAngles& angles, const Eigen::Matrix3d& camera_from_hand) {
  Scene scene;
  scene.hand.angles = angles;
  scene.hand.camera_from_hand = camera_from_hand;
  scene.wrist_in_camera = CenteredWristPosition(camera_from_hand, RightHand().bind_centre(), kDistance);
  return scene;
}

HandCrop CropOf(const Scene& scene) {
  Renderer renderer(RightHand());
  cv::Mat labels;
  renderer.RenderLabels(scene, Camera(), &labels);
  return *CropHand(labels == static_cast<int>(PixelLabel::kHand), Crop());
}

// A half-closed hand seen from the side of its back.
JointAngles HalfClosed() {
  return AnglesFromDegrees({20, 10, 10, 20, 20}, {40, 5, 45, 20}, {45, 0, 50, 25}, {50, -5, 50, 25}, {55, -10, 45, 20});
}

// A pose in the refinement's camera as the estimator reports it: turned in the image plane
// by the target crop's roll less the start crop's, less the turn the refinement gave the
// silhouette in the crop.
Eigen::Matrix3d Reported(const Eigen::Matrix3d& camera_from_hand, double turn, const HandCrop& target, const HandCrop& start_crop) {
  return AxisAngle(Eigen::Vector3d::UnitZ(), target.roll - start_crop.roll - turn) * camera_from_hand;
}

double MeanKeypointMm(const JointAngles& angles, const Eigen::Matrix3d& rotation, const Scene& truth) {
  HandPose pose;
  pose.angles = angles;
  pose.camera_from_hand = rotation;
  const Keypoints3d a = RightHand().KeypointsOf(pose), b = RightHand().KeypointsOf(truth.hand);
  double sum = 0.0;
  for (int k = 0; k < kNumKeypoints; ++k) sum += (a[k] - b[k]).norm();
  return 1000.0 * sum / kNumKeypoints;
}

// The wrist turned by 10 degrees off a view, searched thoroughly (renders of the camera's
// size, eight passes): the refinement brings it most of the way back (measured: to 3.6, 2.0
// and 1.7 degrees; the keypoints from 17.6, 6.6 and 10.9 mm to 6.0, 3.6 and 3.0).
TEST(RefinerTest, APerturbedWristIsRecovered) {
  const Eigen::Matrix3d view = CameraFromHand(ViewpointFromDirection(Eigen::Vector3d(0.3, -0.4, 1.0), 0.4));
  const Scene truth = SceneOf(HalfClosed(), view);
  const HandCrop target = CropOf(truth);
  RefineOptions thorough;
  thorough.render_side = 128;
  thorough.sweeps = 8;
  thorough.halvings = 4;
  Refiner refiner(RightHand(), Camera(), kDistance, Crop(), thorough);
  for (const Eigen::Vector3d& axis : {Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0, 1, 0), Eigen::Vector3d(1, 1, 0).normalized()}) {
    const Scene start = SceneOf(HalfClosed(), AxisAngle(axis, 10.0 * kDeg) * view);
    const HandCrop start_crop = CropOf(start);
    const Refinement r = refiner.Refine(target, start, start_crop.crop_from_image);
    const Eigen::Matrix3d start_reported = Reported(start.hand.camera_from_hand, 0.0, target, start_crop);
    const Eigen::Matrix3d reported = Reported(r.scene.hand.camera_from_hand, r.turn, target, start_crop);
    EXPECT_TRUE(r.moved);
    EXPECT_LT(r.disagreement_after, 0.5 * r.disagreement_before) << "axis " << axis.transpose();
    EXPECT_LT(RotationAngleDeg(reported, view), 0.5 * RotationAngleDeg(start_reported, view)) << "axis " << axis.transpose();
    EXPECT_LT(MeanKeypointMm(r.scene.hand.angles, reported, truth), 0.7 * MeanKeypointMm(start.hand.angles, start_reported, truth))
        << "axis " << axis.transpose();
  }
}

// A hand 10 % longer and 10 % narrower than the database's (`Reproportioned(1.1, 0.9)`: at
// the same length 0.818 as wide) in the start's pose, from several views: with the
// proportions measured, the silhouette favours its width (measured: 0.830-0.840 over these
// views at the default render size, in 243-298 renders against 37-40 for the search alone),
// and the search with that width agrees with it better than with the database's hand (1 -
// IoU 0.035-0.056 against 0.088-0.133).
TEST(RefinerTest, TheHandsWidthIsFoundFromItsSilhouette) {
  const HandModel narrow = RightHand().Reproportioned(1.1, 0.9);
  RefineOptions options;
  options.move_proportions = true;
  Refiner refiner(RightHand(), Camera(), kDistance, Crop(), options);
  for (const Eigen::Vector3d& direction :
       {Eigen::Vector3d(0.3, -0.4, 1.0), Eigen::Vector3d(-0.2, 0.1, 1.0), Eigen::Vector3d(0.6, 0.3, 1.0), Eigen::Vector3d(0.1, 0.6, -1.0)}) {
    const Eigen::Matrix3d view = CameraFromHand(ViewpointFromDirection(direction, 0.4));
    Scene truth = SceneOf(HalfClosed(), view);
    truth.wrist_in_camera = CenteredWristPosition(view, narrow.bind_centre(), kDistance);
    Renderer renderer(narrow);
    cv::Mat labels;
    renderer.RenderLabels(truth, Camera(), &labels);
    const HandCrop target = *CropHand(labels == static_cast<int>(PixelLabel::kHand), Crop());
    const Scene start = SceneOf(HalfClosed(), view);
    const cv::Matx23d start_map = CropOf(start).crop_from_image;
    const Refinement measuring = refiner.Refine(target, start, start_map);
    EXPECT_EQ(measuring.width, 1.0);
    EXPECT_NEAR(measuring.width_measured, 0.9 / 1.1, 0.03) << direction.transpose();
    const Refinement with = refiner.Refine(target, start, start_map, nullptr, measuring.width_measured, false);
    EXPECT_EQ(with.width, measuring.width_measured);
    EXPECT_EQ(with.width_measured, with.width);
    EXPECT_LT(with.disagreement_after, measuring.disagreement_after) << direction.transpose();
    EXPECT_EQ(&refiner.Model(1.0), &RightHand());
    // The model of that width: as long as the database's hand, its width across the palm scaled.
    auto extent = [](const HandModel& model, int axis) {
      float low = 1e9f, high = -1e9f;
      for (const Eigen::Vector3f& v : model.bind_vertices()) low = std::min(low, v[axis]), high = std::max(high, v[axis]);
      return static_cast<double>(high - low);
    };
    EXPECT_NEAR(extent(refiner.Model(with.width), 0), extent(RightHand(), 0), 1e-6);
    EXPECT_NEAR(extent(refiner.Model(with.width), 1) / extent(RightHand(), 1), with.width, 1e-6);
  }
}

// The pull towards the previous frame's rotation holds the wrist back when strong, and a
// previous rotation far from the start (a new view of the track) is ignored.
TEST(RefinerTest, ThePreviousFramesRotationPulls) {
  const Eigen::Matrix3d view = CameraFromHand(ViewpointFromDirection(Eigen::Vector3d(0.3, -0.4, 1.0), 0.4));
  const HandCrop target = CropOf(SceneOf(HalfClosed(), view));
  const Scene start = SceneOf(HalfClosed(), AxisAngle(Eigen::Vector3d(0, 1, 0), 10.0 * kDeg) * view);
  const cv::Matx23d start_map = CropOf(start).crop_from_image;
  Refiner free(RightHand(), Camera(), kDistance, Crop());
  const Refinement alone = free.Refine(target, start, start_map);
  const Eigen::Matrix3d far = AxisAngle(Eigen::Vector3d(1, 0, 0), 90.0 * kDeg) * start.hand.camera_from_hand;
  const Refinement ignored = free.Refine(target, start, start_map, &far);
  EXPECT_EQ(ignored.objective_after, alone.objective_after);
  EXPECT_TRUE(RotationOf(ignored) == RotationOf(alone));
  RefineOptions strong;
  strong.track = 50.0;
  Refiner held(RightHand(), Camera(), kDistance, Crop(), strong);
  const Refinement pulled = held.Refine(target, start, start_map, &start.hand.camera_from_hand);
  EXPECT_LT(RotationAngleDeg(RotationOf(pulled), start.hand.camera_from_hand),
            0.5 * RotationAngleDeg(RotationOf(alone), start.hand.camera_from_hand));
}

// Starts off in every way (wrist, fingers, place), the fingers moving too: never worse than
// the start, always within the joints' limits.
TEST(RefinerTest, TheObjectiveNeverRisesAndLimitsHold) {
  RefineOptions options;
  options.move_fingers = true;
  Refiner refiner(RightHand(), Camera(), kDistance, Crop(), options);
  Random random(testing::kTestSeed);
  for (int trial = 0; trial < 6; ++trial) {
    const Eigen::Matrix3d view = CameraFromHand(RandomViewpoint(random));
    JointAngles angles = HalfClosed();
    for (double& a : angles) a += random.Uniform(-0.3, 0.3);
    const Scene truth = SceneOf(ClampToLimits(angles), view);
    const Scene start = SceneOf(HalfClosed(), AxisAngle(Eigen::Vector3d::UnitZ(), random.Uniform(-0.2, 0.2)) * view);
    cv::Matx23d crop_from_image = CropOf(start).crop_from_image;
    crop_from_image(0, 2) += random.Uniform(-3.0, 3.0);
    const Refinement r = refiner.Refine(CropOf(truth), start, crop_from_image);
    EXPECT_LE(r.objective_after, r.objective_before) << trial;
    EXPECT_TRUE(r.scene.hand.IsValid()) << trial;
    EXPECT_GT(r.renders, 1) << trial;
  }
}

// Moving the place only changes the crop map, not the hand: the search poses and rasterises
// the hand once and warps that render for every trial of the place (a shifted start, which
// the place alone mends).
TEST(RefinerTest, TrialsOfThePlaceAloneReuseTheRender) {
  const Eigen::Matrix3d view = CameraFromHand(ViewpointFromDirection(Eigen::Vector3d(0.3, -0.2, 1.0), 1.0));
  const Scene start = SceneOf(HalfClosed(), view);
  cv::Matx23d shifted = CropOf(start).crop_from_image;
  shifted(0, 2) += 4.0;
  shifted(1, 2) -= 3.0;
  RefineOptions place_only;
  place_only.move_wrist = false;
  Refiner placer(RightHand(), Camera(), kDistance, Crop(), place_only);
  const Refinement placed = placer.Refine(CropOf(start), start, shifted);
  ASSERT_TRUE(placed.moved);
  EXPECT_LT(placed.disagreement_after, 0.5 * placed.disagreement_before);
  EXPECT_EQ(placed.renders, 1) << "one render, warped for every trial";
}

TEST(RefinerTest, TheSameInputGivesTheSameBytes) {
  const Eigen::Matrix3d view = CameraFromHand(ViewpointFromDirection(Eigen::Vector3d(-0.5, 0.2, 1.0), 1.0));
  const Scene start = SceneOf(HalfClosed(), AxisAngle(Eigen::Vector3d::UnitY(), 0.15) * view);
  const HandCrop target = CropOf(SceneOf(HalfClosed(), view));
  RefineOptions options;
  options.move_fingers = true;
  Refiner a(RightHand(), Camera(), kDistance, Crop(), options), b(RightHand(), Camera(), kDistance, Crop(), options);
  const Refinement ra = a.Refine(target, start, CropOf(start).crop_from_image);
  const Refinement rb = b.Refine(target, start, CropOf(start).crop_from_image);
  EXPECT_EQ(ra.scene.hand.angles, rb.scene.hand.angles);
  EXPECT_TRUE(ra.scene.hand.camera_from_hand == rb.scene.hand.camera_from_hand);
  EXPECT_EQ(cv::norm(ra.crop_from_image, rb.crop_from_image, cv::NORM_INF), 0.0);
  EXPECT_EQ(ra.objective_after, rb.objective_after);
  EXPECT_EQ(ra.renders, rb.renders);
}

TEST(RefinerTest, EmptyAndWrongTargetsAndOptions) {
  const Eigen::Matrix3d view = CameraFromHand(Viewpoint{});
  const Scene start = SceneOf(HalfClosed(), view);
  Refiner refiner(RightHand(), Camera(), kDistance, Crop());
  // Nothing to agree with: nothing agrees better, and the start stays.
  HandCrop empty;
  empty.image = cv::Mat::zeros(64, 64, CV_32FC1);
  const Refinement r = refiner.Refine(empty, start, CropOf(start).crop_from_image);
  EXPECT_FALSE(r.moved);
  EXPECT_EQ(r.objective_after, r.objective_before);
  EXPECT_EQ(r.scene.hand.angles, start.hand.angles);
  HandCrop small;
  small.image = cv::Mat::zeros(32, 32, CV_32FC1);
  testing::ExpectError([&] { refiner.Refine(small, start, cv::Matx23d()); },
                       "the target must be a 64 x 64 crop");
  RefineOptions bad;
  bad.sweeps = -1;
  testing::ExpectError([&] { Refiner(RightHand(), Camera(), kDistance, Crop(), bad); }, "refinement sweeps");
  bad = RefineOptions{};
  bad.render_side = 4;
  testing::ExpectError([&] { Refiner(RightHand(), Camera(), kDistance, Crop(), bad); }, "render side");
  bad = RefineOptions{};
  bad.width_step = 0.5;
  testing::ExpectError([&] { Refiner(RightHand(), Camera(), kDistance, Crop(), bad); }, "width step");
  testing::ExpectError([&] { Refiner(RightHand(), Camera(), 0.0, Crop()); }, "distance must be positive");
}

TEST(RefinerTest, WhatMovesIsChosenByName) {
  RefineOptions options;
  EXPECT_EQ(RefineMoves(options), (std::vector<std::string>{"place", "wrist"}));
  SetRefineMoves({"fingers", "wrist"}, &options);
  EXPECT_FALSE(options.move_place);
  EXPECT_TRUE(options.move_wrist);
  EXPECT_TRUE(options.move_fingers);
  EXPECT_EQ(RefineMoves(options), (std::vector<std::string>{"wrist", "fingers"}));
  SetRefineMoves({"proportions"}, &options);
  EXPECT_TRUE(options.move_proportions);
  EXPECT_EQ(RefineMoves(options), (std::vector<std::string>{"proportions"}));
  SetRefineMoves({"fingers", "wrist"}, &options);
  const RefineOptions kept = options;
  testing::ExpectError([&] { SetRefineMoves({"place", "thumb"}, &options); }, "unknown refinement move 'thumb'");
  testing::ExpectError([&] { SetRefineMoves({"wrist", "wrist"}, &options); }, "'wrist' is named twice");
  testing::ExpectError([&] { SetRefineMoves({}, &options); }, "must move something");
  EXPECT_EQ(RefineMoves(options), RefineMoves(kept));  // a refused list changes nothing
  options.move_wrist = options.move_fingers = false;
  std::string why;
  EXPECT_FALSE(options.Check(&why));
  EXPECT_NE(why.find("must move something"), std::string::npos) << why;
}

TEST(RefinerTest, DisagreementIsOneMinusIoUAndSkipsTheUnknown) {
  cv::Mat a = cv::Mat::zeros(8, 8, CV_32FC1), b = cv::Mat::zeros(8, 8, CV_32FC1);
  a(cv::Rect(0, 0, 4, 8)).setTo(1.0);
  b(cv::Rect(2, 0, 4, 8)).setTo(1.0);
  EXPECT_NEAR(Disagreement(a, b), 1.0 - 16.0 / 48.0, 1e-12);
  EXPECT_EQ(Disagreement(a, a), 0.0);
  cv::Mat unknown = cv::Mat::zeros(8, 8, CV_32FC1);
  unknown(cv::Rect(4, 0, 2, 8)).setTo(1.0);
  EXPECT_NEAR(Disagreement(a, b, &unknown), 1.0 - 16.0 / 32.0, 1e-12);
}

}  // namespace
}  // namespace nphand
