#include "nphand/sequence/sequence.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <Eigen/Geometry>
#include <opencv2/imgproc.hpp>

#include "nphand/scene/gesture.h"
#include "nphand/scene/viewpoint.h"
#include "nphand/util/check.h"
#include "nphand/util/random.h"

namespace nphand {
namespace {

constexpr double kDegToRad = std::numbers::pi / 180.0;
// The share of the sequence over which the hand closes; it then holds the grasp.
constexpr double kClosingShare = 0.6;
// The background is this much larger than a frame on each side, for the camera to pan.
constexpr double kPanMargin = 0.08;

const std::vector<SkinTone> kSkinTones = {
    {"light", cv::Vec3f(165, 190, 235)}, {"medium", cv::Vec3f(120, 160, 215)}, {"olive", cv::Vec3f(95, 140, 185)},
    {"brown", cv::Vec3f(70, 105, 160)},  {"dark", cv::Vec3f(45, 70, 115)}};

double SmoothStep(double t) {
  t = std::clamp(t, 0.0, 1.0);
  return t * t * (3.0 - 2.0 * t);
}

std::vector<double> ToVector(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

}  // namespace

const std::vector<SkinTone>& SkinTones() { return kSkinTones; }

const SkinTone& SkinToneByName(const std::string& name) {
  for (const SkinTone& tone : kSkinTones) {
    if (name == tone.name) return tone;
  }
  NPHAND_THROW("unknown skin tone '", name, "' (choose light, medium, olive, brown or dark)");
}

std::string ToString(ForearmKind kind) {
  switch (kind) {
    case ForearmKind::kNone: return "none";
    case ForearmKind::kBare: return "bare";
    case ForearmKind::kSleeved: return "sleeved";
  }
  return "?";
}

ForearmKind ForearmKindFromString(const std::string& text) {
  if (text == "none") return ForearmKind::kNone;
  if (text == "bare") return ForearmKind::kBare;
  if (text == "sleeved") return ForearmKind::kSleeved;
  NPHAND_THROW("unknown forearm '", text, "' (choose none, bare or sleeved)");
}

bool SequenceOptions::Check(std::string* why) const {
  if (frames < 1 || frames > 1000000) {
    *why = "frames must be within [1, 1000000]";
  } else if (!(fps > 0.0 && fps <= 1000.0)) {
    *why = "fps must be within (0, 1000]";
  } else if (width < 64 || height < 64 || width > 4096 || height > 4096) {
    *why = "the frame size must be within 64..4096 pixels a side";
  } else if (!(fov_deg >= 10.0 && fov_deg <= 120.0)) {
    *why = "the field of view must be within [10, 120] degrees";
  } else if (grasp < 0 || grasp > kNumHandShapes) {
    *why = "grasp must be a taxonomy number 1..33, a gesture's 34.." + std::to_string(kNumHandShapes) +
           " (or 0: chosen by the seed)";
  } else if (IsGesture(grasp) && object) {
    *why = "a gesture (" + HandShapeKey(grasp) + ") holds no object";
  } else if (!(object_scale == 0.0 || (object_scale >= 0.5 && object_scale <= 2.0))) {
    *why = "object scale must be within [0.5, 2] (or 0: chosen by the seed)";
  } else if (!(beyond_steps >= 0.0 && beyond_steps <= 1.0)) {
    *why = "beyond-steps must be within [0, 1]";
  } else if (!(turn_deg >= 0.0 && turn_deg <= 180.0) || !(std::abs(roll_deg) <= 720.0)) {
    *why = "turn must be within [0, 180] degrees and roll within [-720, 720]";
  } else if (!(distance_m >= 0.2 && distance_m <= 2.0)) {
    *why = "distance must be within [0.2, 2] metres";
  } else if (!(noise >= 0.0 && noise <= 50.0)) {
    *why = "noise must be within [0, 50] levels";
  } else if (!skin.empty() && std::none_of(kSkinTones.begin(), kSkinTones.end(),
                                           [&](const SkinTone& t) { return skin == t.name; })) {
    *why = "unknown skin tone '" + skin + "' (choose light, medium, olive, brown or dark)";
  } else if (sweater && !face) {
    *why = "a sweater needs a face (it is the person's)";
  } else if (adult_arm && forearm == ForearmKind::kNone) {
    *why = "an adult's arm needs a forearm (bare or sleeved)";
  } else {
    return true;
  }
  return false;
}

Sequence::Sequence(const HandModel& hand, const SequenceOptions& options)
    : hand_(hand), options_(options), renderer_(hand) {
  std::string why;
  NPHAND_THROW_CHECK(options.Check(&why), "sequence: ", why);
  NPHAND_THROW_CHECK(hand.handedness() == Handedness::kRight,
                     "sequence: renders with the right hand model (a left hand is its mirror image)");
  Random random(options.seed);
  intrinsics_ = Intrinsics::FromFieldOfView(options.width, options.height, options.fov_deg * kDegToRad);

  const int grasp_id = options.grasp != 0 ? options.grasp : 1 + static_cast<int>(random.UniformIndex(kNumGrasps));
  const double scale = options.object_scale != 0.0 ? options.object_scale : (random.Uniform() < 0.5 ? 0.8 : 1.25);
  if (IsGesture(grasp_id)) {
    grasp_.id = static_cast<grasp_id_t>(grasp_id);
    grasp_.steps = GestureSteps(Gestures()[grasp_id - kFirstGestureId]);
  } else {
    GraspDefinition definition = GraspTaxonomy()[grasp_id - 1];
    for (double& size : definition.object.size) size *= scale;
    grasp_ = MakeGrasp(hand, definition);
  }

  const SkinTone& tone = options.skin.empty() ? kSkinTones[random.UniformIndex(kSkinTones.size())]
                                              : SkinToneByName(options.skin);
  skin_ = tone.name;
  skin_bgr_ = tone.bgr;
  sleeve_bgr_ = cv::Vec3f(static_cast<float>(random.Uniform(60, 200)), static_cast<float>(random.Uniform(30, 120)),
                          static_cast<float>(random.Uniform(10, 60)));
  light_ = Eigen::Vector3d(random.Uniform(-0.6, 0.6), random.Uniform(-0.8, 0.0), -1.0);

  // The path: a start direction from which the forearm does not hide the hand, turning
  // about an axis perpendicular to it.
  do {
    start_direction_ = ViewDirection(RandomViewpoint(random));
  } while (start_direction_.x() < -0.3);
  Eigen::Vector3d axis;
  do {
    axis = ViewDirection(RandomViewpoint(random)).cross(start_direction_);
  } while (axis.norm() < 0.3);
  turn_axis_ = axis.normalized();
  if ((Eigen::AngleAxisd(options.turn_deg * kDegToRad, turn_axis_) * start_direction_).x() < -0.3) turn_axis_ = -turn_axis_;
  start_roll_ = random.Uniform(-std::numbers::pi, std::numbers::pi);
  for (double& phase : phases_) phase = random.Uniform(0.0, 2.0 * std::numbers::pi);

  const cv::Size size(static_cast<int>(options.width * (1.0 + 2.0 * kPanMargin)),
                      static_cast<int>(options.height * (1.0 + 2.0 * kPanMargin)));
  background_ = MakeBackground(options.background, size, random.Next());
  if (options.face) {
    // A person behind the hand: wholly in view whatever the pan, on the side the hand's
    // sideways motion (Render) visits less. A hand passing in front of a face is not
    // rendered: the skin model would take hand and face for one region.
    double drift = 0.0;
    for (int i = 0; i <= 100; ++i) drift += std::sin(1.3 * std::numbers::pi * i / 100.0 + phases_[2]);
    const int height = options.height * 2 / 5;
    const int side = drift > 0.0 ? -1 : 1;
    const cv::Point centre(size.width / 2 + side * size.width / 4, size.height * 2 / 5);
    if (options.sweater) {
      // Drawn last from the seed, so that sequences without one keep their bytes.
      const double shade = random.Uniform();
      const cv::Vec3f cream(185, 215, 235), camel(105, 150, 195);
      DrawSweater(cream + shade * (camel - cream), centre, height, &background_);
    }
    DrawFace(skin_bgr_, centre, height, &background_);
  }
}

double Sequence::hand_length_m() const {
  return HandLength(hand_.KeypointsOf(HandPose{}));
}

JointAngles Sequence::AnglesAt(double step) const {
  const auto& steps = grasp_.steps;
  JointAngles angles{};
  if (step <= 0.0) {
    // Opening past the pre-shape: towards the flat hand.
    const double f = std::min(1.0, -step);
    for (int d = 0; d < kNumDofs; ++d) angles[d] = (1.0 - f) * steps[0][d];
  } else if (step >= kGraspSteps - 1) {
    const double f = step - (kGraspSteps - 1);
    for (int d = 0; d < kNumDofs; ++d) angles[d] = steps[4][d] + f * (steps[4][d] - steps[3][d]);
  } else {
    const int i = static_cast<int>(std::floor(step));
    const double f = step - i;
    for (int d = 0; d < kNumDofs; ++d) angles[d] = (1.0 - f) * steps[i][d] + f * steps[i + 1][d];
  }
  return ClampToLimits(angles);
}

cv::Mat Sequence::BackgroundAt(double t) const {
  // The camera's pan: the frame is a moving window of the larger background.
  const int pan_x = static_cast<int>(std::lround(kPanMargin * options_.width * (1.0 + std::sin(2.0 * std::numbers::pi * t + phases_[2]))));
  const int pan_y = static_cast<int>(std::lround(kPanMargin * options_.height * (1.0 + std::cos(2.0 * std::numbers::pi * t + phases_[3]))));
  return background_(cv::Rect(std::clamp(pan_x, 0, background_.cols - options_.width),
                              std::clamp(pan_y, 0, background_.rows - options_.height), options_.width, options_.height));
}

void Sequence::AddNoise(int i, cv::Mat* bgr) const {
  if (options_.noise <= 0.0) return;
  cv::Mat noise(bgr->size(), CV_32FC3);
  cv::RNG rng(options_.seed * 1000003ULL + static_cast<uint64_t>(i));
  rng.fill(noise, cv::RNG::NORMAL, 0.0, options_.noise);
  cv::Mat shaded;
  bgr->convertTo(shaded, CV_32FC3);
  cv::Mat(shaded + noise).convertTo(*bgr, CV_8UC3);
}

cv::Mat Sequence::RenderEmpty(int i) const {
  NPHAND_THROW_CHECK(i >= 0 && i < options_.frames, "sequence: frame ", i, " is not within 0..", options_.frames - 1);
  const double t = options_.frames > 1 ? static_cast<double>(i) / (options_.frames - 1) : 0.0;
  cv::Mat frame = BackgroundAt(t).clone();
  AddNoise(i, &frame);
  if (options_.hand == Handedness::kLeft) cv::flip(frame, frame, 1);
  return frame;
}

SequenceFrame Sequence::Render(int i) {
  NPHAND_THROW_CHECK(i >= 0 && i < options_.frames, "sequence: frame ", i, " is not within 0..", options_.frames - 1);
  const double t = options_.frames > 1 ? static_cast<double>(i) / (options_.frames - 1) : 0.0;
  SequenceFrame frame;
  frame.index = i;
  frame.time_s = i / options_.fps;

  const double end_step = (kGraspSteps - 1) + (options_.object ? 0.0 : options_.beyond_steps);
  frame.step = -options_.beyond_steps + (end_step + options_.beyond_steps) * SmoothStep(t / kClosingShare);

  const double u = SmoothStep(t);
  const Eigen::Vector3d direction = Eigen::AngleAxisd(options_.turn_deg * kDegToRad * u, turn_axis_) * start_direction_;
  const double roll = start_roll_ + options_.roll_deg * kDegToRad * u + 0.15 * std::sin(2.0 * std::numbers::pi * t + phases_[0]);
  Scene scene;
  scene.hand.angles = AnglesAt(frame.step);
  scene.hand.camera_from_hand = CameraFromHand(ViewpointFromDirection(direction, roll));
  const double distance = options_.distance_m * (1.0 + 0.12 * std::sin(2.0 * std::numbers::pi * t + phases_[1]));
  const double reach = 0.22 * distance * std::tan(0.5 * options_.fov_deg * kDegToRad);
  scene.wrist_in_camera = CenteredWristPosition(scene.hand.camera_from_hand, hand_.bind_centre(), distance) +
                          Eigen::Vector3d(reach * std::sin(1.3 * std::numbers::pi * t + phases_[2]),
                                          0.6 * reach * std::sin(std::numbers::pi * t + phases_[3]), 0.0);
  if (options_.object) scene.objects = {grasp_.object};
  if (options_.forearm != ForearmKind::kNone) scene.forearm = options_.adult_arm ? Forearm::Adult() : Forearm{};

  RenderOptions render;
  render.skin_colour = skin_bgr_;
  if (options_.forearm == ForearmKind::kSleeved) render.sleeve_colour = sleeve_bgr_;
  render.light_direction = light_;
  render.ambient = 0.45;
  render.background = BackgroundAt(t);
  RenderedImages images = renderer_.Render(scene, intrinsics_, render);
  AddNoise(i, &images.rgb);
  frame.rgb = images.rgb;
  frame.labels = images.labels;
  frame.pose = scene.hand;
  frame.wrist_in_camera = scene.wrist_in_camera;
  frame.keypoints = hand_.KeypointsOf(scene.hand);
  frame.object_in_view = cv::countNonZero(images.labels == static_cast<int>(PixelLabel::kObject)) > 0;

  if (options_.hand == Handedness::kLeft) {
    // The left hand is the right one's mirror image across the image's vertical centre line.
    cv::flip(frame.rgb, frame.rgb, 1);
    cv::flip(frame.labels, frame.labels, 1);
    frame.pose = MirrorPose(frame.pose);
    frame.wrist_in_camera.x() = -frame.wrist_in_camera.x();
    for (Eigen::Vector3d& k : frame.keypoints) k.x() = -k.x();
    // Pixel x maps to width - x; the principal point is at the centre.
  }
  for (int k = 0; k < kNumKeypoints; ++k) {
    frame.keypoints_2d[k] = Project(intrinsics_, frame.wrist_in_camera + frame.keypoints[k]);
  }
  return frame;
}

nlohmann::json Sequence::Describe() const {
  // The object's size over the database's (0 without an object; a gesture has none).
  const double object_scale =
      options_.object ? object().size[0] / GraspTaxonomy()[grasp_.id - 1].object.size[0] : 0.0;
  return {{"frames", options_.frames},
          {"fps", options_.fps},
          {"width", options_.width},
          {"height", options_.height},
          {"intrinsics", {{"fx", intrinsics_.fx}, {"fy", intrinsics_.fy}, {"cx", intrinsics_.cx}, {"cy", intrinsics_.cy}}},
          {"fov_deg", options_.fov_deg},
          {"hand", ToString(options_.hand)},
          {"grasp", {{"id", grasp_.id}, {"name", HandShapeKey(grasp_.id)}}},
          {"object", options_.object ? nlohmann::json{{"shape", ToString(object().shape)},
                                                       {"size_m", std::vector<double>(object().size.begin(),
                                                                                      object().size.begin() + ObjectSizeCount(object().shape))}}
                                     : nlohmann::json(nullptr)},
          {"object_scale", object_scale},
          {"beyond_steps", options_.beyond_steps},
          {"forearm", ToString(options_.forearm)},
          {"adult_arm", options_.adult_arm},
          {"skin", skin_},
          {"background", ToString(options_.background)},
          {"face", options_.face},
          {"sweater", options_.sweater},
          {"turn_deg", options_.turn_deg},
          {"roll_deg", options_.roll_deg},
          {"distance_m", options_.distance_m},
          {"hand_length_m", hand_length_m()},
          {"noise", options_.noise},
          {"seed", options_.seed},
          {"light_direction", ToVector(light_)}};
}

nlohmann::json FrameTruthJson(const SequenceFrame& frame) {
  nlohmann::json keypoints_2d = nlohmann::json::array(), hand_3d = nlohmann::json::array(),
                 camera_3d = nlohmann::json::array();
  for (int k = 0; k < kNumKeypoints; ++k) {
    keypoints_2d.push_back({frame.keypoints_2d[k].x(), frame.keypoints_2d[k].y()});
    hand_3d.push_back(ToVector(frame.keypoints[k]));
    camera_3d.push_back(ToVector(frame.wrist_in_camera + frame.keypoints[k]));
  }
  nlohmann::json angles = nlohmann::json::object();
  for (int d = 0; d < kNumDofs; ++d) angles[Dofs()[d].name] = frame.pose.angles[d] / kDegToRad;
  const PoseVector pose = ToPoseVector(frame.pose);
  std::vector<std::vector<double>> rotation(3, std::vector<double>(3));
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) rotation[r][c] = frame.pose.camera_from_hand(r, c);
  }
  return {{"frame", frame.index},
          {"time_s", frame.time_s},
          {"hand", ToString(frame.pose.handedness)},
          {"step", frame.step},
          {"object_in_view", frame.object_in_view},
          {"wrist_rotation", rotation},
          {"joint_angles_deg", angles},
          {"pose_vector", std::vector<double>(pose.data(), pose.data() + pose.size())},
          {"wrist_in_camera_m", ToVector(frame.wrist_in_camera)},
          {"keypoints_2d_px", keypoints_2d},
          {"keypoints_3d_hand_m", hand_3d},
          {"keypoints_3d_camera_m", camera_3d}};
}

}  // namespace nphand
