// Scores hand-pose predictions on labelled real images and video frames (`nphand eval
// real`): the measures of real-dev's reference scorer (score_realdev.py), computed the same
// way, so that its figures and nphand's agree on the same predictions.
//
// Per labelled hand (one line of labels.jsonl):
//  - label box: the bounding box of its labelled 2D keypoints (or its `bbox_px` when it has
//    none); diag its diagonal; found region: the box grown by 25 % of its width on the left
//    and right and 25 % of its height at the top and bottom;
//  - matching: per image, predicted hands are paired one-to-one with labelled hands; a pair
//    is eligible when the predicted keypoints' centroid lies in the found region; the
//    assignment with the most pairs wins, ties going to the smallest summed cost (the mean
//    normalised 2D error, or for a box only the centroid's distance from the box centre over
//    diag). A labelled hand with a partner is found; a predicted hand without one is extra;
//  - normalised error e_k = |pred_k - label_k| / diag per labelled keypoint; PCK@t the
//    fraction with e_k < t (t = 0.1, 0.2);
//  - handedness: the predicted side against the labelled one, where a side is predicted;
//  - PA-MPJPE (mm): with 3D labels (the camera's, or for the video MediaPipe's world
//    landmarks), after a similarity alignment without reflection;
//  - finger states: index to little, extended iff |MCP->tip| over the finger's bone lengths
//    exceeds 0.75, on the label's and the prediction's 3D; agreement out of 4 per hand;
//  - gesture finger states (nphand's own measure): where a label names a HaGRID gesture whose
//    fingers are plain (RealGestureFingers: "peace" has the index and middle finger straight,
//    the ring and little finger curled), the prediction's 3D finger states against them,
//    agreement out of 4 per hand;
//  - steadiness on video (nphand's own measure): per video and labelled side, over each run
//    of consecutive frames whose hand was found, the mean second difference of the 2D
//    keypoints (|k(t+1) - 2 k(t) + k(t-1)|, over keypoints labelled in all three frames)
//    divided by the labelled box's diagonal at t; beside it the labels' own, over the same
//    frames (for MediaPipe's reference landmarks, MediaPipe's jitter);
//  - palm or back towards the camera (nphand's own measure; the reference has none): from
//    the 2D keypoints and the hand's side, the sense of the turn from the wrist->index MCP
//    ray to the wrist->little MCP ray; a right hand whose palm faces the camera turns
//    counter-clockwise on the screen, a left one clockwise. Judged where the label's wrist
//    and both MCPs are labelled and the label is not edge-on (FacingOf, measures.h); the
//    prediction's side is its own, or the label's when it gives none.
// Aggregates are over hands (each hand counts once), per source, over the ground-truth
// sources (FreiHAND, OneHand10K, Panoptic, InterHand, HaGRID) and over their one-hand and
// two-hand images apart.
#pragma once

#include <array>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "nphand/eval/measures.h"
#include "nphand/model/hand_model.h"

