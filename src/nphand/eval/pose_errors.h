// Errors of estimated poses against ground truth, frame by frame: what `nphand estimate`
// wrote (poses.jsonl) against what `nphand sequence` rendered (truth.jsonl), in the paper's
// measures (joint angles; 3D joint positions about the wrist, which the paper prefers, Fig. 8)
// and today's (wrist rotation, 2D keypoints in pixels, 3D keypoints in the camera frame,
// PA-MPJPE, the fraction within 20 mm and the AUC over 0-50 mm, jitter, the side of the
// hand towards the camera; measures.h).
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

namespace nphand {

struct FramePoseError {
  int frame = 0;
  bool detected = false;
  double joint_deg = 0.0;    // mean absolute joint-angle error
  double wrist_deg = 0.0;    // angle of the rotation between estimated and true wrist rotations
  double keypoint_mm = 0.0;  // mean 3D keypoint distance about the wrist, estimate scaled to the truth's hand length
  double keypoint_px = 0.0;  // mean 2D keypoint distance in the frame
  double camera_mm = 0.0;    // mean 3D keypoint distance in the camera frame
  double pa_mpjpe_mm = 0.0;  // keypoint_mm's keypoints after a similarity (Procrustes) alignment
  // Whether the estimate has the truth's side of the hand towards the camera (FacingOf on
  // each one's 2D keypoints and side; empty when the truth's is edge-on).
  std::optional<bool> palm_back_ok;
};

struct PoseErrorSummary {
  std::vector<FramePoseError> frames;
  int detected = 0;
  // Over detected frames: mean and median of each measure, in the order joint_deg,
  // wrist_deg, keypoint_mm, keypoint_px, camera_mm, pa_mpjpe_mm. Every figure of the
  // summary is NaN (null in JSON, "n/a" in the table) when there was nothing to measure.
  std::vector<double> mean, median;
  // Over every keypoint of the detected frames (about the wrist, as keypoint_mm): the
  // fraction within 20 mm and the area under that fraction's curve over 0-50 mm.
  double within_20mm = 0.0;
  double auc_0_50 = 0.0;
  // Mean keypoint acceleration about the wrist, mm per frame squared, over runs of three
  // detected frames in a row: the estimate's and the truth's own over the same frames.
  double jitter_mm = 0.0;
  double truth_jitter_mm = 0.0;
  // The estimate's lag behind the truth, frames (LagMeter, measures.h); none with nothing detected.
  std::optional<int> lag_frames;
  // Detected frames with the wrist turned about a half turn: kTurnedDeg (measures.h) or more
  // from the truth's.
  int turned = 0;
  // Detected frames whose side towards the camera is judged, and those the estimate has right.
  int palm_back_judged = 0, palm_back_right = 0;
};

// Reads both files (one JSON object per line, the same frames in the same order, as many in
// one as in the other) and compares them. Throws nphand::Error naming the file and line of anything missing or
// mismatched.
PoseErrorSummary ComparePoses(const std::filesystem::path& truth, const std::filesystem::path& poses);

nlohmann::json ToJson(const PoseErrorSummary& summary);
std::string FormatTable(const PoseErrorSummary& summary);
// The errors over the frames: one panel per measure, undetected frames marked.
cv::Mat PlotPoseErrors(const PoseErrorSummary& summary, const std::string& title);

}  // namespace nphand
