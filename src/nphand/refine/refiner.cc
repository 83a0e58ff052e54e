#include "nphand/refine/refiner.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <numbers>
#include <optional>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "nphand/scene/viewpoint.h"
#include "nphand/util/check.h"

namespace nphand {
namespace {

constexpr double kDegToRad = std::numbers::pi / 180.0;
// The parameters: the wrist's turns about the camera's x and y axes (across the view; the
// turn within it is the place's), the joints, then the silhouette's place in the crop:
// shift (x, y, crop pixels), log scale, turn (radians, counter-clockwise as displayed); then
// the hand's width factor.
constexpr int kWristAxes = 2;
constexpr int kPlace = kWristAxes + kNumDofs;
constexpr int kWidth = kPlace + 4;
constexpr int kParameters = kWidth + 1;
constexpr int kRepeats = 4;  // steps taken in a row along a direction that keeps improving
constexpr int kPlaceSweeps = 3;  // passes over the place's directions settling a width's trial (steps from half the first)
using Parameters = std::array<double, kParameters>;

// A direction of the search: parameters moved together, each by its weight times the step.
enum class Kind : uint8_t { kWrist, kJoint, kShift, kScale, kTurn, kWidth };
struct Direction {
  std::vector<std::pair<int, double>> moves;
  Kind kind = Kind::kJoint;
};

// The silhouette's place; the wrist's two axes; the thumb's five joints one by one; for each
// finger its curl (all three flexions), its MCP flexion, its PIP and DIP together, and its
// spread. (The width is measured apart: Refiner::Refine.)
std::vector<Direction> Directions(const RefineOptions& options) {
  std::vector<Direction> out;
  if (options.move_place) {
    out.push_back({{{kPlace, 1.0}}, Kind::kShift});
    out.push_back({{{kPlace + 1, 1.0}}, Kind::kShift});
    out.push_back({{{kPlace + 2, 1.0}}, Kind::kScale});
    out.push_back({{{kPlace + 3, 1.0}}, Kind::kTurn});
  }
  if (options.move_wrist) {
    for (int axis = 0; axis < kWristAxes; ++axis) out.push_back({{{axis, 1.0}}, Kind::kWrist});
  }
  if (options.move_fingers) {
    for (int dof = 0; dof < 5; ++dof) out.push_back({{{kWristAxes + dof, 1.0}}, Kind::kJoint});
    for (int finger = 0; finger < 4; ++finger) {
      const int mcp = kWristAxes + 5 + 4 * finger, abd = mcp + 1, pip = mcp + 2, dip = mcp + 3;
      out.push_back({{{mcp, 1.0}, {pip, 1.0}, {dip, 1.0}}, Kind::kJoint});
      out.push_back({{{mcp, 1.0}}, Kind::kJoint});
      out.push_back({{{pip, 1.0}, {dip, 1.0}}, Kind::kJoint});
      out.push_back({{{abd, 0.5}}, Kind::kJoint});
    }
  }
  return out;
}

// The options moving the place only (the width's search settles each trial's place).
RefineOptions PlaceOnly(RefineOptions options) {
  options.move_wrist = options.move_fingers = options.move_proportions = false;
  options.move_place = true;
  return options;
}

}  // namespace

bool RefineOptions::Check(std::string* why) const {
  if (sweeps < 0 || sweeps > 50 || halvings < 0 || halvings > 10) {
    *why = "refinement sweeps must be within 0..50 and halvings within 0..10";
  } else if (!(wrist_step_deg > 0.0 && wrist_step_deg <= 90.0) || !(joint_step_deg > 0.0 && joint_step_deg <= 90.0)) {
    *why = "refinement steps must be within (0, 90] degrees";
  } else if (!(shift_step > 0.0 && shift_step <= 0.5) || !(scale_step > 0.0 && scale_step <= 1.0)) {
    *why = "the refinement's place steps must be within (0, 0.5] of the crop and (0, 1] in log scale";
  } else if (!(prior >= 0.0 && prior <= 100.0) || !(track >= 0.0 && track <= 100.0)) {
    *why = "the refinement's prior and track weights must be within [0, 100]";
  } else if (!(track_within_deg >= 0.0 && track_within_deg <= 180.0)) {
    *why = "the refinement's track bound must be within [0, 180] degrees";
  } else if (!(blur_px >= 0.0 && blur_px <= 8.0)) {
    *why = "the refinement's blur must be within [0, 8] crop pixels";
  } else if (!(width_step >= kWidthGrid && width_step <= 0.2)) {
    *why = "the refinement's width step must be within [0.005, 0.2]";
  } else if (!move_place && !move_wrist && !move_fingers && !move_proportions) {
    *why = "the refinement must move something: the place, the wrist, the fingers or the proportions";
  } else if (render_side < 16 || render_side > 1024) {
    *why = "the refinement's render side must be within 16..1024 pixels";
  } else {
    return true;
  }
  return false;
}

double WidthOnGrid(double width) {
  return std::clamp(std::round(width / kWidthGrid) * kWidthGrid, kWidthMin, kWidthMax);
}

void SetRefineMoves(const std::vector<std::string>& names, RefineOptions* options) {
  NPHAND_THROW_CHECK(!names.empty(), "the refinement must move something: name any of place, wrist, fingers and proportions");
  RefineOptions moves = *options;
  moves.move_place = moves.move_wrist = moves.move_fingers = moves.move_proportions = false;
  for (const std::string& name : names) {
    bool* move = name == "place"         ? &moves.move_place
                 : name == "wrist"       ? &moves.move_wrist
                 : name == "fingers"     ? &moves.move_fingers
                 : name == "proportions" ? &moves.move_proportions
                                         : nullptr;
    NPHAND_THROW_CHECK(move != nullptr, "unknown refinement move '", name,
                       "' (choose any of place, wrist, fingers and proportions)");
    NPHAND_THROW_CHECK(!*move, "the refinement move '", name, "' is named twice");
    *move = true;
  }
  *options = moves;
}

std::vector<std::string> RefineMoves(const RefineOptions& options) {
  std::vector<std::string> names;
  if (options.move_place) names.push_back("place");
  if (options.move_wrist) names.push_back("wrist");
  if (options.move_fingers) names.push_back("fingers");
  if (options.move_proportions) names.push_back("proportions");
  return names;
}

nlohmann::json ToJson(const RefineOptions& options) {
  return {{"sweeps", options.sweeps},
          {"halvings", options.halvings},
          {"wrist_step_deg", options.wrist_step_deg},
          {"joint_step_deg", options.joint_step_deg},
          {"shift_step", options.shift_step},
          {"scale_step", options.scale_step},
          {"move_place", options.move_place},
          {"move_wrist", options.move_wrist},
          {"move_fingers", options.move_fingers},
          {"move_proportions", options.move_proportions},
          {"width_step", options.width_step},
          {"prior", options.prior},
          {"track", options.track},
          {"track_within_deg", options.track_within_deg},
          {"render_side", options.render_side},
          {"blur_px", options.blur_px},
          {"object_unknown", options.object_unknown}};
}

double Disagreement(const cv::Mat& a, const cv::Mat& b, const cv::Mat* unknown) {
  NPHAND_CHECK(a.type() == CV_32FC1 && b.type() == CV_32FC1 && a.size() == b.size(), "crops of one size compare");
  NPHAND_CHECK(unknown == nullptr || (unknown->type() == CV_32FC1 && unknown->size() == a.size()), "an unknown map of the crops' size");
  double both = 0.0, either = 0.0;
  for (int y = 0; y < a.rows; ++y) {
    const float* p = a.ptr<float>(y);
    const float* q = b.ptr<float>(y);
    const float* u = unknown != nullptr ? unknown->ptr<float>(y) : nullptr;
    for (int x = 0; x < a.cols; ++x) {
      const double known = u != nullptr ? 1.0 - u[x] : 1.0;
      both += known * std::min(p[x], q[x]);
      either += known * std::max(p[x], q[x]);
    }
  }
  return either > 0.0 ? 1.0 - both / either : 1.0;
}

Refiner::Refiner(const HandModel& hand, const Intrinsics& camera, double distance_m, const CropOptions& crop,
                 const RefineOptions& options)
    : hand_model_(hand), camera_(camera), distance_m_(distance_m), crop_(crop), options_(options), renderer_(hand) {
  std::string why;
  NPHAND_THROW_CHECK(options.Check(&why), "refine: ", why);
  NPHAND_THROW_CHECK(camera.Check(&why), "refine: ", why);
  NPHAND_THROW_CHECK(crop.Check(&why), "refine: ", why);
  NPHAND_THROW_CHECK(distance_m > 0.0, "refine: the hand's distance must be positive");
  const double shrink = static_cast<double>(options.render_side) / std::max(camera.width, camera.height);
  small_ = camera;
  small_.width = std::max(1, static_cast<int>(std::lround(camera.width * shrink)));
  small_.height = std::max(1, static_cast<int>(std::lround(camera.height * shrink)));
  small_.fx *= shrink;
  small_.fy *= shrink;
  small_.cx *= shrink;
  small_.cy *= shrink;
}

Refiner::Proportioned& Refiner::ProportionedOf(double width) {
  const long key = std::lround(WidthOnGrid(width) / kWidthGrid);
  auto it = proportioned_.find(key);
  if (it == proportioned_.end()) {
    Proportioned made;
    made.model = std::make_unique<HandModel>(hand_model_.Reproportioned(1.0, key * kWidthGrid));
    made.renderer = std::make_unique<Renderer>(*made.model);
    it = proportioned_.emplace(key, std::move(made)).first;
  }
  return it->second;
}

const HandModel& Refiner::Model(double width) {
  return WidthOnGrid(width) == 1.0 ? hand_model_ : *ProportionedOf(width).model;
}

void Refiner::RenderSmall(const Scene& scene, double width) {
  (WidthOnGrid(width) == 1.0 ? renderer_ : *ProportionedOf(width).renderer).RenderLabels(scene, small_, &labels_);
  hand_.create(labels_.size(), CV_32FC2);
  for (int y = 0; y < labels_.rows; ++y) {
    const uint8_t* label = labels_.ptr<uint8_t>(y);
    cv::Vec2f* out = hand_.ptr<cv::Vec2f>(y);
    for (int x = 0; x < labels_.cols; ++x) {
      out[x] = cv::Vec2f(label[x] == static_cast<uint8_t>(PixelLabel::kHand) ? 1.0f : 0.0f,
                         label[x] == static_cast<uint8_t>(PixelLabel::kObject) ? 1.0f : 0.0f);
    }
  }
}

cv::Mat Refiner::Silhouette(const cv::Matx23d& crop_from_small, cv::Mat* object) const {
  cv::Mat both;
  cv::warpAffine(hand_, both, crop_from_small, cv::Size(crop_.size, crop_.size), cv::INTER_LINEAR, cv::BORDER_CONSTANT, 0.0);
  cv::Mat planes[2];
  cv::split(both, planes);
  *object = planes[1];
  return planes[0];
}

Eigen::Matrix3d RotationOf(const Refinement& refinement) {
  return AxisAngle(Eigen::Vector3d::UnitZ(), -refinement.turn) * refinement.scene.hand.camera_from_hand;
}

Refinement Refiner::Refine(const HandCrop& target, const Scene& start, const cv::Matx23d& start_crop_from_image,
                           const Eigen::Matrix3d* previous, double width, bool move_width) {
  NPHAND_THROW_CHECK(!target.image.empty() && target.image.type() == CV_32FC1 && target.image.rows == crop_.size &&
                         target.image.cols == crop_.size,
                     "refine: the target must be a ", crop_.size, " x ", crop_.size, " crop");
  NPHAND_THROW_CHECK(std::isfinite(width), "refine: the hand's width factor must be finite");
  const std::vector<Direction> directions = Directions(options_);
  // Both silhouettes blurred alike, so that the render's pixel steps and the target's
  // resampling matter less than the shapes.
  cv::Mat goal;  // blurred into its own pixels (a view of the target's would write into them), or the target's, unblurred
  if (options_.blur_px > 0.0) {
    cv::GaussianBlur(target.image, goal, cv::Size(), options_.blur_px);
  } else {
    goal = target.image;
  }
  // A pixel of the search's small render to the camera's (pixel centres at integers).
  const double grow_x = static_cast<double>(camera_.width) / small_.width;
  const double grow_y = static_cast<double>(camera_.height) / small_.height;
  const cv::Matx23d image_from_small(grow_x, 0, 0.5 * grow_x - 0.5, 0, grow_y, 0.5 * grow_y - 0.5);
  Refinement out;
  Scene scene = start;
  const double centre = 0.5 * (crop_.size - 1);
  // The start's crop map moved by the place parameters: shifted, and scaled and turned about
  // the crop's centre.
  auto crop_from_image = [&](const Parameters& p) {
    const double k = std::exp(p[kPlace + 2]), c = k * std::cos(p[kPlace + 3]), s = k * std::sin(p[kPlace + 3]);
    const cv::Matx23d place(c, s, centre - c * centre - s * centre + p[kPlace], -s, c, centre + s * centre - c * centre + p[kPlace + 1]);
    return Compose(place, start_crop_from_image);
  };
  // The wrist's rotation of parameters `p`, in the render's camera.
  auto wrist = [&](const Parameters& p) {
    Eigen::Matrix3d turn = Eigen::Matrix3d::Identity();
    for (int axis = 0; axis < kWristAxes; ++axis) turn = AxisAngle(Eigen::Vector3d::Unit(axis), p[axis]) * turn;
    return Eigen::Matrix3d(turn * start.hand.camera_from_hand);
  };
  auto pose = [&](const Parameters& p) {
    scene.hand.camera_from_hand = wrist(p);
    for (int j = 0; j < kNumDofs; ++j) scene.hand.angles[j] = p[kWristAxes + j];
    scene.wrist_in_camera = CenteredWristPosition(scene.hand.camera_from_hand, Model(p[kWidth]).bind_centre(), distance_m_);
  };
  Parameters origin{};
  for (int j = 0; j < kNumDofs; ++j) origin[kWristAxes + j] = start.hand.angles[j];
  origin[kWidth] = WidthOnGrid(width);
  // The pull towards the start's pose (not its place): the mean square of the changes of
  // its angles (wrist and joints), over (90 degrees)².
  auto prior = [&](const Parameters& p) {
    double squares = 0.0;
    for (int i = 0; i < kPlace; ++i) squares += (p[i] - origin[i]) * (p[i] - origin[i]);
    return options_.prior * squares / kPlace / (0.25 * std::numbers::pi * std::numbers::pi);
  };
  // The pull towards the previous frame's rotation, unless the lookup has moved far from it
  // (a new view of the track, which the search's steps would not reach).
  const bool track = previous != nullptr && options_.track > 0.0 &&
                     RotationAngleDeg(start.hand.camera_from_hand, *previous) <= options_.track_within_deg;
  auto pull = [&](const Parameters& p) {
    if (!track) return 0.0;
    const double angle = RotationAngleDeg(AxisAngle(Eigen::Vector3d::UnitZ(), -p[kPlace + 3]) * wrist(p), *previous);
    return options_.track * (angle / 90.0) * (angle / 90.0);
  };
  // The parameters of the last render: a trial that moves only the place (the crop map)
  // warps it again without posing and rasterising the hand anew.
  std::optional<Parameters> rendered;
  auto same_hand = [](const Parameters& a, const Parameters& b) {
    return std::equal(a.begin(), a.begin() + kPlace, b.begin()) && a[kWidth] == b[kWidth];
  };
  auto evaluate = [&](const Parameters& p, double* disagreement) {
    if (!rendered.has_value() || !same_hand(p, *rendered)) {
      pose(p);
      RenderSmall(scene, p[kWidth]);
      rendered = p;
      ++out.renders;
    }
    cv::Mat object;
    cv::Mat hand = Silhouette(Compose(crop_from_image(p), image_from_small), &object);
    if (options_.blur_px > 0.0) cv::GaussianBlur(hand, hand, cv::Size(), options_.blur_px);
    *disagreement = Disagreement(hand, goal, options_.object_unknown && !start.objects.empty() ? &object : nullptr);
    return *disagreement + prior(p) + pull(p);
  };
  Parameters best = origin;
  double best_disagreement = 0.0;
  double best_objective = evaluate(best, &best_disagreement);
  out.objective_before = best_objective;
  out.disagreement_before = best_disagreement;
  // Steps along `direction` from `from` (into `from`, its objective and disagreement): a
  // step each way, the first that improves taken and repeated while it still does;
  // `settle_trial` (if given) moves each trial further before it is judged. True if it moved.
  using Settle = std::function<double(Parameters*, double*)>;
  auto step_along = [&](const Direction& direction, double step, Parameters* from, double* objective_of, double* disagreement_of,
                        const Settle& settle_trial) {
    for (double sign : {1.0, -1.0}) {
      bool moved = false;
      for (int repeat = 0; repeat < kRepeats; ++repeat) {
        Parameters trial = *from;
        for (const auto& [index, weight] : direction.moves) trial[index] += sign * weight * step;
        JointAngles angles;
        for (int j = 0; j < kNumDofs; ++j) angles[j] = trial[kWristAxes + j];
        angles = ClampToLimits(angles);
        for (int j = 0; j < kNumDofs; ++j) trial[kWristAxes + j] = angles[j];
        if (direction.kind == Kind::kWidth) trial[kWidth] = WidthOnGrid(trial[kWidth]);
        if (trial == *from) break;
        double disagreement = 0.0;
        const double objective = settle_trial ? settle_trial(&trial, &disagreement) : evaluate(trial, &disagreement);
        if (objective >= *objective_of) break;
        *from = trial;
        *objective_of = objective;
        *disagreement_of = disagreement;
        moved = true;
      }
      if (moved) return true;
    }
    return false;
  };
  auto step_of = [&](Kind kind, double scale) {
    return scale * (kind == Kind::kWrist   ? options_.wrist_step_deg * kDegToRad
                    : kind == Kind::kJoint ? options_.joint_step_deg * kDegToRad
                    : kind == Kind::kShift ? options_.shift_step * crop_.size
                    : kind == Kind::kScale ? options_.scale_step
                                           : options_.wrist_step_deg * kDegToRad);
  };
  // With move_width, the hand's width is measured first, from the start's pose: each width's
  // trial judged with its place settled, for a narrower hand is also a smaller silhouette
  // (a width's step alone rarely agrees better, though the width with its place does). From
  // the start's rotation, not the search's: the search's wrist turns to take up much of a
  // width's narrowing. The search below keeps the width given.
  double measured = origin[kWidth];
  if (options_.move_proportions && move_width) {
    const std::vector<Direction> place = Directions(PlaceOnly(options_));
    const Settle settle = [&](Parameters* trial, double* disagreement) {
      double objective = evaluate(*trial, disagreement);
      for (int sweep = 0; sweep < kPlaceSweeps; ++sweep) {
        bool improved = false;
        for (const Direction& direction : place) {
          improved |= step_along(direction, step_of(direction.kind, std::ldexp(0.5, -sweep)), trial, &objective, disagreement, nullptr);
        }
        if (!improved) break;
      }
      return objective;
    };
    Parameters at = origin;
    double disagreement_at = 0.0;
    double objective_at = settle(&at, &disagreement_at);
    const Direction width{{{kWidth, 1.0}}, Kind::kWidth};
    for (double step = options_.width_step; step >= kWidthGrid - 1e-12; step *= 0.5) {
      step_along(width, step, &at, &objective_at, &disagreement_at, settle);
    }
    measured = at[kWidth];
    out.width_disagreement = disagreement_at;
  }
  for (int sweep = 0; sweep < options_.sweeps; ++sweep) {
    const double scale = std::ldexp(1.0, -std::min(sweep, options_.halvings));
    bool improved = false;
    for (const Direction& direction : directions) {
      improved |= step_along(direction, step_of(direction.kind, scale), &best, &best_objective, &best_disagreement, nullptr);
    }
    if (!improved && scale <= std::ldexp(1.0, -options_.halvings)) break;
  }
  out.objective_after = best_objective;
  out.disagreement_after = best_disagreement;
  out.moved = best != origin;
  pose(best);
  out.scene = scene;
  out.crop_from_image = crop_from_image(best);
  out.turn = best[kPlace + 3];
  out.width = best[kWidth];
  out.width_measured = measured;
  return out;
}

}  // namespace nphand
