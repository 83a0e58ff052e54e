// The pose study's reports: its scores as JSON and as a table, and its plots.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "nphand/eval/pose_study.h"

namespace nphand {

nlohmann::json ToJson(const MethodScore& score);
// Rows of the scores whose sequence is `sequence`, one line per (alpha, method).
std::string FormatScores(const std::vector<MethodScore>& scores, const std::string& sequence = "all");

nlohmann::json ToJson(const PoseStudyResult& result);
// Plots of a result, by file stem: "<part>_errors" (Fig. 6: keypoint error normalised by
// NN pose per method; for robustness, keypoint error per variant), "<part>_curves" (the
// fraction of keypoints within a distance, 0-50 mm, per method), and for the noise part
// "noise_alpha" (Fig. 7: keypoint error against alpha per method).
std::vector<std::pair<std::string, cv::Mat>> PlotPoseStudy(const PoseStudyResult& result);

}  // namespace nphand
