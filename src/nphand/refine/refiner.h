// Refinement beyond the database: a pose moved by local search until its rendered
// silhouette agrees with the frame's hand mask better than the database's nearest view did.
// The comparison is made where the descriptor is made, in the hand's normalised crop (its
// square window, turned by its principal axis), through the start's own crop map, so that
// a finger's move does not rescale the silhouette. What moves: the silhouette's place in
// the crop (shift, scale, turn within the view), the wrist across the view and, if asked,
// the fingers' joints. It can also measure the hand's proportions (its width against its
// length: the crop hides the hand's size, so the silhouette tells their ratio only).
#pragma once

#include <map>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "nphand/features/crop.h"
#include "nphand/model/hand_model.h"
#include "nphand/render/renderer.h"
#include "nphand/scene/scene.h"

namespace nphand {

struct RefineOptions {
  int sweeps = 3;               // passes over every direction of the search
  int halvings = 2;             // each pass after the first halves the steps, at most this many times
  double wrist_step_deg = 8.0;  // first step of the wrist's rotation about each camera axis
  double joint_step_deg = 12.0; // first step of the finger joints' directions
  double shift_step = 0.03;     // first step of the silhouette's shift, a fraction of the crop
  double scale_step = 0.05;     // first step of its scale, in log scale (its turn's: the wrist's)
  bool move_place = true;       // the silhouette's shift, scale and turn in the crop
  bool move_wrist = true;
  // The fingers' joints: off by default, for the silhouette does not tell them well enough
  // (the validation sweep, docs/estimator.md: joint error 2.2 -> 3.9 degrees on masks).
  bool move_fingers = false;
  // The hand's width (across the palm and through it) against the database hand's at the
  // same length, HandModel::Reproportioned(1, width): off unless asked (`proportions`).
  bool move_proportions = false;
  double width_step = 0.04;     // first step of the width's measurement (on a grid of kWidthGrid)
  // The pull towards the start: this weight times the sum of the squared changes of the
  // pose's angles (wrist and joints, radians) over their number (23), over (90 degrees)²,
  // added to the disagreement (1 - IoU).
  double prior = 0.05;
  // The pull towards the previous frame's rotation (when given and within track_within_deg
  // of the start's): this weight times the square of the angle between them over 90 degrees.
  // Measured on the validation sweep (docs/estimator.md): 2 lowers both error and jitter.
  double track = 2.0;
  double track_within_deg = 30.0;
  int render_side = 64;         // the search renders at this many pixels a side
  double blur_px = 1.0;         // Gaussian sigma, crop pixels, of both silhouettes before comparing (0: none)
  // The start's object is of the database's size, not the frame's: where it lies, the
  // frame's hand may or may not be, and those pixels do not count.
  bool object_unknown = true;
  bool Check(std::string* why) const;
};

nlohmann::json ToJson(const RefineOptions& options);

// The width factors the refinement searches: multiples of kWidthGrid within [kWidthMin,
// kWidthMax] (a hand 10 % longer and narrower than the database's is 0.82).
inline constexpr double kWidthGrid = 0.005;
inline constexpr double kWidthMin = 0.7;
inline constexpr double kWidthMax = 1.4;
// `width` clamped to [kWidthMin, kWidthMax] and rounded to the grid.
double WidthOnGrid(double width);

// What the search moves, by name: any of "place", "wrist", "fingers" and "proportions"
// (`--refine-move`; the default is place and wrist). Throws nphand::Error naming an unknown
// or repeated name, or for none.
void SetRefineMoves(const std::vector<std::string>& names, RefineOptions* options);
std::vector<std::string> RefineMoves(const RefineOptions& options);

// A silhouette agreement of two crop coverages (CV_32FC1 of one size): 1 - the
// intersection over union (sum of minima over sum of maxima), in [0, 1] (0: the same).
// Pixels count by 1 - `unknown` (if given: where an object may hide the hand, 1). 1 when
// nothing counts (no coverage on either side where it is known).
double Disagreement(const cv::Mat& a, const cv::Mat& b, const cv::Mat* unknown = nullptr);

struct Refinement {
  Scene scene;                       // the refined scene: the start's objects and distance
  cv::Matx23d crop_from_image;       // the camera's pixels to the target's crop, the place included
  double turn = 0.0;                 // radians the silhouette was turned in the crop (counter-clockwise as displayed)
  double objective_before = 0.0;     // disagreement + the pulls, at the start
  double objective_after = 0.0;      // and at the end (never above the start's)
  double disagreement_before = 0.0;  // 1 - IoU at the start
  double disagreement_after = 0.0;
  double width = 1.0;                // the hand's width factor the search used (the one given, on the grid)
  double width_measured = 1.0;       // with move_proportions and move_width: the width the silhouette favours
  double width_disagreement = 1.0;   // and 1 - IoU there (from the start's pose, its place settled)
  int renders = 0;                   // the hand posed and rasterised (a trial of the place alone reuses the last)
  bool moved = false;                // the pose or place changed
};

// A refinement's rotation in the start's image plane: its wrist turned by the silhouette's
// turn in the crop (the estimator turns it further by the lookup's turn).
Eigen::Matrix3d RotationOf(const Refinement& refinement);

class Refiner {
 public:
  // `hand` must outlive the refiner; `camera` is the camera the start scenes are placed
  // for (the database's), `distance_m` the hand centre's distance from it, `crop` the crop
  // the targets were made with. Throws nphand::Error for invalid options.
  Refiner(const HandModel& hand, const Intrinsics& camera, double distance_m, const CropOptions& crop,
          const RefineOptions& options = {});

