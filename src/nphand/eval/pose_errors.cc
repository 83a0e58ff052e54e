#include "nphand/eval/pose_errors.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <iomanip>
#include <limits>
#include <numbers>
#include <span>
#include <sstream>

#include <Eigen/Core>
#include <opencv2/imgproc.hpp>

#include "nphand/eval/json_lines.h"
#include "nphand/eval/measures.h"
#include "nphand/model/hand_model.h"
#include "nphand/model/hand_pose.h"
#include "nphand/model/skeleton.h"
#include "nphand/util/check.h"

namespace nphand {
namespace {

constexpr std::array<const char*, 6> kMeasures = {"joint_deg",   "wrist_deg", "keypoint_mm",
                                                   "keypoint_px", "camera_mm", "pa_mpjpe_mm"};

std::vector<nlohmann::json> ReadLines(const std::filesystem::path& path) {
  std::vector<nlohmann::json> lines;
  for (JsonLine& line : ReadJsonLines(path)) lines.push_back(std::move(line.json));
  NPHAND_THROW_CHECK(!lines.empty(), path.string(), ": no lines");
  return lines;
}

template <typename T>
T Field(const nlohmann::json& line, const char* key, const std::filesystem::path& path, size_t index) {
  try {
    return line.at(key).get<T>();
  } catch (const nlohmann::json::exception&) {
    NPHAND_THROW(path.string(), ": line ", index + 1, " has no valid '", key, "'");
  }
}

using Points3 = std::vector<std::array<double, 3>>;
using Points2 = std::vector<std::array<double, 2>>;

double ChainLength(const Points3& points) {
  Keypoints3d k;
  for (int i = 0; i < kNumKeypoints; ++i) k[i] = Eigen::Vector3d(points[i][0], points[i][1], points[i][2]);
  return HandLength(k);
}

double Mean(const std::vector<double>& v) {
  double s = 0.0;
  for (double x : v) s += x;
  return v.empty() ? 0.0 : s / v.size();
}

}  // namespace

PoseErrorSummary ComparePoses(const std::filesystem::path& truth_path, const std::filesystem::path& poses_path) {
  const std::vector<nlohmann::json> truth = ReadLines(truth_path), poses = ReadLines(poses_path);
  NPHAND_THROW_CHECK(poses.size() == truth.size(), poses_path.string(), " has ", poses.size(), " frames and ",
                     truth_path.string(), " ", truth.size(),
                     ": a run is scored whole (was it stopped, cut by --max-frames, or made on another sequence?)");
  PoseErrorSummary summary;
  std::array<std::vector<double>, kMeasures.size()> values;
  std::vector<double> distances;  // every keypoint's, about the wrist
  // Hand keypoints (metres, about the wrist) of the detected frames, estimate and truth, with
  // their frame numbers: for jitter.
  std::vector<Keypoints3d> estimated, true_keypoints;
  std::vector<int> detected_frames;
  LagMeter lag;
  for (size_t i = 0; i < poses.size(); ++i) {
    const nlohmann::json& p = poses[i];
    const nlohmann::json& t = truth[i];
    FramePoseError e;
    e.frame = Field<int>(p, "frame", poses_path, i);
    NPHAND_THROW_CHECK(e.frame == Field<int>(t, "frame", truth_path, i), poses_path.string(), ": line ", i + 1,
                       " is frame ", e.frame, " but the truth's line is another frame");
    e.detected = Field<bool>(p, "detected", poses_path, i);
    const Points3 th = Field<Points3>(t, "keypoints_3d_hand_m", truth_path, i);
    NPHAND_THROW_CHECK(th.size() == kNumKeypoints, truth_path.string(), ": line ", i + 1, ": keypoints must be 21");
    Keypoints3d truth_hand;
    for (int k = 0; k < kNumKeypoints; ++k) truth_hand[k] = Eigen::Vector3d(th[k][0], th[k][1], th[k][2]);
    // The lag reaches back over consecutive frames only, as the jitter does.
    if (i > 0 && int64_t{e.frame} != int64_t{summary.frames.back().frame} + 1) lag.Restart();
    if (e.detected) {
      const auto true_angles = Field<std::map<std::string, double>>(t, "joint_angles_deg", truth_path, i);
      const auto angles = Field<std::map<std::string, double>>(p, "joint_angles_deg", poses_path, i);
      for (const auto& [name, deg] : true_angles) {
        const auto it = angles.find(name);
        NPHAND_THROW_CHECK(it != angles.end(), poses_path.string(), ": line ", i + 1, " has no angle '", name, "'");
        e.joint_deg += std::abs(it->second - deg) / true_angles.size();
      }
      const auto r1 = Field<std::array<std::array<double, 3>, 3>>(p, "wrist_rotation", poses_path, i);
      const auto r2 = Field<std::array<std::array<double, 3>, 3>>(t, "wrist_rotation", truth_path, i);
      Eigen::Matrix3d a, b;
      for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c) {
          a(r, c) = r1[r][c];
          b(r, c) = r2[r][c];
        }
      }
      e.wrist_deg = RotationAngleDeg(a, b);
      summary.turned += e.wrist_deg >= kTurnedDeg;
      const Points3 kh = Field<Points3>(p, "keypoints_3d_hand_m", poses_path, i);
      const Points3 kc = Field<Points3>(p, "keypoints_3d_camera_m", poses_path, i);
      const Points3 tc = Field<Points3>(t, "keypoints_3d_camera_m", truth_path, i);
      const Points2 k2 = Field<Points2>(p, "keypoints_2d_px", poses_path, i);
      const Points2 t2 = Field<Points2>(t, "keypoints_2d_px", truth_path, i);
      NPHAND_THROW_CHECK(kh.size() == kNumKeypoints && kc.size() == kNumKeypoints &&
                             tc.size() == kNumKeypoints && k2.size() == kNumKeypoints && t2.size() == kNumKeypoints,
                         poses_path.string(), ": line ", i + 1, ": keypoints must be 21");
      const double scale = ChainLength(th) / std::max(ChainLength(kh), 1e-9);
      Keypoints3d estimate;
      for (int k = 0; k < kNumKeypoints; ++k) estimate[k] = scale * Eigen::Vector3d(kh[k][0], kh[k][1], kh[k][2]);
      lag.Add(truth_hand, &estimate);
      // Both sets hold the wrist at the origin: root-relative distances are the plain ones.
      const std::vector<double> d = RootRelativeDistances(estimate, truth_hand);
      distances.insert(distances.end(), d.begin(), d.end());
      e.keypoint_mm = 1000.0 * RootRelativeError(estimate, truth_hand);
      for (int k = 0; k < kNumKeypoints; ++k) {
        e.camera_mm += 1000.0 * std::hypot(kc[k][0] - tc[k][0], kc[k][1] - tc[k][1], kc[k][2] - tc[k][2]) / kNumKeypoints;
        e.keypoint_px += std::hypot(k2[k][0] - t2[k][0], k2[k][1] - t2[k][1]) / kNumKeypoints;
      }
      e.pa_mpjpe_mm = 1000.0 * ProcrustesError(estimate, truth_hand);
      // A line without a side (older files) is not judged.
      auto facing = [&](const Points2& points, const nlohmann::json& line) {
        const auto side = line.find("hand");
        if (side == line.end() || !side->is_string()) return Facing::kUnknown;
        std::array<Eigen::Vector2d, kNumKeypoints> keypoints;
        for (int k = 0; k < kNumKeypoints; ++k) keypoints[k] = Eigen::Vector2d(points[k][0], points[k][1]);
        return FacingOf(keypoints, side->get<std::string>());
      };
      const Facing true_facing = facing(t2, t);
      if (true_facing != Facing::kUnknown) {
        e.palm_back_ok = facing(k2, p) == true_facing;
        ++summary.palm_back_judged;
        summary.palm_back_right += *e.palm_back_ok;
      }
      estimated.push_back(estimate);
      true_keypoints.push_back(truth_hand);
      detected_frames.push_back(e.frame);
      ++summary.detected;
      const std::array<double, kMeasures.size()> row = {e.joint_deg,   e.wrist_deg, e.keypoint_mm,
                                                        e.keypoint_px, e.camera_mm, e.pa_mpjpe_mm};
      for (size_t m = 0; m < row.size(); ++m) values[m].push_back(row[m]);
    } else {
      lag.Add(truth_hand, nullptr);
    }
    summary.frames.push_back(e);
  }
  // Nothing detected, nothing measured: not a number, never a perfect 0.
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  for (const std::vector<double>& v : values) {
    summary.mean.push_back(v.empty() ? kNaN : Mean(v));
    summary.median.push_back(v.empty() ? kNaN : Median(v));
  }
  summary.within_20mm = distances.empty() ? kNaN : FractionWithin(distances, 0.02);
  summary.auc_0_50 = distances.empty() ? kNaN : AreaUnderCurve(distances, 0.05);
  summary.jitter_mm = summary.truth_jitter_mm = kNaN;
  // Jitter over each run of consecutive detected frames, weighted by its second differences.
  RunJitter jitter, truth_jitter;
  for (size_t begin = 0, end = 0; begin < detected_frames.size(); begin = end) {
    for (end = begin + 1; end < detected_frames.size() &&
                          int64_t{detected_frames[end]} == int64_t{detected_frames[end - 1]} + 1;) {
      ++end;
    }
    jitter.Add(std::span(estimated).subspan(begin, end - begin));
    truth_jitter.Add(std::span(true_keypoints).subspan(begin, end - begin));
  }
  if (!jitter.empty()) {
    summary.jitter_mm = 1000.0 * jitter.mean();
    summary.truth_jitter_mm = 1000.0 * truth_jitter.mean();
  }
  summary.lag_frames = lag.Lag();
  return summary;
}

