#include "nphand/estimate/frame_json.h"

#include <numbers>
#include <vector>

#include <Eigen/Geometry>

#include "nphand/scene/gesture.h"

namespace nphand {
namespace {

constexpr double kDegPerRad = 180.0 / std::numbers::pi;

nlohmann::json Rotation(const Eigen::Matrix3d& r) {
  return {{r(0, 0), r(0, 1), r(0, 2)}, {r(1, 0), r(1, 1), r(1, 2)}, {r(2, 0), r(2, 1), r(2, 2)}};
}

nlohmann::json Angles(const JointAngles& angles) {
  nlohmann::json out = nlohmann::json::object();
  for (int d = 0; d < kNumDofs; ++d) out[Dofs()[d].name] = angles[d] * kDegPerRad;
  return out;
}

nlohmann::json Points(const Keypoints3d& points) {
  nlohmann::json out = nlohmann::json::array();
  for (const Eigen::Vector3d& p : points) out.push_back({p.x(), p.y(), p.z()});
  return out;
}

nlohmann::json Posterior(const std::vector<std::pair<std::string, double>>& p, const char* key) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& [name, probability] : p) out.push_back({{key, name}, {"p", probability}});
  return out;
}

}  // namespace

nlohmann::json FrameResultJson(const FrameResult& r, const Database& db, bool with_top) {
  nlohmann::json j = {{"frame", r.frame}, {"time_s", r.time_s}, {"detected", r.detected()}, {"status", ToString(r.status)}};
  j["ms"] = {{"segment", r.ms.segment}, {"describe", r.ms.describe}, {"search", r.ms.search}, {"weigh", r.ms.weigh},
             {"refine", r.ms.refine},   {"place", r.ms.place},       {"total", r.ms.total}};
  if (!r.detected()) {
    j["reason"] = r.reason;
    if (r.status == FrameStatus::kNotAHand) j["nearest_distance"] = r.nearest_distance;
    return j;
  }
  const Eigen::Quaterniond q(r.pose.camera_from_hand);
  const PoseVector pose = ToPoseVector(r.pose);
  nlohmann::json keypoints_2d = nlohmann::json::array();
  for (const Eigen::Vector2d& k : r.keypoints_2d) keypoints_2d.push_back({k.x(), k.y()});
  j["hand"] = ToString(r.hand);
  if (r.hand_margin.has_value()) j["hand_margin"] = *r.hand_margin;
  j["wrist_rotation"] = Rotation(r.pose.camera_from_hand);
  j["wrist_quaternion_wxyz"] = {q.w(), q.x(), q.y(), q.z()};
  j["joint_angles_deg"] = Angles(r.pose.angles);
  j["pose_vector"] = std::vector<double>(pose.data(), pose.data() + pose.size());
  j["keypoints_2d_px"] = keypoints_2d;
  j["keypoints_3d_hand_m"] = Points(r.keypoints_hand);
  j["keypoints_3d_camera_m"] = Points(r.keypoints_camera);
  j["depth_m"] = r.depth_m;
  j["box_px"] = {r.box.x, r.box.y, r.box.width, r.box.height};
  if (r.refine_objective.has_value()) {
    j["refined"] = r.refined;
    j["refine_objective"] = {{"before", r.refine_objective->first}, {"after", r.refine_objective->second}};
  }
  if (r.proportions.has_value()) {
    j["proportions"] = {{"length", r.proportions->length}, {"width", r.proportions->width}, {"held", r.proportions->held}};
  }
  j["grasps"] = Posterior(r.grasps, "grasp");
  j["objects"] = Posterior(r.objects, "object");
  j["confidence"] = r.confidence;
  j["effective_samples"] = r.effective_samples;
  j["mean_of"] = r.mean_of;
  j["nearest_distance"] = r.nearest_distance;
  j["forearm_cut"] = r.forearm_cut;
  j["both_turns"] = r.both_turns;
  j["tilted"] = r.tilted;
  j["tilt_deg"] = r.tilt_deg;
  j["prior_used"] = r.prior_used;
  j["entry"] = r.top[0].entry;
  if (with_top) {
    nlohmann::json top = nlohmann::json::array();
    for (const Hypothesis& h : r.top) {
      const EntryMeta meta = db.Meta(h.entry);
      const Eigen::Quaterniond hq(h.pose.camera_from_hand);
      top.push_back({{"entry", h.entry},
                     {"weight", h.weight},
                     {"distance", h.distance},
                     {"grasp", HandShapeKey(meta.grasp)},
                     {"step", meta.step},
                     {"with_object", meta.with_object},
                     {"wrist_quaternion_wxyz", {hq.w(), hq.x(), hq.y(), hq.z()}},
                     {"joint_angles_deg", Angles(h.pose.angles)}});
    }
    j["top"] = top;
  }
  return j;
}

}  // namespace nphand
