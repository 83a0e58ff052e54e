#include "nphand/estimate/estimator.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>

#include <opencv2/imgproc.hpp>

#include "nphand/features/crop.h"
#include "nphand/features/descriptor.h"
#include "nphand/scene/gesture.h"
#include "nphand/scene/viewpoint.h"
#include "nphand/segment/picture.h"
#include "nphand/segment/regions.h"
#include "nphand/util/check.h"
#include "nphand/util/parallel.h"
#include "nphand/util/stats.h"

namespace nphand {
namespace {

using Clock = std::chrono::steady_clock;

// The nearest neighbour's squared distance (infinite for none).
float Nearest(const Neighbours& n) { return n.distances.empty() ? std::numeric_limits<float>::infinity() : n.distances.front(); }

double Ms(Clock::time_point from, Clock::time_point to) {
  return std::chrono::duration<double, std::milli>(to - from).count();
}

// A region of at least this share of the seed's pixels is no piece an object split off the
// seed's hand but a hand of its own beside it (two hands side by side): a candidate of its
// own, not gathered. Chosen by the validation sweep (docs/estimator.md): 0.5 took pieces an
// object parts from the hand for hands (16.4 -> 17.6 mm).
constexpr double kPieceShare = 0.9;

// Pieces gathered with a region that together hold under this share of its pixels may be
// stray skin-coloured things beside the hand, which spread the region's box until it looks
// like no hand: then the region alone is judged too. Chosen by the validation sweep
// (docs/estimator.md): 0.05 16.14 -> 15.74 mm against every share (1.0), 0.2 15.82.
constexpr double kStrayShare = 0.05;

// A hand region together with the pieces an object splits off it (skin regions, under
// kPieceShare of its pixels, whose boxes meet the region's box grown by 30 % of its longer
// side): their pixels within `*box`, which gets the pixels' bounds. `pieces`: whether
// to gather them (false: the region alone); `gathered` (if not null) gets the pieces' pixels.
// Only pixels within `view` count (the frame's picture between black bars, or the caller's
// region of interest within it).
cv::Mat GatherHand(const SkinSegmentation& s, const SkinRegion& seed, const cv::Rect& view, bool pieces, cv::Rect* box,
                   int* gathered) {
  const cv::Rect reach = HandReach(seed.box & view);
  int pixels = 0;
  std::vector<int> labels = {seed.label};
  cv::Rect bounds = seed.box & view;
  for (const SkinRegion& r : s.regions) {
    if (!pieces || r.label == seed.label || (r.box & view & reach).area() == 0 || r.area >= kPieceShare * seed.area) continue;
    labels.push_back(r.label);
    bounds |= r.box & view;
    pixels += r.area;
  }
  if (gathered != nullptr) *gathered = pixels;
  const cv::Mat mask = s.Mask(labels, bounds);
  const cv::Rect tight = cv::boundingRect(mask);
  *box = tight + bounds.tl();
  return mask(tight);
}

// Which sides of `box` lie on the edges of `view` (the frame's picture, or the caller's
// region of interest within it): bit 0 left, 1 top, 2 right, 3 bottom (see CutForearm).
int Border(const cv::Rect& box, const cv::Rect& view) {
  return (box.x == view.x ? 1 : 0) | (box.y == view.y ? 2 : 0) | (box.x + box.width == view.x + view.width ? 4 : 0) |
         (box.y + box.height == view.y + view.height ? 8 : 0);
}

Eigen::Vector2d Apply(const cv::Matx23d& a, const Eigen::Vector2d& p) {
  return Eigen::Vector2d(a(0, 0) * p.x() + a(0, 1) * p.y() + a(0, 2), a(1, 0) * p.x() + a(1, 1) * p.y() + a(1, 2));
}

cv::Matx23d Invert(const cv::Matx23d& a) {
  cv::Matx23d inverse;
  cv::invertAffineTransform(a, inverse);
  return inverse;
}

double Scale(const cv::Matx23d& a) { return std::sqrt(std::abs(a(0, 0) * a(1, 1) - a(0, 1) * a(1, 0))); }

void MirrorResult(int width, FrameResult* r) {
  r->pose = MirrorPose(r->pose);
  r->tilt_deg = -r->tilt_deg;
  for (Hypothesis& h : r->top) h.pose = MirrorPose(h.pose);
  for (int k = 0; k < kNumKeypoints; ++k) {
    r->keypoints_2d[k].x() = width - r->keypoints_2d[k].x();
    r->keypoints_hand[k].x() = -r->keypoints_hand[k].x();
    r->keypoints_camera[k].x() = -r->keypoints_camera[k].x();
  }
}

// A region looked up more than once in a frame (both sides, or cut and whole): `kept`, the
// result given, also counts the time of `other`'s lookup.
void AddLookupTime(const FrameResult& other, FrameResult* kept) {
  kept->ms.describe += other.ms.describe;
  kept->ms.search += other.ms.search;
  kept->ms.weigh += other.ms.weigh;
  kept->ms.refine += other.ms.refine;
}

}  // namespace

std::string ToString(ObservationWeight weight) { return weight == ObservationWeight::kFixed ? "fixed" : "adaptive"; }

std::string ToString(PriorCombination combination) {
  switch (combination) {
    case PriorCombination::kNone: return "none";
    case PriorCombination::kProduct: return "product";
    case PriorCombination::kSum: return "sum";
  }
  return "?";
}

ObservationWeight ObservationWeightFromString(const std::string& text) {
  if (text == "fixed") return ObservationWeight::kFixed;
  if (text == "adaptive") return ObservationWeight::kAdaptive;
  NPHAND_THROW("unknown observation weight '", text, "' (choose fixed or adaptive)");
}

PriorCombination PriorCombinationFromString(const std::string& text) {
  if (text == "none") return PriorCombination::kNone;
  if (text == "product") return PriorCombination::kProduct;
  if (text == "sum") return PriorCombination::kSum;
  NPHAND_THROW("unknown prior combination '", text, "' (choose none, product or sum)");
}

std::vector<double> CombineWithPrior(const std::vector<PoseX>& poses, const std::vector<double>& observation,
                                     const std::vector<WeightedPose>& carried, const EstimatorOptions& options,
                                     bool* prior_used) {
  NPHAND_CHECK(poses.size() == observation.size(), "poses and weights differ in number");
  *prior_used = false;
  std::vector<double> w = observation;
  if (options.prior == PriorCombination::kNone || carried.empty()) return w;
  // A Gaussian kernel density over the carried hypotheses.
  std::vector<double> g(poses.size(), 0.0);
  const double inv = 1.0 / (2.0 * options.sigma_x * options.sigma_x);
  double g_sum = 0.0;
  for (size_t i = 0; i < poses.size(); ++i) {
    for (const WeightedPose& c : carried) g[i] += c.weight * std::exp(-(poses[i] - c.x).squaredNorm() * inv);
    g_sum += g[i];
  }
  // A prior that gives every hypothesis nothing (the hand jumped) is no prior.
  if (!(g_sum > 1e-300)) return w;
  double sum = 0.0;
  for (size_t i = 0; i < poses.size(); ++i) {
    w[i] = options.prior == PriorCombination::kProduct ? observation[i] * g[i]
                                                       : (1.0 - options.prior_share) * observation[i] +
                                                             options.prior_share * g[i] / g_sum;
    sum += w[i];
  }
  if (!(sum > 1e-300)) return observation;
  for (double& v : w) v /= sum;
  *prior_used = true;
  return w;
}

std::vector<size_t> CarriedOrder(const std::vector<PoseX>& poses, const std::vector<size_t>& order, int count, double apart) {
  std::vector<size_t> carried;
  for (size_t i : order) {
    if (static_cast<int>(carried.size()) >= count) break;
    if (apart > 0.0 && std::any_of(carried.begin(), carried.end(), [&](size_t c) { return (poses[c] - poses[i]).norm() < apart; })) {
      continue;
    }
    carried.push_back(i);
  }
  return carried;
}

std::string ToString(FrameStatus status) {
  switch (status) {
    case FrameStatus::kDetected: return "detected";
    case FrameStatus::kNoSkin: return "no_skin";
    case FrameStatus::kNotAHand: return "not_a_hand";
  }
  return "?";
}

bool EstimatorOptions::Check(std::string* why) const {
  if (k < 1 || k > 100000) {
    *why = "k must be within 1..100000";
  } else if (!(sigma_y > 0.0 && sigma_y < 10.0) || !(sigma_x > 0.0 && sigma_x < 100.0)) {
    *why = "sigma_y must be within (0, 10) and sigma_x within (0, 100)";
  } else if (!(prior_share >= 0.0 && prior_share <= 1.0)) {
    *why = "the prior's share must be within [0, 1]";
  } else if (track_views < 0 || track_views > 64) {
    *why = "the track's views must be within 0..64";
  } else if (carry_apart_frames < 0) {
    *why = "the frames carrying hypotheses apart must be 0 or more";
  } else if (prior_reset_frames < 0 || !(prior_reset_margin >= 0.0 && prior_reset_margin < 10.0)) {
    *why = "the prior's reset must be after 0 or more frames, its margin within [0, 10)";
  } else if (carried < 1 || carried > k || top_n < 1 || top_n > k) {
    *why = "carried hypotheses and top-N must be within 1..k";
  } else if (!(mode_mean >= 0.0 && mode_mean < 10.0)) {
    *why = "the mode's mean must reach within [0, 10) of the best hypothesis";
  } else if (!(roll_ambiguity >= 0.0 && roll_ambiguity < 10.0) || !(max_distance > 0.0 && max_distance < 10.0)) {
    *why = "roll ambiguity must be within [0, 10) and the largest distance within (0, 10)";
  } else if (std::any_of(tilts_deg.begin(), tilts_deg.end(), [](double t) { return !(t > 0.0 && t <= 90.0); })) {
    *why = "each tilt of the crop must be within (0, 90] degrees";
  } else if (!(tilt_above >= 0.0 && tilt_above < 10.0) || tilt_k < 1 || tilt_effort < 1) {
    *why = "the distance above which the crop is tilted must be within [0, 10), and the tilts' k and effort at least 1";
  } else if (!(focal_px >= 0.0 && focal_px < 1e6) || !(fov_deg > 1.0 && fov_deg < 179.0)) {
    *why = "the focal length must be >= 0 pixels (0: from the field of view) and the field of view within (1, 179) degrees";
  } else if (!(hand_length_m >= 0.05 && hand_length_m <= 0.4)) {
    *why = "the hand length must be within [0.05, 0.4] metres";
  } else if (!(max_elongation >= 1.0)) {
    *why = "the largest elongation must be at least 1 (a disk)";
  } else if (min_hand_px < 1) {
    *why = "the smallest hand must span at least 1 pixel";
  } else if (!(min_area_share >= 0.0 && min_area_share < 1.0)) {
    *why = "the least share of the hand found last must be within [0, 1)";
  } else if (!(hand_memory >= 0.0 && hand_memory < 1.0) || !(hand_switch >= 0.0 && hand_switch < 10.0)) {
    *why = "the side's memory must be within [0, 1) and its switching margin within [0, 10)";
  } else if (!(arm_agreement >= 0.0 && arm_agreement <= 100.0)) {
    *why = "the arm's agreement must be within [0, 100]";
  } else if (learn_interval < 1) {
    *why = "the learning interval must be at least 1 frame";
  } else if (!skin.Check(why) || !forearm.Check(why) || !refinement.Check(why) || !smoothing.Check(why)) {
    return false;
  } else if (!rotation_smoothing.Check(why)) {
    *why = "the rotation's filter: " + *why;
    return false;
  } else {
    return true;
  }
  return false;
}

nlohmann::json RefinementJson(const EstimatorOptions& options) {
  if (!options.refine) return false;
  nlohmann::json j = ToJson(options.refinement);
  j["both_turns"] = options.refine_both_turns;
  return j;
}

nlohmann::json SmoothingJson(const EstimatorOptions& options) {
  if (!options.smooth) return false;
  auto settings = [](const SmoothOptions& s) {
    return nlohmann::json{
        {"min_cutoff_hz", s.min_cutoff_hz}, {"beta", s.beta}, {"derivative_cutoff_hz", s.derivative_cutoff_hz}, {"trend", s.trend}};
  };
  nlohmann::json j = settings(options.smoothing);
  j["rotation"] = settings(options.rotation_smoothing);
  return j;
}

void SetHandChoice(const std::string& text, EstimatorOptions* options) {
  options->hand_auto = text == "auto";
  if (options->hand_auto) {
    options->hand = Handedness::kRight;
    return;
  }
  NPHAND_THROW_CHECK(text == "right" || text == "left", "unknown hand '", text, "' (choose right, left or auto)");
  options->hand = HandednessFromString(text);
}

double ModelHandLength(const Database& db) {
  NPHAND_THROW_CHECK(db.header().value("keypoints", "") == kKeypointRule,
                     "the database's keypoints are the hand asset's joints where labelled hands put them elsewhere "
                     "(its tip joints short of the fingers' ends, or its thumb pivot past the thumb's base: a file "
                     "made before 2026-12-07): make it again with `nphand db build`");
  for (size_t i = 0; i < db.size(); ++i) {
    if (db.Meta(i).has_hand) return HandLength(db.Keypoints(i));
  }
  NPHAND_THROW("the database holds no entry with a hand");
}

double CandidateScore(const SkinRegion& region, cv::Size frame, cv::Rect last_box, int last_area) {
  double score = region.area;
  if (last_box.area() > 0) {
    const double spread = 0.2 * std::hypot(frame.width, frame.height);
    const cv::Point2d d = region.centroid - cv::Point2d(last_box.x + 0.5 * last_box.width, last_box.y + 0.5 * last_box.height);
    score *= std::exp(-(d.x * d.x + d.y * d.y) / (2.0 * spread * spread));
  }
  if (last_area > 0) {
    const double two_octaves = std::log2(static_cast<double>(region.area) / last_area) / 2.0;
    score *= std::exp(-0.5 * two_octaves * two_octaves);
  }
  return score;
}

namespace {

// `options` once checked: before the members made from them, so that a bad setting is
// named as the estimator's.
const EstimatorOptions& Checked(const EstimatorOptions& options) {
  std::string why;
  NPHAND_THROW_CHECK(options.Check(&why), "estimator: ", why);
  return options;
}

}  // namespace

Estimator::Estimator(const Database& db, const KnnIndex& index, const HandModel& hand, const EstimatorOptions& options)
    : db_(db),
      index_(index),
      hand_(hand),
      options_(Checked(options)),
      segmenter_(options.skin),
      renderer_(hand),
      smooth_wrist_(options.smoothing),
      smooth_image_(options.smoothing),
      smooth_angles_(options.smoothing),
      smooth_rotation_(options.rotation_smoothing),
      side_(options.hand) {
  NPHAND_THROW_CHECK(db.header().value("hand", "") == "right" && hand.handedness() == Handedness::kRight,
                     "estimator: needs a right-hand database and the right hand model (left hands are mirrored)");
  NPHAND_THROW_CHECK(db.header().value("hand_asset_sha256", "") == PinnedAssetSha256(Handedness::kRight),
                     "estimator: the database was rendered from another hand asset");
  CheckSameDescriptor(db.descriptor(), index.config(), "estimator: the index");
  NPHAND_THROW_CHECK(index.size() <= db.size(), "estimator: the index holds ", index.size(),
                     " entries, more than the database's ", db.size(), " (an index of another database?)");
  const nlohmann::json& render = db.header()["render"];
  db_intrinsics_ = Intrinsics::FromFieldOfView(render["image_size"].get<int>(), render["image_size"].get<int>(),
                                               render["fov_deg"].get<double>() * std::numbers::pi / 180.0);
  db_distance_ = render["distance_m"].get<double>();
  if (options.refine) refiner_.emplace(hand, db_intrinsics_, db_distance_, db.descriptor().Crop(), options.refinement);
  directions_ = ViewSphereDirections(db.header()["viewpoints"].get<int>());
  grasps_.resize(kNumGrasps + 1);  // the grasps' objects; a gesture has none
  model_hand_length_ = ModelHandLength(db);
  entries_.resize(db.size());
  std::array<bool, kNumHandShapes + 1> with_object{};
  ScanRecords(db, [&](size_t i) {
    EntryRow& row = entries_[i];
    row.meta = db.Meta(i);
    const PoseVector pose = db.Pose(i);
    const JointAngles angles = db.Angles(i);
    for (int j = 0; j < kPoseVectorSize; ++j) row.pose[j] = static_cast<float>(pose[j]);
    for (int j = 0; j < kNumDofs; ++j) row.angles[j] = static_cast<float>(angles[j]);
    with_object[row.meta.grasp] = with_object[row.meta.grasp] || row.meta.with_object;
  });
  if (options.track_views > 0) {
    view_entries_.resize(directions_.size());
    for (entry_id_t id : index.ids()) view_entries_[entries_[id].meta.viewpoint].push_back(id);
    const size_t nearest = std::min<size_t>(options.track_views, directions_.size());
    near_views_.resize(directions_.size());
    for (size_t v = 0; v < directions_.size(); ++v) {
      std::vector<int> by_angle(directions_.size());
      for (size_t w = 0; w < by_angle.size(); ++w) by_angle[w] = static_cast<int>(w);
      // Nearest first; ties by number, so that the choice is the same on every machine.
      std::partial_sort(by_angle.begin(), by_angle.begin() + nearest, by_angle.end(), [&](int a, int b) {
        const double da = directions_[v].dot(directions_[a]), db = directions_[v].dot(directions_[b]);
        return da != db ? da > db : a < b;
      });
      near_views_[v].assign(by_angle.begin(), by_angle.begin() + nearest);
    }
    found_in_.assign(entries_.size(), 0);
  }
  // The grasps whose objects the database shows, closed onto them now, on every core: a
  // grasp takes about 100 ms, far too long to make on the frame that first needs it.
  std::vector<int> held;
  for (int id = 1; id <= kNumGrasps; ++id) {
    if (with_object[id]) held.push_back(id);
  }
  ParallelFor(held.size(), 0, [&](size_t i, int) { grasps_[held[i]] = MakeGrasp(hand_, GraspTaxonomy()[held[i] - 1]); });
}

PoseVector Estimator::PoseOf(uint32_t entry) const {
  PoseVector pose;
  for (int j = 0; j < kPoseVectorSize; ++j) pose[j] = entries_[entry].pose[j];
  return pose;
}

JointAngles Estimator::AnglesOf(uint32_t entry) const {
  JointAngles angles;
  for (int j = 0; j < kNumDofs; ++j) angles[j] = entries_[entry].angles[j];
  return angles;
}

void Estimator::Reset() {
  carried_.clear();
  last_area_ = 0;
  last_area_frame_ = 0;
  last_box_ = cv::Rect();
  segmenter_.Reset();
  frame_ = 0;
  since_learn_ = 0;
  side_ = options_.hand;
  side_evidence_ = 0.0;
  side_frame_ = -1;
  refined_ = {};
  refined_before_ = {};
  track_start_ = {0, 0};
  elsewhere_ = {0, 0};
  widths_.clear();
  held_width_.reset();
  ResetSmoothing();
  smoothed_side_ = options_.hand;
}

const Intrinsics& Estimator::intrinsics_for(cv::Size frame) const {
  if (frame_intrinsics_.width != frame.width || frame_intrinsics_.height != frame.height) {
    frame_intrinsics_ = Intrinsics::FromFieldOfView(frame.width, frame.height, options_.fov_deg * std::numbers::pi / 180.0);
    if (options_.focal_px > 0.0) frame_intrinsics_.fx = frame_intrinsics_.fy = options_.focal_px;
  }
  return frame_intrinsics_;
}

const Grasp& Estimator::GraspOf(int id) const {
  NPHAND_CHECK(id >= 1 && id <= kNumGrasps && grasps_[id].has_value(), "grasp ", id, " was not made");
  return *grasps_[id];
}

Scene Estimator::EntryScene(uint32_t entry) {
  const EntryMeta meta = entries_[entry].meta;
  Scene scene;
  scene.hand.angles = AnglesOf(entry);
  scene.hand.camera_from_hand = CameraFromHand(ViewpointFromDirection(directions_[meta.viewpoint]));
  scene.wrist_in_camera = CenteredWristPosition(scene.hand.camera_from_hand, hand_.bind_centre(), db_distance_);
  if (meta.with_object) scene.objects = {GraspOf(meta.grasp).object};
  return scene;
}

const Estimator::EntryPlacement& Estimator::PlacementOf(uint32_t entry) {
  ++placements_clock_;
  for (EntryPlacement& p : placements_) {
    if (p.entry == entry) {
      p.used = placements_clock_;
      return p;
    }
  }
  const Scene scene = EntryScene(entry);
  cv::Mat labels;
  renderer_.RenderLabels(scene, db_intrinsics_, &labels);
  const std::optional<HandCrop> crop = CropHand(labels == static_cast<int>(PixelLabel::kHand), db_.descriptor().Crop());
  NPHAND_CHECK(crop.has_value(), "entry ", entry, " has no hand to crop");
  EntryPlacement made{entry, placements_clock_, crop->crop_from_image, hand_.KeypointsOf(scene.hand), scene.wrist_in_camera};
  if (placements_.size() < kPlacements) {
    placements_.push_back(std::move(made));
    return placements_.back();
  }
  // The least recently used makes way.
  EntryPlacement& oldest = *std::min_element(placements_.begin(), placements_.end(),
                                              [](const EntryPlacement& a, const EntryPlacement& b) { return a.used < b.used; });
  oldest = std::move(made);
  return oldest;
}

RenderedImages Estimator::RenderEntry(uint32_t entry) {
  NPHAND_THROW_CHECK(entry < db_.size(), "estimator: no database entry ", entry);
  RenderOptions options;
  options.depth = false;
  return renderer_.Render(EntryScene(entry), db_intrinsics_, options);
}

FrameResult Estimator::Process(const cv::Mat& bgr, double time_s, const std::optional<cv::Rect>& roi) {
  FrameResult result = Detect(bgr, time_s, roi);
  Smooth(&result);
  return result;
}

FrameResult Estimator::ProcessMask(const cv::Mat& mask, double time_s) {
  FrameResult result = DetectMask(mask, time_s);
  Smooth(&result);
  return result;
}

void Estimator::ResetSmoothing() {
  for (OneEuroFilter* f : {&smooth_wrist_, &smooth_image_, &smooth_angles_, &smooth_rotation_}) f->Reset();
}

void Estimator::Smooth(FrameResult* r) {
  if (!options_.smooth) return;
  if (!r->detected() || r->hand != smoothed_side_) ResetSmoothing();
  if (!r->detected()) return;
  smoothed_side_ = r->hand;
  const double length = options_.hand_length_m;
  Eigen::VectorXd wrist(4), image(2 * kNumKeypoints), angles(kNumDofs);
  wrist << r->keypoints_camera[0], r->depth_m;
  for (int k = 0; k < kNumKeypoints; ++k) image.segment<2>(2 * k) = r->keypoints_2d[k];
  for (int j = 0; j < kNumDofs; ++j) angles[j] = r->pose.angles[j];
  wrist = smooth_wrist_.Filter(wrist, length, r->time_s);
  image = smooth_image_.Filter(image, std::max(1.0, std::hypot(r->box.width, r->box.height)), r->time_s);
  angles = smooth_angles_.Filter(angles, 1.0, r->time_s);
  // The rotation as a quaternion on the last filtered one's side of the sphere.
  Eigen::Quaterniond q(r->pose.camera_from_hand);
  if (const Eigen::VectorXd* last = smooth_rotation_.last(); last != nullptr && q.coeffs().dot(*last) < 0.0) {
    q.coeffs() = -q.coeffs();
  }
  r->pose.camera_from_hand =
      Eigen::Quaterniond(Eigen::Vector4d(smooth_rotation_.Filter(q.coeffs(), 1.0, r->time_s))).normalized().toRotationMatrix();
  for (int j = 0; j < kNumDofs; ++j) r->pose.angles[j] = angles[j];
  // The keypoints are the smoothed pose's, so that they stay a hand's and agree with the
  // angles and the rotation: a left hand's are the mirrored right hand's the database holds.
  const bool left = r->hand == Handedness::kLeft;
  const HandModel& model = r->proportions.has_value() ? refiner_->Model(r->proportions->width / r->proportions->length) : hand_;
  Keypoints3d keypoints = model.KeypointsOf(left ? MirrorPose(r->pose) : r->pose);
  const double size = length / model_hand_length_;
  for (int k = 0; k < kNumKeypoints; ++k) {
    if (left) keypoints[k].x() = -keypoints[k].x();
    r->keypoints_hand[k] = size * keypoints[k];
    r->keypoints_camera[k] = wrist.head<3>() + r->keypoints_hand[k];
    r->keypoints_2d[k] = image.segment<2>(2 * k);
  }
  r->depth_m = wrist[3];
}

FrameResult Estimator::Detect(const cv::Mat& bgr, double time_s, const std::optional<cv::Rect>& roi) {
  const Clock::time_point start = Clock::now();
  const cv::Rect frame(0, 0, bgr.cols, bgr.rows);
  NPHAND_THROW_CHECK(!bgr.empty() && bgr.type() == CV_8UC3, "estimator: a frame must be a non-empty 8-bit BGR image");
  cv::Rect view = roi.has_value() ? *roi & frame : frame;
  NPHAND_THROW_CHECK(!roi.has_value() || view.area() > 0, "estimator: the region of interest (", roi->x, ", ", roi->y, ", ",
                     roi->width, " x ", roi->height, ") does not meet the ", bgr.cols, " x ", bgr.rows, " frame");
  // Within the picture: an arm leaving it ends at a black bar, which is the frame's edge. A
  // region of interest wholly within a bar stays as it is (it has no skin).
  if (const cv::Rect within = view & PictureOf(bgr); within.area() > 0) view = within;
  FrameResult result;
  result.frame = frame_++;
  result.time_s = time_s;
  const bool recent = result.frame - last_area_frame_ <= EstimatorOptions::kAreaMemory;
  const SkinSegmentation skin = segmenter_.Segment(bgr, recent ? last_box_ : cv::Rect());
  std::vector<const SkinRegion*> candidates;
  int widest = 0;
  // Regions of a hand's size set aside as under min_area_share of the hand found last.
  bool crumbs = false;
  const int last_area = recent ? last_area_ : 0;
  const int least_area = static_cast<int>(std::ceil(options_.min_area_share * last_area));
  for (const SkinRegion& r : skin.regions) {
    const cv::Rect within = r.box & view;
    if (within.area() == 0 || (within != r.box && cv::countNonZero(skin.Mask({r.label}, within)) == 0)) continue;
    const int across = std::max(within.width, within.height);
    widest = std::max(widest, across);
    if (across < options_.min_hand_px) continue;
    if (r.area < least_area) {
      crumbs = true;
      continue;
    }
    candidates.push_back(&r);
  }
  // Larger, nearer the last hand and nearer its size first (each scored once).
  std::vector<std::pair<double, const SkinRegion*>> ranked;
  for (const SkinRegion* r : candidates) ranked.emplace_back(CandidateScore(*r, bgr.size(), last_box_, last_area), r);
  std::stable_sort(ranked.begin(), ranked.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
  for (size_t i = 0; i < ranked.size(); ++i) candidates[i] = ranked[i].second;
  result.ms.segment = Ms(start, Clock::now());
  if (candidates.empty()) {
    result.status = FrameStatus::kNoSkin;
    result.reason = crumbs       ? "no skin-coloured region near the size of the hand found last (" + std::to_string(last_area) +
                                     " pixels; regions under " + std::to_string(least_area) + " are not looked up)"
                    : widest > 0 ? "no skin-coloured region of a hand's size (the largest spans " + std::to_string(widest) +
                                     " pixels; a hand at least " + std::to_string(options_.min_hand_px) + ")"
                    : roi.has_value() && !skin.regions.empty() ? "no skin-coloured region within the region of interest"
                    : skin.colourless      ? "the frame has no colour (greyscale): skin cannot be told by its colour"
                    : skin.body_pixels > 0 ? "only faces and the bodies below them are skin-coloured"
                    : skin.face_pixels > 0 ? "only faces are skin-coloured"
                                           : "no skin-coloured region";
    carried_.clear();
    result.ms.total = Ms(start, Clock::now());
    return result;
  }
  // A candidate gathered with its pieces, or alone (`pieces`): its pixels within its box;
  // `gathered` (if not null) gets the pieces' pixels.
  struct Region {
    cv::Mat mask;
    cv::Rect box;
  };
  auto gather = [&](const SkinRegion& candidate, bool pieces, int* gathered) {
    const Clock::time_point part = Clock::now();
    Region region;
    region.mask = GatherHand(skin, candidate, view, pieces, &region.box, gathered);
    result.ms.segment += Ms(part, Clock::now());
    return region;
  };
  // A region cut at the wrist (with `cut`) and judged; `hand` gets the mask judged.
  auto judge = [&](const Region& region, bool cut, cv::Mat* hand) {
    const Clock::time_point part = Clock::now();
    cv::Rect box = region.box;
    *hand = cv::Mat::zeros(bgr.size(), CV_8UC1);
    std::optional<cv::Point2d> arm;
    bool cut_off = false;
    if (cut) {
      const ForearmCut forearm = CutForearm(region.mask, Border(box, view), options_.forearm);
      forearm.hand.copyTo((*hand)(box));
      if ((cut_off = forearm.cut)) {
        box = cv::boundingRect(forearm.hand) + box.tl();
        arm = forearm.arm_direction;
      }
    } else {
      region.mask.copyTo((*hand)(box));
    }
    result.ms.segment += Ms(part, Clock::now());
    FrameResult attempt = EstimateHand(*hand, box, arm, result);
    attempt.forearm_cut = cut_off;
    return attempt;
  };
  // The best region that looks like a hand; a second try if the first does not.
  for (size_t c = 0; c < std::min<size_t>(2, candidates.size()); ++c) {
    cv::Mat hand;
    int pieces = 0;
    const Region gathered = gather(*candidates[c], true, &pieces);
    FrameResult attempt = judge(gathered, options_.cut_forearm, &hand);
    const bool cut = attempt.forearm_cut, searched = attempt.searched;
    auto retry = [&](const Region& region, bool cut_again) {
      FrameResult next = judge(region, cut_again, &hand);
      AddLookupTime(attempt, &next);
      attempt = std::move(next);
    };
    // Then, while none is a hand: the region without the pieces gathered where they are
    // specks (skin-coloured things beside the hand), and the whole region uncut (the cut may
    // have gone through the hand).
    const bool specks = pieces > 0 && pieces < kStrayShare * candidates[c]->area;
    if (!attempt.detected() && searched && specks) retry(gather(*candidates[c], false, nullptr), options_.cut_forearm);
    if (!attempt.detected() && searched && cut) retry(gathered, false);
    if (attempt.detected() || c + 1 == std::min<size_t>(2, candidates.size())) {
      // The hand is lost: the next frame starts from its observation alone.
      if (!attempt.detected()) carried_.clear();
      if (attempt.detected()) {
        last_area_ = candidates[c]->area;
        last_area_frame_ = result.frame;
        last_box_ = attempt.box;
        if (++since_learn_ >= options_.learn_interval && attempt.confidence >= 0.5) {
          segmenter_.Learn(bgr, hand);
          since_learn_ = 0;
        }
      }
      attempt.ms.total = Ms(start, Clock::now());
      return attempt;
    }
  }
  NPHAND_CHECK(false, "unreachable");
  return result;
}

FrameResult Estimator::DetectMask(const cv::Mat& mask, double time_s) {
  NPHAND_THROW_CHECK(!mask.empty() && mask.type() == CV_8UC1, "estimator: a hand mask must be a non-empty 8-bit single-channel image");
  const Clock::time_point start = Clock::now();
  FrameResult result;
  result.frame = frame_++;
  result.time_s = time_s;
  const cv::Rect box = cv::boundingRect(mask);
  if (box.area() == 0) {
    result.status = FrameStatus::kNoSkin;
    result.reason = "the mask is empty";
    carried_.clear();
    return result;
  }
  FrameResult out = EstimateHand(mask != 0, box, std::nullopt, result);
  if (!out.detected()) carried_.clear();
  out.ms.total = Ms(start, Clock::now());
  return out;
}

FrameResult Estimator::EstimateSide(const cv::Mat& hand_mask, cv::Rect box, Handedness side, const std::optional<cv::Point2d>& arm,
                                    FrameResult result) {
  result.hand = side;
  if (side == Handedness::kRight) return Estimate(hand_mask, box, hand_mask.size(), arm, std::move(result));
  cv::Mat mirrored;
  cv::flip(hand_mask, mirrored, 1);
  const cv::Rect mirrored_box(hand_mask.cols - box.x - box.width, box.y, box.width, box.height);
  std::optional<cv::Point2d> mirrored_arm = arm;
  if (mirrored_arm.has_value()) mirrored_arm->x = -mirrored_arm->x;
  FrameResult out = Estimate(mirrored, mirrored_box, hand_mask.size(), mirrored_arm, std::move(result));
  if (out.detected()) MirrorResult(hand_mask.cols, &out);
  out.box = box;
  return out;
}

FrameResult Estimator::EstimateHand(const cv::Mat& hand_mask, cv::Rect box, const std::optional<cv::Point2d>& arm,
                                    FrameResult result) {
  if (!options_.hand_auto) return EstimateSide(hand_mask, box, options_.hand, arm, std::move(result));
  const Handedness other = side_ == Handedness::kRight ? Handedness::kLeft : Handedness::kRight;
  FrameResult held = EstimateSide(hand_mask, box, side_, arm, result);
  // The other side starts without the carried hypotheses: they are poses of this side's.
  std::vector<WeightedPose> held_carried = std::move(carried_);
  carried_.clear();
  FrameResult turned = EstimateSide(hand_mask, box, other, arm, std::move(result));
  // Both searched (a region too thin for a hand is searched for neither): the difference
  // of their nearest distances is this frame's evidence.
  // Once a frame: a region judged again whole is the same frame's evidence.
  if (held.searched && turned.searched && held.frame != side_frame_) {
    const bool first = side_frame_ < 0;
    side_frame_ = held.frame;
    side_evidence_ = options_.hand_memory * side_evidence_ + (turned.nearest_distance - held.nearest_distance);
    if (side_evidence_ < (first ? 0.0 : -options_.hand_switch)) {
      side_ = other;
      side_evidence_ = -side_evidence_;
      turned.hand_margin = side_evidence_;
      AddLookupTime(held, &turned);
      return turned;
    }
  }
  carried_ = std::move(held_carried);
  held.hand_margin = side_evidence_;
  AddLookupTime(turned, &held);
  return held;
}

namespace {

// A neighbour as a hypothesis: its entry, which crop found it, its feature distance, the
// image-plane turn from the entry's view to the crop's, its pose vector so turned, and its
// weight.
struct Candidate {
  uint32_t entry;
  EntryMeta meta;
  int turn_of;
  double distance;
  double turn;
  PoseX x;
  double w = 0.0;
};

}  // namespace

// A frame's region as it passes Estimate's stages.
struct Estimator::Lookup {
  std::optional<cv::Point2d> arm;     // the forearm's direction, if one was cut off
  cv::Rect roi;                       // the hand's box, padded, within the frame
  std::vector<HandCrop> crops;        // the crop, its half turn when its ends look alike, the nearer one's tilts
  size_t untilted = 1;                // crops before the tilts
  size_t tilted_from = 0;             // the crop the tilts turn
  // The untilted crop that crop i is, or was tilted from: 0 the crop, 1 its half turn.
  size_t HalfOf(size_t i) const { return i < untilted ? i : tilted_from; }
  std::vector<Descriptor> descriptors;
  std::vector<Neighbours> found;      // per crop
  std::vector<Candidate> hyp;
  std::vector<size_t> order;          // hyp by weight, best first
  const Candidate& best() const { return hyp[order[0]]; }
  // With mode_mean: the best's scene in its database view, the hand posed as the mode's mean.
  std::optional<Scene> mean;
};

bool Estimator::Describe(const cv::Mat& hand_mask, cv::Rect box, cv::Size frame, Lookup* lookup, FrameResult* result) {
  // Describe the hand's pixels within a padded box (turning a whole frame would cost more).
  const Clock::time_point t = Clock::now();
  lookup->roi = cv::Rect(box.x - 2, box.y - 2, box.width + 4, box.height + 4) & cv::Rect(0, 0, frame.width, frame.height);
  const DescriptorConfig& config = db_.descriptor();
  const std::optional<HandCrop> crop = CropHand(hand_mask(lookup->roi), config.Crop());
  NPHAND_CHECK(crop.has_value(), "a non-empty box gave no crop");
  const double elongation = Elongation(crop->image);
  if (elongation > options_.max_elongation) {
    result->status = FrameStatus::kNotAHand;
    result->reason = "too thin for a hand (principal axes " + std::to_string(elongation) + " : 1, more than " +
                     std::to_string(options_.max_elongation) + ")";
    result->box = box;
    result->ms.describe = Ms(t, Clock::now());
    return false;
  }
  lookup->crops = {*crop};
  if (config.normalize_roll && crop->roll_skewness < options_.roll_ambiguity) lookup->crops.push_back(HalfTurn(*crop));
  for (const HandCrop& c : lookup->crops) lookup->descriptors.push_back(DescribeCrop(c, config));
  result->both_turns = lookup->crops.size() == 2;
  result->ms.describe = Ms(t, Clock::now());
  return true;
}

void Estimator::Search(Lookup* lookup, FrameResult* result) {
  const Clock::time_point t = Clock::now();
  const double described = result->ms.describe;
  for (const Descriptor& d : lookup->descriptors) lookup->found.push_back(index_.Search(d, options_.k));
  // A poor match (by the index's neighbours, before the track's views join them): the
  // nearer turn's crop tilted a little each way too, their describing timed apart. Beyond
  // max_distance the region is no hand, tilted or not.
  float nearest = std::numeric_limits<float>::infinity();
  for (const Neighbours& n : lookup->found) nearest = std::min(nearest, Nearest(n));
  const size_t searched = lookup->untilted = lookup->crops.size();
  const double seen = std::sqrt(nearest);
  if (!options_.tilts_deg.empty() && db_.descriptor().normalize_roll && seen >= options_.tilt_above && seen <= options_.max_distance) {
    result->tilted = true;
    // Of the two turns, the one whose nearest view is nearer (the other's tilts won no frame
    // of the validation sweep).
    const size_t c = lookup->tilted_from = searched == 2 && Nearest(lookup->found[1]) < Nearest(lookup->found[0]) ? 1 : 0;
    for (double tilt : options_.tilts_deg) {
      for (double sign : {-1.0, 1.0}) {
        const Clock::time_point d = Clock::now();
        lookup->crops.push_back(TiltCrop(lookup->crops[c], sign * tilt * std::numbers::pi / 180.0));
        lookup->descriptors.push_back(DescribeCrop(lookup->crops.back(), db_.descriptor()));
        result->ms.describe += Ms(d, Clock::now());
        lookup->found.push_back(index_.Search(lookup->descriptors.back(), options_.tilt_k, options_.tilt_effort));
      }
    }
  }
  if (options_.track_views > 0 && !carried_.empty() && carried_[0].entry.has_value()) {
    const std::vector<int>& views = near_views_[entries_[*carried_[0].entry].meta.viewpoint];
    std::vector<entry_id_t> more;
    std::vector<float> distances;
    for (size_t c = 0; c < searched; ++c) {
      Neighbours& found = lookup->found[c];
      if (++searches_ == 0) {  // the counter wrapped: forget every mark
        std::fill(found_in_.begin(), found_in_.end(), 0);
        searches_ = 1;
      }
      for (entry_id_t id : found.ids) found_in_[id] = searches_;
      more.clear();
      for (int view : views) {
        for (entry_id_t id : view_entries_[view]) {
          if (found_in_[id] != searches_) more.push_back(id);
        }
      }
      if (!index_.Distances(lookup->descriptors[c], more, &distances)) break;
      found.ids.insert(found.ids.end(), more.begin(), more.end());
      found.distances.insert(found.distances.end(), distances.begin(), distances.end());
    }
  }
  result->ms.search = Ms(t, Clock::now()) - (result->ms.describe - described);
}

bool Estimator::Weigh(cv::Rect box, Lookup* lookup, FrameResult* result) {
  const Clock::time_point t = Clock::now();
  const DescriptorConfig& config = db_.descriptor();
  const std::vector<Neighbours>& found = lookup->found;
  // The neighbours' rows lie anywhere in a table of tens of megabytes: ask for them all
  // before reading any, so that their cache misses overlap.
  size_t total = 0;
  for (const Neighbours& n : found) {
    total += n.ids.size();
    for (uint32_t id : n.ids) {
      const char* row = reinterpret_cast<const char*>(&entries_[id]);
      for (size_t line = 0; line < sizeof(EntryRow); line += 64) __builtin_prefetch(row + line);
    }
  }
  std::vector<Candidate>& hyp = lookup->hyp;
  hyp.reserve(total);
  for (size_t c = 0; c < found.size(); ++c) {
    for (size_t i = 0; i < found[c].ids.size(); ++i) {
      if (!options_.objects && entries_[found[c].ids[i]].meta.with_object) continue;
      Candidate h;
      h.entry = found[c].ids[i];
      h.turn_of = static_cast<int>(c);
      h.distance = std::sqrt(std::max(0.0f, found[c].distances[i]));
      h.meta = entries_[h.entry].meta;
      h.turn = config.normalize_roll ? std::remainder(lookup->crops[c].roll - h.meta.roll, 2.0 * std::numbers::pi) : 0.0;
      const PoseVector pose = PoseOf(h.entry);
      Eigen::Matrix3d entry_rotation;
      for (int r = 0; r < 3; ++r) {
        for (int col = 0; col < 3; ++col) entry_rotation(r, col) = pose[3 * r + col];
      }
      const Eigen::Matrix3d rotation = AxisAngle(Eigen::Vector3d::UnitZ(), h.turn) * entry_rotation;
      for (int r = 0; r < 3; ++r) {
        for (int col = 0; col < 3; ++col) h.x[3 * r + col] = rotation(r, col);
      }
      h.x.tail<kNumDofs>() = pose.tail<kNumDofs>();
      hyp.push_back(std::move(h));
    }
  }
  if (hyp.empty()) {
    NPHAND_CHECK(!options_.objects, "the index returned no neighbours");
    result->status = FrameStatus::kNotAHand;
    result->reason = "every view in the database near this region holds an object, and the hand holds none (--no-object)";
    result->box = box;
    result->ms.weigh = Ms(t, Clock::now());
    return false;
  }
  // Whether the region is a hand at all is judged by its own crop's matches, and so is the
  // nearest distance reported (--hand auto compares the sides by it): a tilt reads a hand's
  // silhouette better, it does not make a region a hand, nor a side nearer.
  double nearest = hyp[0].distance, untilted = std::numeric_limits<double>::infinity();
  for (const Candidate& h : hyp) {
    nearest = std::min(nearest, h.distance);
    if (static_cast<size_t>(h.turn_of) < lookup->untilted) untilted = std::min(untilted, h.distance);
  }
  result->searched = true;
  result->nearest_distance = untilted;
  if (untilted > options_.max_distance) {
    result->status = FrameStatus::kNotAHand;
    result->reason = "nothing in the database looks like this region (nearest feature distance " +
                     std::to_string(untilted) + " > " + std::to_string(options_.max_distance) + ")";
    result->box = box;
    result->ms.weigh = Ms(t, Clock::now());
    return false;
  }
  // Observation weights, as logarithms until normalised.
  std::vector<double> log_w(hyp.size());
  if (options_.observation == ObservationWeight::kFixed) {
    for (size_t i = 0; i < hyp.size(); ++i) log_w[i] = -hyp[i].distance * hyp[i].distance / (2.0 * options_.sigma_y * options_.sigma_y);
  } else {
    double mean = 0.0, var = 0.0;
    for (const Candidate& h : hyp) mean += h.distance;
    mean /= hyp.size();
    for (const Candidate& h : hyp) var += (h.distance - mean) * (h.distance - mean);
    var = std::max(var / hyp.size(), 1e-12);
    for (size_t i = 0; i < hyp.size(); ++i) {
      const double d = hyp[i].distance - nearest;
      log_w[i] = -d * d / (2.0 * var);
    }
  }
  if (lookup->arm.has_value() && options_.arm_agreement > 0.0) {
    // The hand frame's x runs from the wrist to the middle finger's knuckle: the palm-to-wrist
    // direction in the camera is the rotation's first column, negated (x right, y down).
    const cv::Point2d arm = *lookup->arm;
    for (size_t i = 0; i < hyp.size(); ++i) {
      const double px = -hyp[i].x[0], py = -hyp[i].x[3];
      log_w[i] += options_.arm_agreement * (arm.x * px + arm.y * py - std::sqrt(px * px + py * py));
    }
  }
  const double top_log = *std::max_element(log_w.begin(), log_w.end());
  std::vector<double> w(hyp.size());
  double w_sum = 0.0;
  for (size_t i = 0; i < hyp.size(); ++i) w_sum += (w[i] = std::exp(log_w[i] - top_log));
  for (double& v : w) v /= w_sum;

  std::vector<PoseX> poses(hyp.size());
  for (size_t i = 0; i < hyp.size(); ++i) poses[i] = hyp[i].x;
  w = CombineWithPrior(poses, w, carried_, options_, &result->prior_used);
  for (size_t i = 0; i < hyp.size(); ++i) hyp[i].w = w[i];

  std::vector<size_t>& order = lookup->order;
  order.resize(hyp.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return hyp[a].w > hyp[b].w; });
  const Candidate& best = hyp[order[0]];

  // Carry the best to the next frame (in a track's first frames, the best of each mode).
  const size_t side = result->hand == Handedness::kRight ? 0 : 1;
  if (!result->prior_used) track_start_[side] = result->frame;
  const bool apart = result->frame - track_start_[side] < options_.carry_apart_frames;
  carried_.clear();
  double carried_sum = 0.0;
  for (size_t i : CarriedOrder(poses, order, options_.carried, apart ? options_.sigma_x : 0.0)) {
    carried_.push_back({hyp[i].x, hyp[i].w, hyp[i].entry});
    carried_sum += hyp[i].w;
  }
  for (WeightedPose& c : carried_) c.weight = carried_sum > 0.0 ? c.weight / carried_sum : 1.0 / carried_.size();

  // Posteriors, confidence.
  // Summed by hand shape (grasp or gesture) and by object shape (the last slot: no object);
  // named once.
  std::array<double, kNumHandShapes + 1> grasp_mass{};
  std::array<double, static_cast<int>(ObjectShape::kStick) + 2> object_mass{};
  constexpr size_t kNoObject = static_cast<int>(ObjectShape::kStick) + 1;
  // The mode's mean (mode_mean) sums the hypotheses of weight near the best, each by its
  // weight, in the same pass: their distance from the best is the confidence's too, and the
  // prior's reset's (the nearest view within the track's mode and outside it).
  double squares = 0.0, mode = 0.0;
  double in_mode = std::numeric_limits<double>::infinity(), outside = in_mode;
  Eigen::Matrix3d mean_rotation = Eigen::Matrix3d::Zero();
  JointAngles mean_angles{};
  double mean_weight = 0.0;
  int mean_of = 0;
  for (const Candidate& h : hyp) {
    grasp_mass[h.meta.grasp] += h.w;
    object_mass[h.meta.with_object ? static_cast<size_t>(GraspTaxonomy()[h.meta.grasp - 1].object.shape) : kNoObject] += h.w;
    squares += h.w * h.w;
    const double from_best = (h.x - best.x).norm();
    if (from_best < options_.sigma_x) mode += h.w;
    double& nearest_of = from_best <= 2.0 * options_.sigma_x ? in_mode : outside;
    nearest_of = std::min(nearest_of, h.distance);
    if (h.w <= 0.0 || from_best >= options_.mode_mean) continue;
    for (int r = 0; r < 3; ++r) {
      for (int col = 0; col < 3; ++col) mean_rotation(r, col) += h.w * h.x[3 * r + col];
    }
    const JointAngles angles = AnglesOf(h.entry);
    for (int j = 0; j < kNumDofs; ++j) mean_angles[j] += h.w * angles[j];
    mean_weight += h.w;
    ++mean_of;
  }
  for (int g = 1; g <= kNumHandShapes; ++g) {
    if (grasp_mass[g] > 0.0) result->grasps.emplace_back(HandShapeKey(g), grasp_mass[g]);
  }
  for (size_t o = 0; o < object_mass.size(); ++o) {
    if (object_mass[o] <= 0.0) continue;
    result->objects.emplace_back(o == kNoObject ? std::string("none") : ToString(static_cast<ObjectShape>(o)), object_mass[o]);
  }
  auto by_weight = [](const auto& a, const auto& b) { return a.second != b.second ? a.second > b.second : a.first < b.first; };
  std::sort(result->grasps.begin(), result->grasps.end(), by_weight);
  std::sort(result->objects.begin(), result->objects.end(), by_weight);
  result->effective_samples = squares > 0.0 ? 1.0 / squares : 0.0;
  result->confidence = std::min(1.0, mode);
  if (options_.prior_reset_frames > 0) {
    elsewhere_[side] = result->prior_used && in_mode - outside > options_.prior_reset_margin ? elsewhere_[side] + 1 : 0;
    if (elsewhere_[side] >= options_.prior_reset_frames) {
      carried_.clear();
      elsewhere_[side] = 0;
    }
  }

  for (size_t r = 0; r < order.size() && static_cast<int>(r) < options_.top_n; ++r) {
    const Candidate& h = hyp[order[r]];
    Hypothesis out;
    out.entry = h.entry;
    out.weight = h.w;
    out.distance = h.distance;
    out.turn = h.turn;
    out.pose.angles = AnglesOf(h.entry);
    out.pose.camera_from_hand = AxisAngle(Eigen::Vector3d::UnitZ(), h.turn) *
                                CameraFromHand(ViewpointFromDirection(directions_[h.meta.viewpoint]));
    result->top.push_back(out);
  }
  result->pose = result->top[0].pose;
  if (mean_of > 1) {
    // The mean's rotation is in the frame's image plane (before the ray); the best's turn
    // undone puts it in the best's database view, where its wrist is placed as the
    // database places it.
    for (double& a : mean_angles) a /= mean_weight;
    result->pose.angles = mean_angles;
    result->pose.camera_from_hand = NearestRotation(mean_rotation);
    result->mean_of = mean_of;
    Scene& scene = lookup->mean.emplace(EntryScene(best.entry));
    scene.hand.angles = mean_angles;
    scene.hand.camera_from_hand = AxisAngle(Eigen::Vector3d::UnitZ(), -best.turn) * result->pose.camera_from_hand;
    scene.wrist_in_camera = CenteredWristPosition(scene.hand.camera_from_hand, hand_.bind_centre(), db_distance_);
  }
  result->ms.weigh = Ms(t, Clock::now());
  return true;
}

std::optional<Estimator::EntryPlacement> Estimator::Refine(const Lookup& lookup, double* turn, int* crop, FrameResult* result) {
  const Candidate& best = lookup.best();
  *turn = best.turn;
  *crop = best.turn_of;
  if (!refiner_.has_value()) return std::nullopt;
  // Refinement: the best entry's pose (the mode's mean, where there is one) moved until its
  // silhouette agrees with the query's; it then stands for the entry in what follows.
  const Clock::time_point t = Clock::now();
  // While the track holds (the prior took part), the side's refined rotation of the frame
  // before.
  const size_t side = result->hand == Handedness::kRight ? 0 : 1;
  if (refined_[side].frame != result->frame) refined_before_[side] = refined_[side];
  const Eigen::Matrix3d& before = refined_before_[side].rotation;
  const bool last = refined_before_[side].frame == result->frame - 1;
  const bool track = result->prior_used && last;
  struct Tried {
    const Candidate* start;
    Refinement r;
    double from_last;  // degrees from the last frame's refined rotation (0 without one)
  };
  // The width is measured on the side the track holds (with hand_auto both are refined)
  // until it is held; `width_was_held`: this frame's hand is of the held width.
  const bool width_was_held = held_width_.has_value();
  const bool move_width =
      options_.refinement.move_proportions && !width_was_held && (!options_.hand_auto || result->hand == side_);
  auto attempt = [&](const Candidate& c) {
    const cv::Matx23d start_map = PlacementOf(c.entry).crop_from_image;
    // The best starts from the mode's mean, where there is one.
    const Scene start = &c == &best && lookup.mean.has_value() ? *lookup.mean : EntryScene(c.entry);
    // The track's last rotation in this entry's image plane.
    const Eigen::Matrix3d previous = AxisAngle(Eigen::Vector3d::UnitZ(), -c.turn) * before;
    Tried tried{&c,
                refiner_->Refine(lookup.crops[c.turn_of], start, start_map, track ? &previous : nullptr,
                                 held_width_.value_or(1.0), move_width),
                0.0};
    if (last) tried.from_last = RotationAngleDeg(AxisAngle(Eigen::Vector3d::UnitZ(), c.turn) * RotationOf(tried.r), before);
    return tried;
  };
  Tried chosen = attempt(best);
  if (options_.refine_both_turns && result->both_turns) {
    // The silhouette's ends look alike: the best of the other turn is refined too, and
    // replaces the lookup's best only if the silhouette agrees with it better and it is no
    // farther from the last frame's rotation.
    for (size_t i : lookup.order) {
      if (lookup.HalfOf(lookup.hyp[i].turn_of) == lookup.HalfOf(best.turn_of)) continue;
      Tried other = attempt(lookup.hyp[i]);
      if (other.r.disagreement_after < chosen.r.disagreement_after && other.from_last <= chosen.from_last) chosen = std::move(other);
      break;
    }
  }
  const Candidate& c = *chosen.start;
  const Refinement& r = chosen.r;
  result->refined = r.moved || &c != &best;
  if (&c != &best) result->mean_of = 1;  // the other turn's best stands alone
  result->refine_objective = std::make_pair(r.objective_before, r.objective_after);
  if (options_.refinement.move_proportions) {
    // A frame's measurement counts if the silhouette of its start's pose at that width agrees
    // with the hand's: a wrong pose favours a wrong width.
    if (move_width && r.width_disagreement <= kWidthFit) {
      widths_.push_back(r.width_measured);
      if (widths_.size() >= kWidthFrames) {
        std::vector<double> last(widths_.end() - kWidthFrames, widths_.end());
        std::sort(last.begin(), last.end());
        if (last[3 * kWidthFrames / 4] - last[kWidthFrames / 4] <= kWidthSpread) held_width_ = WidthOnGrid(*TrueMedian(widths_));
      }
    }
    const double length = options_.hand_length_m / model_hand_length_;
    result->proportions = FrameResult::Proportions{length, length * r.width, width_was_held};
  }
  std::optional<EntryPlacement> refined;
  if (result->refined || r.width != 1.0) {
    refined = EntryPlacement{c.entry, 0, r.crop_from_image, refiner_->Model(r.width).KeypointsOf(r.scene.hand),
                             r.scene.wrist_in_camera};
    // The silhouette turned counter-clockwise in the crop stands for a hand turned the
    // other way in the frame.
    *turn = c.turn - r.turn;
    *crop = c.turn_of;
    result->pose.angles = r.scene.hand.angles;
    result->pose.camera_from_hand = AxisAngle(Eigen::Vector3d::UnitZ(), c.turn) * RotationOf(r);
  }
  refined_[side] = {result->pose.camera_from_hand, result->frame};
  result->ms.refine = Ms(t, Clock::now());
  return refined;
}

void Estimator::Place(const Lookup& lookup, int crop, const EntryPlacement& entry, double turn, cv::Rect box, cv::Size frame,
                      FrameResult* result) {
  // The entry rendered as the database saw it tells where its keypoints lie in its crop;
  // the query's crop maps them into the frame, and the two crops' scales give the distance.
  const Clock::time_point t = Clock::now();
  const HandCrop& query_crop = lookup.crops[crop];
  const cv::Rect roi = lookup.roi;
  const cv::Matx23d frame_from_crop = Invert(query_crop.crop_from_image);
  const double size = options_.hand_length_m / model_hand_length_;
  const Intrinsics& camera = intrinsics_for(frame);
  // A pixel of the database's render (pixel centres at +0.5) to the frame's.
  auto to_frame = [&](const Eigen::Vector2d& pixel_in_entry) {
    const Eigen::Vector2d in_crop = Apply(entry.crop_from_image, pixel_in_entry.array() - 0.5);
    const Eigen::Vector2d in_roi = Apply(frame_from_crop, in_crop);
    return Eigen::Vector2d(in_roi.x() + roi.x + 0.5, in_roi.y() + roi.y + 0.5);
  };
  // The hand centre (on the database camera's axis) in the frame, and the ray to it: a hand
  // off the axis is seen from a direction turned by that ray, so the entry's rotation is
  // turned by it too.
  const Eigen::Vector2d centre_px = to_frame(Project(db_intrinsics_, Eigen::Vector3d(0.0, 0.0, db_distance_)));
  const Eigen::Vector3d ray =
      Eigen::Vector3d((centre_px.x() - camera.cx) / camera.fx, (centre_px.y() - camera.cy) / camera.fy, 1.0).normalized();
  const Eigen::Matrix3d towards_ray = Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), ray).toRotationMatrix();
  // The hand centre's distance: the database's, scaled by the focal lengths, the crops'
  // scales and the hand's size.
  const double range = db_distance_ * (camera.fx / db_intrinsics_.fx) * size *
                       (Scale(query_crop.crop_from_image) / Scale(entry.crop_from_image));
  const Eigen::Matrix3d rotation = towards_ray * AxisAngle(Eigen::Vector3d::UnitZ(), turn);
  result->pose.camera_from_hand = towards_ray * result->pose.camera_from_hand;
  for (Hypothesis& h : result->top) h.pose.camera_from_hand = towards_ray * h.pose.camera_from_hand;
  const Eigen::Vector3d wrist = range * ray - size * (result->pose.camera_from_hand * hand_.bind_centre());
  result->depth_m = range * ray.z();
  for (int k = 0; k < kNumKeypoints; ++k) {
    result->keypoints_2d[k] = to_frame(Project(db_intrinsics_, entry.wrist_in_camera + entry.keypoints[k]));
    result->keypoints_hand[k] = size * (rotation * entry.keypoints[k]);
    result->keypoints_camera[k] = wrist + result->keypoints_hand[k];
  }
  result->box = box;
  result->status = FrameStatus::kDetected;
  result->ms.place = Ms(t, Clock::now());
}