namespace {

// A figure with two decimals, or "n/a".
std::string Figure(double v) { return std::isfinite(v) ? cv::format("%.2f", v) : std::string("n/a"); }

}  // namespace

nlohmann::json ToJson(const PoseErrorSummary& summary) {
  nlohmann::json mean = nlohmann::json::object(), median = nlohmann::json::object();
  for (size_t m = 0; m < kMeasures.size(); ++m) {
    mean[kMeasures[m]] = JsonNumber(summary.mean[m]);
    median[kMeasures[m]] = JsonNumber(summary.median[m]);
  }
  nlohmann::json frames = nlohmann::json::array();
  for (const FramePoseError& e : summary.frames) {
    nlohmann::json f = {{"frame", e.frame}, {"detected", e.detected}};
    if (e.detected) {
      f["joint_deg"] = e.joint_deg;
      f["wrist_deg"] = e.wrist_deg;
      f["keypoint_mm"] = e.keypoint_mm;
      f["keypoint_px"] = e.keypoint_px;
      f["camera_mm"] = e.camera_mm;
      f["pa_mpjpe_mm"] = e.pa_mpjpe_mm;
      f["palm_back_ok"] = e.palm_back_ok.has_value() ? nlohmann::json(*e.palm_back_ok) : nlohmann::json(nullptr);
    }
    frames.push_back(f);
  }
  return {{"frames", summary.frames.size()},
          {"detected", summary.detected},
          {"mean", mean},
          {"median", median},
          {"within_20mm", JsonNumber(summary.within_20mm)},
          {"auc_0_50", JsonNumber(summary.auc_0_50)},
          {"jitter_mm", JsonNumber(summary.jitter_mm)},
          {"truth_jitter_mm", JsonNumber(summary.truth_jitter_mm)},
          {"lag_frames", summary.lag_frames.has_value() ? nlohmann::json(*summary.lag_frames) : nlohmann::json(nullptr)},
          {"turned", summary.turned},
          {"palm_back_judged", summary.palm_back_judged},
          {"palm_back_right", summary.palm_back_right},
          {"per_frame", frames}};
}

