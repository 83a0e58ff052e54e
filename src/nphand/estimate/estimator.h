// The estimator (PAPER.md Sec. 3 and 5): from a camera frame to the hand's full 3D pose.
// A frame is skin-segmented, the hand chosen among the skin regions and cut at the wrist,
// described by the database's descriptor (roll-normalised HOG), and its K nearest database
// entries found; each neighbour becomes a hypothesis (its pose turned by the two rolls),
// weighted by its feature distance (the observation) and by a kernel density over the
// previous frame's weighted hypotheses (the temporal prior). The estimate is the weighted
// mean of the hypotheses near the best (the paper's: the best alone); the weighted set
// carries to the next frame. The result also places the hand: 21 keypoints in the image, in
// 3D about the wrist and in the camera frame.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "nphand/db/database.h"
#include "nphand/estimate/smoother.h"
#include "nphand/index/knn_index.h"
#include "nphand/model/hand_model.h"
#include "nphand/render/camera.h"
#include "nphand/render/renderer.h"
#include "nphand/refine/refiner.h"
#include "nphand/scene/grasp.h"
#include "nphand/segment/forearm.h"
#include "nphand/segment/skin.h"

namespace nphand {

// How a neighbour's feature distance d becomes its weight.
enum class ObservationWeight : uint8_t {
  kFixed,     // the paper: exp(-d^2 / (2 sigma_y^2))
  kAdaptive,  // the released code: exp(-(d - d_min)^2 / (2 var(d))) over the K distances
};
// How the observation weight w and the prior density g combine.
enum class PriorCombination : uint8_t {
  kNone,     // the observation alone (the paper's "NN feature" with weights)
  kProduct,  // the paper: w* = w g
  kSum,      // the released code: w* = (1 - prior_share) w + prior_share g, each normalised
};
std::string ToString(ObservationWeight weight);
std::string ToString(PriorCombination combination);
ObservationWeight ObservationWeightFromString(const std::string& text);
PriorCombination PriorCombinationFromString(const std::string& text);

struct EstimatorOptions {
  int k = 500;                                  // neighbours searched (the paper's K)
  // The defaults are the validation sweep's best (docs/estimator.md, `nphand eval estimator`).
  ObservationWeight observation = ObservationWeight::kFixed;
  double sigma_y = 0.1;                         // kFixed: feature-distance scale (L2 of the descriptor)
  PriorCombination prior = PriorCombination::kProduct;
  double sigma_x = 0.5;                         // the prior's kernel width in pose-vector units
  double prior_share = 0.9;                     // kSum's weight on the prior
  int carried = 5;                              // hypotheses carried to the next frame
  // In the first carry_apart_frames frames of a track the carried hypotheses lie at least
  // sigma_x apart in pose (the best of each mode), so that a second mode survives while the
  // first holds the estimate, where the lookup's first pick may lock a wrong one in
  // (0: never; docs/estimator.md).
  int carry_apart_frames = 0;
  // Where, in a track, the nearest view lies outside the track's mode (farther than twice
  // sigma_x in pose from the best) and nearer than the mode's own nearest by more than
  // prior_reset_margin (feature distance), for prior_reset_frames frames in a row, the track
  // starts afresh on the next frame: a mode the prior holds against the frames' evidence (a
  // hand read end for end) is let go; the smoothing's filters go on from the old track.
  // Only where a prior took part (not with PriorCombination::kNone). 0: never, the default:
  // a small gain on the validation sweep, but real video lost more than it gained and a
  // database of sparser views loses its tracks (docs/estimator.md).
  int prior_reset_frames = 0;
  double prior_reset_margin = 0.1;
  // The track's views: in a track, the entries seen from the `track_views` viewpoints
  // nearest the last frame's best (its own first) join the K neighbours, measured against the
  // frame's descriptor, so that the prior finds the views near its track even where an
  // outline alike from the palm and the back fills the K nearest with the other side's
  // (docs/estimator.md). 0: none.
  int track_views = 4;
  int top_n = 5;                                // hypotheses in each result
  // The estimate: the weighted mean of the hypotheses within this distance of the best in
  // pose (pose-vector units, as sigma_x; their rotations' chordal mean, their joint angles'
  // mean), placed through the best's crop, so that it moves between the database's poses
  // rather than stepping from one to the next (0: the best alone, as the paper).
  double mode_mean = 1.0;
  // Search the half-turned crop too when the silhouette's skewness is below this (its two
  // ends look alike, so the principal axis's direction is a guess). The sweep's choice:
  // 0.05 searches twice in a quarter of the frames (0.15: 58 %), for 0.2 mm more error and
  // 11-15 % more frames a second (docs/estimator.md).
  double roll_ambiguity = 0.05;
  // Where the database's crops were turned by their principal axis (its descriptor's
  // normalize_roll) and the nearest view the index finds for the crop (and for its half
  // turn) lies tilt_above or farther (0: every frame) but within max_distance (a larger
  // tilt_above: never), the crop (of the two turns, the nearer's) is
  // searched again turned by plus and minus each of tilts_deg: a segmented silhouette's
  // principal axis errs (a forearm's stump, an object's hole, stray skin beside it), where
  // the database's renders were turned by their own. Each turned crop's tilt_k nearest views
  // are found with a candidate list of tilt_effort (KnnIndex::Search) and weighed with the
  // rest; whether the region is a hand at all stays the untilted crop's to say
  // (max_distance). The validation sweep's choice (docs/estimator.md): 15 and 30 degrees
  // from 0.6, on 9 % of its RGB frames, 14.5 -> 13.8 mm. None: tilts_deg empty.
  std::vector<double> tilts_deg = {15.0, 30.0};
  double tilt_above = 0.6;
  int tilt_k = 30;
  int tilt_effort = 50;
  // No hand unless the nearest database entry is at most this far in feature space.
  double max_distance = 0.8;
  // No hand when the silhouette's principal axes are farther apart than this ratio: a sliver
  // of skin (a neck's edge beside a face) is no hand. The default database's silhouettes:
  // 99.9 % at most 4.7, 99.99 % at most 5.9, the thinnest 10.0 (`nphand db info`).
  double max_elongation = 6.0;
  // No hand in a skin region whose box spans fewer frame pixels than this on its longer
  // side: the descriptor's 8 x 8 cells would each hold under 3 of its pixels. Such specks
  // are not looked up: a frame holding only them is no_skin ("no skin-coloured region of a
  // hand's size").
  int min_hand_px = 24;
  // A hand does not shrink to a crumb within a few frames: skin regions of less than this
  // share of the pixels of the region where a hand was last found, within the last
  // kAreaMemory frames, are not looked up (a neck's remnant below a face, a fold of skin on
  // a sleeve would pass for a fist seen from afar while the hand's own region is judged no
  // hand).
  double min_area_share = 0.125;
  static constexpr int kAreaMemory = 15;  // half a second at 30 frames/s
  Handedness hand = Handedness::kRight;         // left: mirrored into the right-hand database
  // Either side (`--hand auto`): each region is searched as it is and mirrored, and the side
  // whose nearest entry is nearer gains the difference of the two distances as evidence.
  // A track's evidence decays by `hand_memory` a frame, and its side changes only when the
  // other side leads by more than `hand_switch` (feature distance); a track's first frame
  // takes the nearer side. `hand` is where a track starts when the two tie.
  bool hand_auto = false;
  double hand_memory = 0.8;
  double hand_switch = 0.05;
  // Camera: a focal length in pixels, or (focal_px = 0) a horizontal field of view.
  double focal_px = 0.0;
  double fov_deg = 60.0;
  double hand_length_m = 0.18;                  // wrist to middle fingertip, an adult's
  SkinOptions skin;
  bool cut_forearm = true;
  ForearmCutOptions forearm;
  // The arm's direction: where a forearm was cut off, the hand's own axis (wrist from the
  // palm, in the image) should point along the arm, from the wrist towards the elbow. Each
  // hypothesis's log weight gains arm_agreement * |p| (cos a - 1), p the hypothesis's palm-to-
  // wrist direction in the image (length: how far it lies in the image plane) and a its angle
  // to the arm: a hand turned against its arm (the wrist drawn at the fingertips) weighs
  // less, one pointing at the camera is not judged (0: the arm is not looked at). The
  // validation sweep's choice: 4 (16.50 -> 15.74 mm, jitter 7.00 -> 6.84, frames turned
  // 21 -> 17; 8 turns 10 but shakes more; docs/estimator.md).
  double arm_agreement = 4.0;
  // The hand may hold an object (the paper's object context). False where the user knows it
  // holds nothing (gestures, an empty hand): the entries rendered with an object are not
  // weighed, for their objects hide fingers that an empty hand shows curled (on real-dev's
  // video, finger states 909 -> 927 of 1300; docs/estimator.md).
  bool objects = true;
  int learn_interval = 10;                      // frames between skin-colour updates from confident frames
  // Refinement beyond the database (refine/refiner.h): the estimate (the mode's mean, or the
  // best hypothesis alone) moved until its silhouette agrees with the hand's; keypoints,
  // angles and rotation then come from the refined pose.
  bool refine = false;
  RefineOptions refinement;
  // Where both turns of the crop were searched (roll_ambiguity), the other turn's best
  // hypothesis is refined too, and replaces the lookup's best if its silhouette agrees
  // better and it lies no farther from the last frame's refined rotation.
  bool refine_both_turns = true;
  // The track's estimates smoothed over time (estimate/smoother.h): the joint angles, the
  // rotation, the wrist's place and the image keypoints, each frame's pulled towards the
  // last's by a One Euro filter; the 3D keypoints are the smoothed pose's. `smoothing` is
  // every group's but the rotation's, which has a filter of its own: a track's steps from
  // view to view are mostly the wrist's turns, and a lower cutoff with a trend steadies them
  // with no more lag than the others' (the validation sweep's choice, docs/estimator.md).
  bool smooth = true;
  SmoothOptions smoothing;
  SmoothOptions rotation_smoothing = {.min_cutoff_hz = 2.0, .beta = 0.5, .derivative_cutoff_hz = 0.5, .trend = 0.5};
  bool Check(std::string* why) const;
};

// The refinement's settings (refine/refiner.h's ToJson) when `options` refine, else false:
// how reports say whether and how a run refined.
nlohmann::json RefinementJson(const EstimatorOptions& options);
// The same for the smoothing: its settings, or false.
nlohmann::json SmoothingJson(const EstimatorOptions& options);

// Sets `options`' hand from "right", "left" or "auto" (hand_auto, starting right); throws
// nphand::Error for anything else.
void SetHandChoice(const std::string& text, EstimatorOptions* options);

enum class FrameStatus : uint8_t {
  kDetected,
  kNoSkin,     // no skin-coloured region of a hand's size
  kNotAHand,   // skin, but no region looks like any database view (e.g. only a face)
};
std::string ToString(FrameStatus status);

struct Hypothesis {
  uint32_t entry = 0;             // database entry
  double weight = 0.0;            // normalised over the frame's hypotheses
  double distance = 0.0;          // L2 feature distance
  double turn = 0.0;              // radians: the query's roll minus the entry's (the image-plane turn)
  HandPose pose;                  // the entry's pose turned by `turn` (mirrored for a left hand)
};

struct StageMilliseconds {
  double segment = 0.0, describe = 0.0, search = 0.0, weigh = 0.0, refine = 0.0, place = 0.0, total = 0.0;
};

struct FrameResult {
  int frame = 0;
  double time_s = 0.0;
  FrameStatus status = FrameStatus::kNoSkin;
  std::string reason;                          // why not detected, for people
  Handedness hand = Handedness::kRight;        // the side searched for (chosen, with hand_auto)
  // hand_auto: the track's evidence for `hand` over the other side (feature distance, >= 0).
  std::optional<double> hand_margin;
  bool detected() const { return status == FrameStatus::kDetected; }
  // The estimate (valid when detected).
  HandPose pose;
  Keypoints3d keypoints_hand{};                // metres, camera orientation, wrist at the origin, the user's hand size
  Keypoints3d keypoints_camera{};              // metres, camera frame
  std::array<Eigen::Vector2d, kNumKeypoints> keypoints_2d{};  // pixels (pixel centres at +0.5)
  double depth_m = 0.0;                        // the hand centre's distance along the optical axis
  cv::Rect box;                                // the hand's pixels (after the forearm cut)
  bool forearm_cut = false;
  bool both_turns = false;                     // the half-turned crop was searched too
  bool tilted = false;                         // the crop was searched turned too (EstimatorOptions::tilts_deg)
  double tilt_deg = 0.0;                       // the turn, counter-clockwise in the frame, of the crop the estimate came through (0: untilted)
  bool prior_used = false;                     // the temporal prior took part
  std::vector<Hypothesis> top;                 // the best top_n, best first
  std::vector<std::pair<std::string, double>> grasps;   // posterior over hand shapes (grasps, gestures), descending
  std::vector<std::pair<std::string, double>> objects;  // posterior over object shapes ("none": no object)
  bool searched = false;                       // the region was looked up in the database
  double nearest_distance = 0.0;               // the best neighbour's feature distance (if searched), of the untilted crop
  double effective_samples = 0.0;              // 1 / sum w^2 over the hypotheses
  double confidence = 0.0;                     // the posterior mass near the best hypothesis, 0..1
  // Hypotheses of positive weight averaged into the estimate (EstimatorOptions::mode_mean;
  // 1: the best alone).
  int mean_of = 1;
  // With refine: whether the refinement moved the pose (or kept the other turn's best
  // entry), and the kept refinement's objective (silhouette disagreement, 1 - IoU, plus the
  // pulls towards the start and the last frame's rotation) before and after.
  bool refined = false;
  std::optional<std::pair<double, double>> refine_objective;
  // With refine measuring the proportions (RefineOptions::move_proportions): the hand's
  // length and width as factors of the database hand's. The length is hand_length_m's; the
  // width the database's until the video's measurements settle, then theirs (`held`, no
  // longer measured). The frame's pose was refined, and its keypoints made, for a hand of
  // these proportions.
  struct Proportions {
    double length = 1.0;
    double width = 1.0;
    bool held = false;
  };
  std::optional<Proportions> proportions;
  StageMilliseconds ms;
};

using PoseX = Eigen::Matrix<double, kPoseVectorSize, 1>;  // the paper's pose vector x

struct WeightedPose {
  PoseX x;
  double weight;
  std::optional<uint32_t> entry;  // the database entry it is (none: a pose from elsewhere)
};

// Which hypotheses are carried to the next frame: the first `count` of `order` (indices
// into `poses` by descending weight), or with `apart` > 0 the first `count` that lie at
// least `apart` from every one taken before them.
std::vector<size_t> CarriedOrder(const std::vector<PoseX>& poses, const std::vector<size_t>& order, int count, double apart);

// The temporal step: hypotheses' observation weights (normalised) combined with the kernel
// density over the previous frame's weighted hypotheses `carried`, as `options` says
// (prior, sigma_x, prior_share); normalised. Without a prior, or when the prior gives every
// hypothesis nothing (the hand jumped), the observation weights come back and
// `*prior_used` is false.
std::vector<double> CombineWithPrior(const std::vector<PoseX>& poses, const std::vector<double>& observation,
                                     const std::vector<WeightedPose>& carried, const EstimatorOptions& options,
                                     bool* prior_used);

// How a skin region of `frame` ranks as the hand: its area, times a Gaussian of its
// centroid's distance from the last hand's box's centre (0.2 of the frame's diagonal) and
// one of its area's ratio to the last hand's (two octaves): the larger, nearer and more
// like the last hand's size, the sooner it is looked up. Without a last box (empty) or
// area (0) that factor is left out.
double CandidateScore(const SkinRegion& region, cv::Size frame, cv::Rect last_box, int last_area);

// The length of the database's hand from the wrist to the middle fingertip along its
// bones (metres); throws nphand::Error for a database without a hand, or whose keypoints
// are older ones (the header's keypoints: HandModel::bind_keypoints).
double ModelHandLength(const Database& db);

class Estimator {
 public:
  // `db`, `index` (built for `db`) and `hand` (the model `db` was rendered from) must outlive
  // the estimator. Throws nphand::Error for invalid options, an index of another database,
  // a hand model of another asset, or a database of the other hand.
  Estimator(const Database& db, const KnnIndex& index, const HandModel& hand, const EstimatorOptions& options);

