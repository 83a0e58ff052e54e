// The paper's experiments (PAPER.md Sec. 6, Figs. 6, 7 and 9) on our system: test
// sequences whose grasps close onto objects the database lacks, the segmentation noise of
// Fig. 7, the methods (pose_methods.h) run over them, and the paper's and today's measures
// per method, noise level and sequence; pose_report.h writes and plots the results.
//
// Methods see what the paper's experiments gave them: the hand's mask (the object leaves
// its hole; no forearm), noisy or clean. The estimator is also run on the RGB frames, which
// is what a user has. Every method answers in the frame's camera: a method that predicts a
// roll-normalised pose is turned back by the mask's roll and by the ray to the hand, as the
// estimator turns its neighbours.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "nphand/db/database.h"
#include "nphand/estimate/estimator.h"
#include "nphand/eval/regression.h"
#include "nphand/index/knn_index.h"
#include "nphand/model/hand_model.h"
#include "nphand/sequence/sequence.h"

namespace nphand {

// A test sequence: how `nphand sequence` renders it, and the hand's proportions
// (HandModel::Reproportioned; 1, 1: the database's hand).
struct StudySequence {
  std::string name;
  SequenceOptions options;
  double length = 1.0;
  double width = 1.0;
};

// The evaluation's sequences, as the paper's Fig. 9: a book-sized box, a ball and a bottle
// of sizes the database lacks, a lid and a pen; each grasp closed onto its object afresh,
// the camera moving and rolling, a forearm in view. Seeds seed, seed + 1, ... (the
// estimator's validation used 7000-7023; these are never used to choose parameters).
std::vector<StudySequence> TestSequences(int frames, int width, int height, uint64_t seed, bool adult_arm);
// One sequence (the ball) on a plain background with a bare forearm and a medium skin, then
// variants that each change one thing: a dark and a light skin, a textured background, a
// sleeve, a hand 10 % longer and narrower.
std::vector<StudySequence> RobustnessSequences(int frames, int width, int height, uint64_t seed, bool adult_arm);

// A rendered frame of a study sequence, with what the methods and the measures need.
struct StudyFrame {
  SequenceFrame truth;
  cv::Mat hand_mask;           // CV_8UC1: the hand's pixels of truth.labels (255)
  Intrinsics intrinsics;       // the sequence's camera
  double hand_length_m = 0.0;  // the rendered hand's
};
struct RenderedSequence {
  StudySequence sequence;
  std::vector<StudyFrame> frames;
  // Every tenth frame's view without the hand, object or arm (Sequence::RenderEmpty; its
  // face stays): what the methods that read RGB must call "no hand".
  std::vector<StudyFrame> empty_frames;
};
// Renders the sequences (the proportioned hands made from `hand`), reporting progress.
std::vector<RenderedSequence> RenderSequences(const HandModel& hand, const std::vector<StudySequence>& sequences,
                                              std::ostream* progress);

// Fig. 7's segmentation noise: `alpha_percent` of the mask's pixels removed at random (by
// the seed), then a 3 x 3 erosion and a 3 x 3 dilation. 0 gives the mask as it is.
cv::Mat SegmentationNoise(const cv::Mat& mask, double alpha_percent, uint64_t seed);

// A method's figures over a set of frames at one noise level.
struct MethodScore {
  std::string method;
  std::string sequence;            // a sequence's name, or "all"
  double alpha = 0.0;              // noise, percent of the hand's pixels
  int frames = 0;
  int detected = 0;
  // Methods that read RGB, on the frames without a hand: how many, and how many had one found.
  int no_hand_frames = 0;
  int false_detections = 0;
  // Means over detected frames.
  double pose_error = 0.0;         // Euclidean, pose-vector space (the paper's first measure)
  double keypoint_mm = 0.0;        // 21 keypoints about the wrist (the paper's second; = root-relative MPJPE)
  double pa_mpjpe_mm = 0.0;        // after a similarity alignment
  double joint_deg = 0.0;          // mean absolute joint-angle error
  double wrist_deg = 0.0;          // wrist orientation
  int turned = 0;                  // detected frames with the wrist turned about a half turn (kTurnedDeg or more from the truth)
  double keypoint_px = 0.0;        // 2D, in the frame; NaN for methods that do not place the hand
  // Over every keypoint of the detected frames.
  double within_20mm = 0.0;
  double auc_0_50 = 0.0;
  double jitter_mm = 0.0;          // mm per frame squared, over runs of detected frames
  double truth_jitter_mm = 0.0;    // the truth's over the same frames
  std::optional<int> lag_frames;   // behind the truth (LagMeter, measures.h); none with nothing detected
  double ms_median = 0.0;          // per frame
  // Divided by the NN-pose bound's on the same frames (Fig. 6's normalisation); NaN without it.
  double pose_error_norm = 0.0;
  double keypoint_norm = 0.0;
  std::vector<double> distances;   // every keypoint distance (metres), for the error curves
};

class PoseMethod;  // pose_methods.h

// Runs every method over every sequence at every noise level (RGB methods at alpha 0 only,
// and then over the sequence's frames without a hand) and scores them over all sequences and
// per sequence.
std::vector<MethodScore> RunMethods(std::vector<std::unique_ptr<PoseMethod>>& methods,
                                    const std::vector<RenderedSequence>& sequences, const std::vector<double>& alphas,
                                    const HandModel& hand, uint64_t noise_seed, std::ostream* progress);

nlohmann::json DescribeSequences(const std::vector<RenderedSequence>& sequences);

// The study's parts (`nphand eval baselines|noise|robustness`).
enum class PoseStudyPart : uint8_t {
  kBaselines,   // every method on the test sequences, clean masks (and the estimator on RGB)
  kNoise,       // the mask methods at every alpha (Fig. 7); its alpha-0 rows are the baselines
  kRobustness,  // the estimator (RGB and mask), NN feature and the NN-pose bound on the variants
};
std::string ToString(PoseStudyPart part);

struct PoseStudyOptions {
  int frames = 100;                // per sequence
  int width = 640;
  int height = 480;
  uint64_t seed = 9000;            // test sequences seed..seed+4; robustness seed + 100
  std::vector<double> alphas = {0.0, 0.5, 1.0, 2.0, 3.0, 4.0, 5.0};  // kNoise
  bool exact = true;               // run the estimator with exact search too (the index issue's yardstick)
  int lsq_rows = 20000;            // regression fits: database entries drawn by fit_seed
  int gp_rows = 2000;
  int rvm_rows = 800;
  uint64_t fit_seed = 1;
  bool adult_arm = false;          // the sequences' forearms are an adult's arm (Forearm::Adult()), not the cone
  bool Check(std::string* why) const;
};

struct PoseStudyResult {
  std::string part;
  nlohmann::json sequences;        // DescribeSequences
  nlohmann::json methods;          // name -> what it is (Describe)
  std::vector<MethodScore> scores;
  double seconds = 0.0;
};

// Renders the part's sequences, makes its methods (the estimator with `options_base`'s
// settings on `index`, and on an exact index of `db` when options.exact) and runs them.
PoseStudyResult RunPoseStudy(PoseStudyPart part, const Database& db, const KnnIndex& index, const HandModel& hand,
                             const EstimatorOptions& options_base, const PoseStudyOptions& options, std::ostream* progress);

// The baselines part of a noise result: its rows at alpha 0.
PoseStudyResult BaselinesOf(const PoseStudyResult& noise);

}  // namespace nphand
