#include "nphand/eval/pose_report.h"

#include <cmath>
#include <iomanip>
#include <limits>
#include <sstream>

#include "nphand/eval/json_lines.h"
#include "nphand/eval/measures.h"
#include "nphand/eval/plot.h"

namespace nphand {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

}  // namespace

nlohmann::json ToJson(const MethodScore& s) {
  return {{"method", s.method},
          {"sequence", s.sequence},
          {"alpha", s.alpha},
          {"frames", s.frames},
          {"detected", s.detected},
          {"no_hand_frames", s.no_hand_frames},
          {"false_detections", s.false_detections},
          {"pose_error", JsonNumber(s.pose_error)},
          {"keypoint_error_mm", JsonNumber(s.keypoint_mm)},
          {"pa_mpjpe_mm", JsonNumber(s.pa_mpjpe_mm)},
          {"within_20mm", JsonNumber(s.within_20mm)},
          {"auc_0_50", JsonNumber(s.auc_0_50)},
          {"keypoint_px", JsonNumber(s.keypoint_px)},
          {"joint_deg", JsonNumber(s.joint_deg)},
          {"wrist_deg", JsonNumber(s.wrist_deg)},
          {"turned", s.turned},
          {"jitter_mm", JsonNumber(s.jitter_mm)},
          {"truth_jitter_mm", JsonNumber(s.truth_jitter_mm)},
          {"lag_frames", s.lag_frames.has_value() ? nlohmann::json(*s.lag_frames) : nlohmann::json(nullptr)},
          {"ms_median", JsonNumber(s.ms_median)},
          {"pose_error_normalised", JsonNumber(s.pose_error_norm)},
          {"keypoint_error_normalised", JsonNumber(s.keypoint_norm)}};
}

std::string FormatScores(const std::vector<MethodScore>& scores, const std::string& sequence) {
  std::ostringstream out;
  out << std::left << std::setw(7) << "alpha" << std::setw(26) << "method" << std::right << std::setw(10) << "detected"
      << std::setw(9) << "no-hand"
      << std::setw(8) << "pose" << std::setw(7) << "/NN" << std::setw(9) << "kp_mm" << std::setw(7) << "/NN" << std::setw(8)
      << "PA_mm" << std::setw(7) << "<20mm" << std::setw(7) << "AUC" << std::setw(7) << "px" << std::setw(8) << "wrist"
      << std::setw(7) << "turned" << std::setw(8) << "jitter" << std::setw(5) << "lag" << std::setw(8) << "ms" << "\n";
  out << std::fixed;
  auto cell = [&](double v, int width, int precision) {
    if (std::isfinite(v)) {
      out << std::setprecision(precision) << std::setw(width) << v;
    } else {
      out << std::setw(width) << "-";
    }
  };
  for (const MethodScore& s : scores) {
    if (s.sequence != sequence) continue;
    out << std::left << std::setprecision(1) << std::setw(7) << s.alpha << std::setw(26) << s.method << std::right
        << std::setw(10) << (std::to_string(s.detected) + "/" + std::to_string(s.frames)) << std::setw(9)
        << (s.no_hand_frames > 0 ? std::to_string(s.false_detections) + "/" + std::to_string(s.no_hand_frames) : "-");
    cell(s.pose_error, 8, 3);
    cell(s.pose_error_norm, 7, 2);
    cell(s.keypoint_mm, 9, 1);
    cell(s.keypoint_norm, 7, 2);
    cell(s.pa_mpjpe_mm, 8, 1);
    cell(s.within_20mm, 7, 2);
    cell(s.auc_0_50, 7, 2);
    cell(s.keypoint_px, 7, 1);
    cell(s.wrist_deg, 8, 1);
    out << std::setw(7) << s.turned;
    cell(s.jitter_mm, 8, 2);
    out << std::setw(5) << (s.lag_frames.has_value() ? std::to_string(*s.lag_frames) : "-");
    cell(s.ms_median, 8, 2);
    out << "\n";
  }
  return out.str();
}

nlohmann::json ToJson(const PoseStudyResult& result) {
  nlohmann::json rows = nlohmann::json::array();
  for (const MethodScore& s : result.scores) rows.push_back(ToJson(s));
  return {{"part", result.part},   {"sequences", result.sequences}, {"methods", result.methods},
          {"seconds", result.seconds}, {"rows", rows}};
}

std::vector<std::pair<std::string, cv::Mat>> PlotPoseStudy(const PoseStudyResult& result) {
  std::vector<std::pair<std::string, cv::Mat>> plots;
  std::vector<std::string> methods;
  for (const MethodScore& s : result.scores) {
    if (std::find(methods.begin(), methods.end(), s.method) == methods.end()) methods.push_back(s.method);
  }
  const auto at = [&](const std::string& method, const std::string& sequence, double alpha) -> const MethodScore* {
    for (const MethodScore& s : result.scores) {
      if (s.method == method && s.sequence == sequence && s.alpha == alpha) return &s;
    }
    return nullptr;
  };
  if (result.part == "robustness") {
    std::vector<PlotSeries> series;
    for (const std::string& m : methods) {
      PlotSeries line{m, {}, {}};
      for (size_t v = 0; v < result.sequences.size(); ++v) {
        const MethodScore* s = at(m, result.sequences[v]["name"].get<std::string>(), 0.0);
        line.x.push_back(static_cast<double>(v));
        line.y.push_back(s != nullptr ? s->keypoint_mm : kNaN);
      }
      series.push_back(line);
    }
    std::string variants;
    for (size_t v = 0; v < result.sequences.size(); ++v) {
      variants += (v == 0 ? "" : ", ") + std::to_string(v) + " " + result.sequences[v]["name"].get<std::string>();
    }
    plots.emplace_back("robustness_errors", PlotLines(series, "3D keypoint error (mm) per variant", variants));
  } else {
    std::vector<std::string> names;
    std::vector<double> values;
    for (const std::string& m : methods) {
      const MethodScore* s = at(m, "all", 0.0);
      if (s == nullptr) continue;
      names.push_back(m);
      values.push_back(s->keypoint_norm);
    }
    plots.emplace_back(result.part + "_errors",
                       PlotBars(names, values, "3D keypoint error / NN-pose bound's, clean masks (Fig. 6)"));
  }
  std::vector<PlotSeries> curves;
  const std::string sequence = result.part == "robustness" ? "base" : "all";
  for (const std::string& m : methods) {
    const MethodScore* s = at(m, sequence, 0.0);
    if (s == nullptr) continue;
    PlotSeries curve{m, {}, {}};
    for (int mm = 0; mm <= 50; mm += 2) {
      curve.x.push_back(mm);
      curve.y.push_back(FractionWithin(s->distances, mm / 1000.0));
    }
    curves.push_back(curve);
  }
  plots.emplace_back(result.part + "_curves",
                     PlotLines(curves, "fraction of keypoints within a distance (" + sequence + ")", "mm"));
  if (result.part == "noise") {
    std::vector<PlotSeries> series;
    for (const std::string& m : methods) {
      PlotSeries line{m, {}, {}};
      for (const MethodScore& s : result.scores) {
        if (s.method == m && s.sequence == "all") {
          line.x.push_back(s.alpha);
          line.y.push_back(s.keypoint_mm);
        }
      }
      if (line.x.size() > 1) series.push_back(line);
    }
    plots.emplace_back("noise_alpha", PlotLines(series, "3D keypoint error (mm) against segmentation noise (Fig. 7)",
                                                "alpha: % of hand pixels removed"));
  }
  return plots;
}

}  // namespace nphand