  // The next frame (8-bit BGR) of a video at `time_s`. In a letterboxed or pillarboxed
  // frame the hand is sought in the picture between its black bars, whose edges count as
  // the frame's (`PictureOf`). With `roi` (frame pixels: a box from the caller's own
  // detector or tracker, or a fixed workspace) the hand is sought there only (within the
  // picture): skin regions that do not meet it are no candidates, the others are clipped to
  // it, and its edges count as the frame's (an arm clipped there enters from an edge).
  // Throws nphand::Error for another image or a box that does not meet the frame.
  FrameResult Process(const cv::Mat& bgr, double time_s, const std::optional<cv::Rect>& roi = std::nullopt);
  // The same from a hand mask (CV_8UC1, non-zero = hand) instead of a frame: no
  // segmentation, no region choice, no forearm cut.
  FrameResult ProcessMask(const cv::Mat& mask, double time_s);
  // Forgets the temporal state and the learned skin colours (a new video).
  void Reset();

  const EstimatorOptions& options() const { return options_; }
  const Intrinsics& intrinsics_for(cv::Size frame) const;
  // The database entry rendered as the database saw it (labels, RGB): for overlays.
  RenderedImages RenderEntry(uint32_t entry);

 private:
  // Process and ProcessMask before smoothing.
  FrameResult Detect(const cv::Mat& bgr, double time_s, const std::optional<cv::Rect>& roi);
  FrameResult DetectMask(const cv::Mat& mask, double time_s);
  // With smooth: `r` filtered with the track's last estimates: the joint angles, the
  // rotation, the wrist's place and the image keypoints, the 3D keypoints then made from
  // them (a frame without the hand, or of the other side, starts the filters afresh).
  void Smooth(FrameResult* r);
  void ResetSmoothing();
  // Everything after the hand's mask: describe, search, weigh, refine, place. `hand_mask` is
  // frame-sized, `box` its pixels' bounds; `result` comes with frame, time and segmentation
  // time filled in. A region unlike any view leaves the carried hypotheses as they were
  // (the caller may try another region, and forgets them if none is a hand).
  // `arm`: with a forearm cut off, its direction in the mask (unit, from the wrist towards
  // the elbow).
  FrameResult Estimate(const cv::Mat& hand_mask, cv::Rect box, cv::Size frame, const std::optional<cv::Point2d>& arm,
                       FrameResult result);
  // Estimate's stages, each timed into the result's ms; the lookup carries what they find.
  struct Lookup;
  // The crop (and its half turn) and their descriptors; false (with the reason) for a
  // silhouette too thin to be a hand.
  bool Describe(const cv::Mat& hand_mask, cv::Rect box, cv::Size frame, Lookup* lookup, FrameResult* result);
  // The K neighbours of each descriptor, and in a track the entries of the track's views
  // (measured by the index; none where the backend keeps nothing to measure with).
  void Search(Lookup* lookup, FrameResult* result);
  // Hypotheses, observation weights, the prior, the carried hypotheses, the posteriors and
  // the top-N; false (with the reason) when nothing in the database is near.
  bool Weigh(cv::Rect box, Lookup* lookup, FrameResult* result);
  // With refine: the estimate's pose (the mode's mean, or the best entry's; with
  // refine_both_turns perhaps the other turn's best entry's) refined against its crop: the
  // placement, the turn and which crop it was refined against, or nothing (the estimate as
  // the lookup made it, the best's turn and crop).
  struct EntryPlacement;
  std::optional<EntryPlacement> Refine(const Lookup& lookup, double* turn, int* crop, FrameResult* result);
  // Keypoints in the frame and in 3D, from `entry` (an entry's render, its pose the entry's
  // own, the mode's mean or the refinement's) and the query's crop `crop`, turned by `turn`.
  void Place(const Lookup& lookup, int crop, const EntryPlacement& entry, double turn, cv::Rect box, cv::Size frame,
             FrameResult* result);
  // Estimate for a hand of side `side`: a left hand's mask is mirrored into the right-hand
  // database, and its result mirrored back.
  FrameResult EstimateSide(const cv::Mat& hand_mask, cv::Rect box, Handedness side, const std::optional<cv::Point2d>& arm,
                           FrameResult result);
  // The same for the side the track holds, or with hand_auto for both sides, keeping the
  // side the evidence favours (and its carried hypotheses).
  FrameResult EstimateHand(const cv::Mat& hand_mask, cv::Rect box, const std::optional<cv::Point2d>& arm, FrameResult result);
  const Grasp& GraspOf(int id) const;
  Scene EntryScene(uint32_t entry);