  // Moves `start`'s wrist rotation and joint angles (within their limits), and the
  // silhouette's place, to agree with `target` (a crop made with the same crop options).
  // `start_crop_from_image` maps the start's render by `camera` into the crop it was
  // matched with (the database entry's); the search keeps it, so that a finger's move does
  // not rescale the whole silhouette. The wrist stays centred at the distance; the objects
  // stay with the hand and hide it as they do in the frame. Throws nphand::Error for a
  // target of another size.
  // `previous` (if not null) is the previous frame's refined rotation as this start's would
  // be reported: RotationOf(previous refinement), turned into this start's image plane.
  // The hand is `width` times as wide as the database's (on the grid: WidthOnGrid); with
  // move_proportions and `move_width` the width the silhouette favours is measured too
  // (from the start's pose, its place settled; Refinement::width_measured), the search
  // keeping the width given.
  Refinement Refine(const HandCrop& target, const Scene& start, const cv::Matx23d& start_crop_from_image,
                    const Eigen::Matrix3d* previous = nullptr, double width = 1.0, bool move_width = true);

  const RefineOptions& options() const { return options_; }
  // The hand `width` times as wide as the database's (the one given at construction for 1;
  // the others made when first asked for and kept while the refiner lives).
  const HandModel& Model(double width);

 private:
  // Renders `scene`'s hand (`width` times as wide as the database's) at the search's
  // resolution into hand_: its coverage and its object's.
  void RenderSmall(const Scene& scene, double width);
  // The last render's hand coverage in the crop, warped by `crop_from_small`; `object` gets
  // its object's.
  cv::Mat Silhouette(const cv::Matx23d& crop_from_small, cv::Mat* object) const;
  struct Proportioned {
    std::unique_ptr<HandModel> model;
    std::unique_ptr<Renderer> renderer;
  };
  Proportioned& ProportionedOf(double width);

  const HandModel& hand_model_;
  Intrinsics camera_;
  Intrinsics small_;  // camera_ scaled to render_side
  double distance_m_;
  CropOptions crop_;
  RefineOptions options_;
  Renderer renderer_;
  std::map<long, Proportioned> proportioned_;  // by width in grid steps, other than 1
  cv::Mat labels_, hand_;  // the search's buffers
};

}  // namespace nphand