std::string FormatTable(const PoseErrorSummary& summary) {
  std::ostringstream out;
  out << "detected " << summary.detected << " of " << summary.frames.size() << " frames\n";
  out << std::left << std::setw(14) << "measure" << std::right << std::setw(10) << "mean" << std::setw(10) << "median" << "\n";
  for (size_t m = 0; m < kMeasures.size(); ++m) {
    out << std::left << std::setw(14) << kMeasures[m] << std::right << std::setw(10) << Figure(summary.mean[m])
        << std::setw(10) << Figure(summary.median[m]) << "\n";
  }
  out << "keypoints within 20 mm " << Figure(summary.within_20mm) << ", AUC 0-50 mm " << Figure(summary.auc_0_50) << "\n";
  out << "jitter " << Figure(summary.jitter_mm) << " mm/frame^2 (the truth's own " << Figure(summary.truth_jitter_mm)
      << "; over runs of three detected frames)\n";
  out << "lag behind the truth "
      << (summary.lag_frames.has_value() ? std::to_string(*summary.lag_frames) + (*summary.lag_frames == 1 ? " frame" : " frames")
                                          : std::string("n/a"))
      << " (the shift of the truth, 0-" << kMaxLag << " frames back, at which the keypoints about the wrist agree best)\n";
  out << "wrist turned about a half turn (" << kTurnedDeg << " degrees or more off) in " << summary.turned << " of "
      << summary.detected << " detected frames\n";
  out << "palm or back towards the camera right in " << summary.palm_back_right << " of " << summary.palm_back_judged
      << " judged detected frames (the others edge-on or without a side)\n";
  return out.str();
}