namespace nphand {

struct RealLabel {
  int line = 0;                   // 0-based line of labels.jsonl
  std::string file;               // relative to the labels' folder
  std::optional<int> frame;       // a video's frame
  std::string source;             // freihand, onehand10k, panoptic, interhand, hagrid, tfjs_hands, mediapipe_thumbs_up, asl_video, other
  std::string hand;               // "left" or "right" as it appears in the image; empty: not given
  std::string hand_side_by;       // "source" or "eye"
  std::string gesture;            // its class: HaGRID's ("peace", "two up inv.") or MediaPipe's ("Thumb_Up")
  std::array<std::optional<Eigen::Vector2d>, kNumKeypoints> keypoints_2d;  // pixels; unlabelled joints empty
  std::vector<int> labelled;      // the joints with a 2D position
  std::optional<Keypoints3d> keypoints_3d;  // metres: the camera's, or MediaPipe's world landmarks (video)
  bool world_3d = false;          // keypoints_3d are MediaPipe's world landmarks
  std::array<double, 4> box{};    // x_min, y_min, x_max, y_max
  double diag = 0.0;
  std::array<double, 4> region{};  // the found region
  // Which image (file, frame) the line belongs to.
  std::pair<std::string, int> key() const { return {file, frame.value_or(-1)}; }
};

// The index, middle, ring and little finger's states (extended: true) a gesture class
// shows (HaGRID's, and MediaPipe's "Thumb_Up"), for the classes that fix them; none for the
// others (HaGRID's "grabbing" and "grip", "three3", the two-hand gestures).
std::optional<std::array<bool, 4>> RealGestureFingers(const std::string& gesture);

// The source a label file name belongs to (the reference's source_of).
std::string RealSourceOf(const std::string& file);
// Whether a source's labels are ground truth (not MediaPipe's own outputs).
bool IsGroundTruthSource(const std::string& source);

// Reads labels.jsonl. Throws nphand::Error naming the line of anything malformed: not JSON,
// no `file`, keypoints not 21 [x, y] (or null), 3D not 21 [x, y, z], a side not left or
// right, neither keypoints nor a box.
std::vector<RealLabel> ReadRealLabels(const std::filesystem::path& path);

struct PredictedHand {
  std::array<Eigen::Vector2d, kNumKeypoints> keypoints_2d{};  // pixels, origin at the image's top-left corner
  std::optional<Keypoints3d> keypoints_3d;                     // metres, any hand-centred frame
  std::string hand;                                            // "left", "right" or empty
};

// What a system reported for one labelled image or video frame.
struct RealPrediction {
  std::string file;
  std::optional<int> frame;
  std::vector<PredictedHand> hands;  // empty: no hand found
  std::optional<double> ms;
  // What each estimate that found no hand said. nphand's own runs only: the reference's
  // format has no such field.
  struct Miss {
    std::string hand;    // the side it looked for ("right", "left"), or "" (either: --hand auto)
    std::string status;  // ToString(FrameStatus)
    std::string reason;
  };
  std::vector<Miss> missed;
  std::pair<std::string, int> key() const { return {file, frame.value_or(-1)}; }
};

// One line of the reference's generic predictions JSONL.
nlohmann::json ToJson(const RealPrediction& prediction);
// Reads a generic predictions JSONL (the reference scorer's format), matching each line's
// `file` to a label's as the reference does (the same path, or for a still the same stem).
// Throws nphand::Error naming the line of anything malformed or unmatched, or repeated.
std::vector<RealPrediction> ReadRealPredictions(const std::filesystem::path& path, const std::vector<RealLabel>& labels);

struct RealHandScore {
  const RealLabel* label = nullptr;
  int hands_in_image = 0;             // labelled hands in the same image
  bool run = false;                   // the image has a prediction record
  bool found = false;
  std::optional<double> pck_01, pck_02, mean_norm_err, mean_err_px;  // found hands with keypoints
  std::optional<bool> handedness_ok;  // found hands whose prediction has a side
  std::optional<double> pa_mpjpe_mm;  // found hands with 3D on both sides
  std::optional<int> finger_agree;    // of 4
  std::optional<int> gesture_finger_agree;  // of 4: found hands whose label's gesture fixes its fingers
  std::optional<bool> facing_ok;      // found hands whose label's facing is judged
  std::optional<std::array<Eigen::Vector2d, kNumKeypoints>> keypoints_2d;  // the partner's
  // A hand not found: why. The status of the estimate that looked for its side and found
  // nothing (RealPrediction::missed: "no_skin", "not_a_hand"), else "elsewhere" (hands were
  // estimated, all off it), "not_run", or "no_hand" (a prediction without hands that says
  // nothing more); `miss_reason` the estimate's own words, if any.
  std::string miss, miss_reason;
};

struct RealAggregate {
  int hands = 0, images = 0, found = 0, not_run = 0, extra = 0, kp_hands = 0, kp_found = 0;
  std::optional<double> pck_01_found, pck_02_found, pck_01_all, pck_02_all;
  std::optional<double> mean_norm_err_found, median_norm_err_found, mean_err_px_found;
  int handedness_n = 0, handedness_correct = 0, handedness_source_n = 0, handedness_source_correct = 0;
  int pa_mpjpe_n = 0, hands_with_3d_label = 0;
  std::optional<double> pa_mpjpe_mm;
  int finger_agree = 0, finger_total = 0;
  int gesture_finger_agree = 0, gesture_finger_total = 0;
  int facing_n = 0, facing_correct = 0;
  std::map<std::string, int> misses;  // hands not found, by RealHandScore::miss
  std::optional<double> found_rate() const { return hands > 0 ? std::optional<double>(double(found) / hands) : std::nullopt; }
};

// A video's steadiness (one labelled side): jitter of the found hand's 2D keypoints and of
// the labels' own over the same frames, in label-box diagonals per frame squared.
struct RealSteadiness {
  std::string file, hand;
  int frames = 0;                    // labelled frames of this side
  int second_differences = 0;        // centred on frames whose neighbours were found too
  std::optional<double> jitter, label_jitter;
};

struct RealScore {
  std::vector<RealHandScore> hands;                  // in label order within each image
  std::vector<RealSteadiness> videos;                // by file and side
  std::vector<std::pair<std::string, int>> extras;   // (file, frame) of each extra predicted hand
  std::map<std::string, RealAggregate> per_source;
  RealAggregate gt_all, gt_one_hand, gt_two_hand;
  std::optional<double> stills_median_ms, video_median_ms;
};

// Scores `predictions` against `labels`. Throws nphand::Error for a prediction of an image
// with no label. An image without a prediction record is "not run": its hands are not found.
RealScore ScoreReal(const std::vector<RealLabel>& labels, const std::vector<RealPrediction>& predictions);

// The reference's figures, under its names: {"per_source": {...}, "overall": {"gt_all",
// "gt_one_hand_images", "gt_two_hand_images"}, "timing", "per_hand"}.
nlohmann::json ToJson(const RealScore& score);
std::string FormatTable(const RealScore& score);

}  // namespace nphand