FrameResult Estimator::Estimate(const cv::Mat& hand_mask, cv::Rect box, cv::Size frame, const std::optional<cv::Point2d>& arm,
                                FrameResult result) {
  Lookup lookup;
  lookup.arm = arm;
  if (!Describe(hand_mask, box, frame, &lookup, &result)) return result;
  Search(&lookup, &result);
  if (!Weigh(box, &lookup, &result)) return result;
  // The image-plane turn from the database's camera to the frame's; the refinement (if on)
  // may turn it further, and its pose then stands for the best entry's.
  double turn = 0.0;
  int crop = 0;
  std::optional<EntryPlacement> placed = Refine(lookup, &turn, &crop, &result);
  result.tilt_deg = std::remainder(lookup.crops[crop].roll - lookup.crops[lookup.HalfOf(crop)].roll, 2.0 * std::numbers::pi) /
                    (std::numbers::pi / 180.0);
  if (!placed.has_value() && lookup.mean.has_value()) {
    // The mode's mean, placed through the best's crop.
    const uint32_t best = lookup.best().entry;
    placed = EntryPlacement{best, 0, PlacementOf(best).crop_from_image, hand_.KeypointsOf(lookup.mean->hand),
                            lookup.mean->wrist_in_camera};
  }
  Place(lookup, crop, placed.has_value() ? *placed : PlacementOf(lookup.best().entry), turn, box, frame, &result);
  return result;
}

}  // namespace nphand