cv::Mat PlotPoseErrors(const PoseErrorSummary& summary, const std::string& title) {
  const int width = 900, panel = 170, left = 70, right = 20, top = 40;
  const std::array<int, 3> shown = {0, 1, 2};  // joint_deg, wrist_deg, keypoint_mm
  const std::array<const char*, 3> labels = {"joint angle error, deg", "wrist rotation error, deg",
                                             "3D keypoint error about the wrist, mm"};
  cv::Mat plot(top + panel * static_cast<int>(shown.size()) + 30, width, CV_8UC3, cv::Scalar(255, 255, 255));
  const cv::Scalar black(0, 0, 0), blue(180, 90, 20), red(60, 60, 220);
  cv::putText(plot, title, {left, 25}, cv::FONT_HERSHEY_SIMPLEX, 0.6, black, 1, cv::LINE_AA);
  const size_t n = std::max<size_t>(summary.frames.size(), 2);
  const auto x_of = [&](size_t i) { return left + static_cast<int>((width - left - right) * i / (n - 1)); };
  for (size_t s = 0; s < shown.size(); ++s) {
    const int y0 = top + static_cast<int>(s) * panel, y1 = y0 + panel - 30;
    double high = 1.0;
    for (const FramePoseError& e : summary.frames) {
      const std::array<double, 3> v = {e.joint_deg, e.wrist_deg, e.keypoint_mm};
      if (e.detected) high = std::max(high, v[s]);
    }
    high = std::ceil(high);
    cv::line(plot, {left, y1}, {width - right, y1}, black);
    cv::line(plot, {left, y0}, {left, y1}, black);
    cv::putText(plot, labels[s], {left + 8, y0 + 14}, cv::FONT_HERSHEY_SIMPLEX, 0.45, black, 1, cv::LINE_AA);
    cv::putText(plot, cv::format("%.0f", high), {8, y0 + 10}, cv::FONT_HERSHEY_SIMPLEX, 0.42, black);
    cv::putText(plot, "0", {8, y1}, cv::FONT_HERSHEY_SIMPLEX, 0.42, black);
    std::vector<cv::Point> line;
    for (size_t i = 0; i < summary.frames.size(); ++i) {
      const FramePoseError& e = summary.frames[i];
      if (!e.detected) {
        cv::line(plot, {x_of(i), y1 - 6}, {x_of(i), y1}, red, 1);
        if (line.size() > 1) cv::polylines(plot, line, false, blue, 1, cv::LINE_AA);
        line.clear();
        continue;
      }
      const std::array<double, 3> v = {e.joint_deg, e.wrist_deg, e.keypoint_mm};
      line.emplace_back(x_of(i), y1 - static_cast<int>((y1 - y0 - 20) * v[s] / high));
    }
    if (line.size() > 1) cv::polylines(plot, line, false, blue, 1, cv::LINE_AA);
  }
  cv::putText(plot, "frame (red ticks: no hand reported)", {width / 2 - 120, plot.rows - 8}, cv::FONT_HERSHEY_SIMPLEX, 0.45,
              black, 1, cv::LINE_AA);
  return plot;
}

}  // namespace nphand