  // What a frame needs of an entry, copied from the database once: frames then never touch
  // the mapped file, whose pages would otherwise pile up in resident memory.
  struct EntryRow {
    EntryMeta meta;
    std::array<float, kPoseVectorSize> pose;
    std::array<float, kNumDofs> angles;
  };
  PoseVector PoseOf(uint32_t entry) const;
  JointAngles AnglesOf(uint32_t entry) const;

  // Where an entry's keypoints lie in its render and its crop: the render costs a quarter of
  // a millisecond, and in a video the best entry is mostly one of the last few frames', so
  // the last kPlacements are kept (a pure function of the entry: kept or made afresh, the
  // figures are the same).
  struct EntryPlacement {
    uint32_t entry = 0;
    uint64_t used = 0;                  // when it was last needed (placements_clock_)
    cv::Matx23d crop_from_image;        // the entry's render to its crop
    Keypoints3d keypoints;              // hand-centred, camera orientation
    Eigen::Vector3d wrist_in_camera;
  };
  static constexpr size_t kPlacements = 32;
  const EntryPlacement& PlacementOf(uint32_t entry);

  const Database& db_;
  std::vector<EntryRow> entries_;  // by entry number
  const KnnIndex& index_;
  const HandModel& hand_;
  EstimatorOptions options_;
  SkinSegmenter segmenter_;
  Renderer renderer_;
  Intrinsics db_intrinsics_;
  double db_distance_ = 0.5;
  std::vector<Eigen::Vector3d> directions_;
  std::vector<std::optional<Grasp>> grasps_;  // by taxonomy number: those the database holds with an object
  double model_hand_length_ = 0.0;
  mutable Intrinsics frame_intrinsics_;
  std::vector<EntryPlacement> placements_;
  uint64_t placements_clock_ = 0;  // counts the placements asked for
  std::optional<Refiner> refiner_;  // with refine
  // A refinement's rotation, turned as reported (before the ray), and its frame.
  struct Refined {
    Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
    int frame = -2;  // none
  };
  std::array<Refined, 2> refined_;         // by side (right, left): the latest
  std::array<Refined, 2> refined_before_;  // by side: the latest of an earlier frame than refined_'s
  // With the proportions measured: the video's frames' widths (against the length) where
  // the silhouette at the width measured agreed within kWidthFit, and the width held once
  // the last kWidthFrames measurements' middle half spans at most kWidthSpread: their whole
  // median, no longer measured (until then the hand is the database's, width 1).
  std::vector<double> widths_;
  std::optional<double> held_width_;
  static constexpr size_t kWidthFrames = 10;
  static constexpr double kWidthSpread = 0.03;
  static constexpr double kWidthFit = 0.15;
  std::vector<WeightedPose> carried_;
  std::array<int, 2> track_start_ = {0, 0};  // by side: the frame the track began (its first frame without the prior)
  std::array<int, 2> elsewhere_ = {0, 0};    // by side: frames in a row the nearest view lay outside the track's mode
  // track_views: by viewpoint, the entries the index holds and the track_views nearest
  // viewpoints (itself first); per entry, the search that last found it.
  std::vector<std::vector<entry_id_t>> view_entries_;
  std::vector<std::vector<int>> near_views_;
  std::vector<uint32_t> found_in_;
  uint32_t searches_ = 0;
  cv::Rect last_box_;        // the box of the hand found last (frame pixels; empty: none yet)
  int last_area_ = 0;        // the pixels of its region (0: none)
  int last_area_frame_ = 0;  // the frame it was found in
  OneEuroFilter smooth_wrist_, smooth_image_, smooth_angles_, smooth_rotation_;
  Handedness smoothed_side_ = Handedness::kRight;
  Handedness side_ = Handedness::kRight;  // the track's side
  double side_evidence_ = 0.0;            // hand_auto: for side_ over the other (decaying sum)
  int side_frame_ = -1;                   // hand_auto: the frame last weighed (-1: none yet in this track)
  int frame_ = 0;
  int since_learn_ = 0;
};

}  // namespace nphand
