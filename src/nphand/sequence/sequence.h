// Rendered grasping sequences with ground truth, made to look like a camera's frames: a
// hand (with a bare or sleeved forearm, a skin tone) closing onto an object of a size the
// database does not hold, through poses between and beyond the database's steps, seen by a
// camera that moves, turns and rolls, in front of a procedural background, with sensor
// noise. The tests, the estimator's validation sweep, the demo and the evaluation use it.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "nphand/model/hand_model.h"
#include "nphand/render/camera.h"
#include "nphand/render/renderer.h"
#include "nphand/scene/grasp.h"
#include "nphand/sequence/background.h"

namespace nphand {

struct SkinTone {
  const char* name;
  cv::Vec3f bgr;  // 0..255, as lit head-on
};
// Five tones from light to dark ("light", "medium", "olive", "brown", "dark").
const std::vector<SkinTone>& SkinTones();
// The tone named `name`; throws nphand::Error naming the choices otherwise.
const SkinTone& SkinToneByName(const std::string& name);

enum class ForearmKind : uint8_t { kNone, kBare, kSleeved };
std::string ToString(ForearmKind kind);
ForearmKind ForearmKindFromString(const std::string& text);

struct SequenceOptions {
  int frames = 90;
  double fps = 30.0;
  int width = 640;
  int height = 480;
  double fov_deg = 60.0;          // horizontal, a webcam's
  // The hand shape: a grasp's taxonomy number 1..33 or a gesture's shape number (scene/
  // gesture.h: held without an object, so `object` must be false); 0: a grasp chosen by the seed.
  int grasp = 0;
  // The object's sizes are the grasp's times this factor, and the hand closes onto it
  // afresh, so that neither object nor grasp pose is in the database. 0: 0.8 or 1.25 by
  // the seed. 1 gives the database's object.
  double object_scale = 0.0;
  bool object = true;             // hold the object (else the same motion with an empty hand)
  // The hand opens past the database's pre-shape (towards the flat hand) by this many steps
  // at the start and, without an object, closes past its final step by as many at the end.
  double beyond_steps = 0.5;
  ForearmKind forearm = ForearmKind::kBare;
  // The forearm an adult's (Forearm::Adult: rounder and thicker towards the elbow, and the
  // upper arm beyond it) instead of the cone sized to the mesh's wrist; needs a forearm.
  bool adult_arm = false;
  std::string skin;               // a SkinTones() name; empty: chosen by the seed
  BackgroundKind background = BackgroundKind::kTexture;
  bool face = false;              // a face beside the hand: skin that is not a hand
  bool sweater = false;           // the face's person wears a sweater of a skin-like colour (cream to camel); needs face
  double turn_deg = 60.0;         // how far the viewing direction travels over the sequence
  double roll_deg = 90.0;         // how far the camera rolls over the sequence
  double distance_m = 0.45;       // camera to hand centre, on average
  double noise = 3.0;             // sensor noise, standard deviation in 8-bit levels
  Handedness hand = Handedness::kRight;
  uint64_t seed = 1;
  bool Check(std::string* why) const;
};

struct SequenceFrame {
  int index = 0;
  double time_s = 0.0;
  cv::Mat rgb;                       // CV_8UC3, BGR
  cv::Mat labels;                    // CV_8UC1, PixelLabel values (the forearm has its own)
  HandPose pose;                     // the truth
  double step = 0.0;                 // where between the grasp's steps the hand is (may be < 0 or > 4)
  Eigen::Vector3d wrist_in_camera;   // metres
  Keypoints3d keypoints;             // camera orientation, wrist at the origin, metres
  std::array<Eigen::Vector2d, kNumKeypoints> keypoints_2d;  // pixels (pixel centres at +0.5)
  bool object_in_view = false;       // some object pixel is visible
};

class Sequence {
 public:
  // Makes the grasp (closed onto the scaled object) and the camera path; `hand` must have
  // the handedness of `options` and outlive the sequence. Throws nphand::Error for invalid
  // options.
  Sequence(const HandModel& hand, const SequenceOptions& options);

  int size() const { return options_.frames; }
  const SequenceOptions& options() const { return options_; }
  const Intrinsics& intrinsics() const { return intrinsics_; }
  int grasp() const { return grasp_.id; }
  const ObjectSpec& object() const { return grasp_.object.spec; }
  const std::string& skin() const { return skin_; }
  // The rendered hand's length from the wrist to the middle fingertip along its bones, metres
  // (for `nphand estimate --hand-length`).
  double hand_length_m() const;

  // Frame `i` (0 <= i < size()): the same bytes for the same options.
  SequenceFrame Render(int i);

  // Frame `i`'s view with nothing held up to it: the background (and the face, if any) as
  // the camera sees it then, with the same sensor noise. For "no hand" checks.
  cv::Mat RenderEmpty(int i) const;

  // What the sequence is, for its files: options, intrinsics, grasp, object.
  nlohmann::json Describe() const;

 private:
  JointAngles AnglesAt(double step) const;
  // The background window the camera sees at time t (0..1 over the sequence).
  cv::Mat BackgroundAt(double t) const;
  // Sensor noise of frame i, added in place.
  void AddNoise(int i, cv::Mat* bgr) const;

  const HandModel& hand_;
  SequenceOptions options_;
  Intrinsics intrinsics_;
  Grasp grasp_;
  std::string skin_;
  cv::Vec3f skin_bgr_;
  cv::Vec3f sleeve_bgr_;
  Eigen::Vector3d light_;
  Eigen::Vector3d start_direction_, turn_axis_;
  double start_roll_ = 0.0;
  std::array<double, 4> phases_{};
  cv::Mat background_;  // larger than a frame: the camera's motion pans across it
  Renderer renderer_;
};

// A frame's truth as one JSON object (the fields docs/FORMAT.md gives for truth.jsonl).
nlohmann::json FrameTruthJson(const SequenceFrame& frame);

}  // namespace nphand
