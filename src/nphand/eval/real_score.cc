#include "nphand/eval/real_score.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <iomanip>
#include <numeric>
#include <set>
#include <sstream>

#include <Eigen/Geometry>

#include "nphand/eval/json_lines.h"
#include "nphand/eval/measures.h"
#include "nphand/util/check.h"
#include "nphand/util/stats.h"
#include "nphand/util/text.h"

namespace nphand {
namespace {

constexpr std::array<const char*, 5> kGroundTruthSources = {"freihand", "onehand10k", "panoptic", "interhand", "hagrid"};
constexpr std::array<const char*, 3> kMediaPipeSources = {"tfjs_hands", "mediapipe_thumbs_up", "asl_video"};
constexpr double kGrow = 0.25;

std::string Stem(const std::string& file) { return std::filesystem::path(file).stem().string(); }

bool IsNumber(const nlohmann::json& j) { return j.is_number() && std::isfinite(j.get<double>()); }

// 21 [x, y] points (null entries allowed when `nulls`); throws naming `where`.
std::array<std::optional<Eigen::Vector2d>, kNumKeypoints> Points2(const nlohmann::json& j, bool nulls, const std::string& where) {
  NPHAND_THROW_CHECK(j.is_array() && j.size() == kNumKeypoints, where, ": keypoints_2d_px must hold 21 [x, y] points");
  std::array<std::optional<Eigen::Vector2d>, kNumKeypoints> points;
  for (int k = 0; k < kNumKeypoints; ++k) {
    if (j[k].is_null() && nulls) continue;
    NPHAND_THROW_CHECK(j[k].is_array() && j[k].size() >= 2 && IsNumber(j[k][0]) && IsNumber(j[k][1]), where,
                       ": keypoint ", k, " is not [x, y]");
    points[k] = Eigen::Vector2d(j[k][0].get<double>(), j[k][1].get<double>());
  }
  return points;
}

Keypoints3d Points3(const nlohmann::json& j, const std::string& name, const std::string& where) {
  NPHAND_THROW_CHECK(j.is_array() && j.size() == kNumKeypoints, where, ": ", name, " must hold 21 [x, y, z] points");
  Keypoints3d points;
  for (int k = 0; k < kNumKeypoints; ++k) {
    NPHAND_THROW_CHECK(j[k].is_array() && j[k].size() == 3 && IsNumber(j[k][0]) && IsNumber(j[k][1]) && IsNumber(j[k][2]),
                       where, ": ", name, " point ", k, " is not [x, y, z]");
    points[k] = Eigen::Vector3d(j[k][0].get<double>(), j[k][1].get<double>(), j[k][2].get<double>());
  }
  return points;
}

std::string Side(const nlohmann::json& j, const std::string& where) {
  if (j.is_null()) return "";
  NPHAND_THROW_CHECK(j.is_string(), where, ": hand must be \"left\", \"right\" or null");
  const std::string side = AsciiLower(j.get<std::string>());
  NPHAND_THROW_CHECK(side == "left" || side == "right", where, ": hand must be \"left\", \"right\" or null, not '", side, "'");
  return side;
}

Eigen::Vector2d Centroid(const std::array<Eigen::Vector2d, kNumKeypoints>& points) {
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  for (const Eigen::Vector2d& p : points) sum += p;
  return sum / kNumKeypoints;
}

bool Inside(const Eigen::Vector2d& p, const std::array<double, 4>& box) {
  return box[0] <= p.x() && p.x() <= box[2] && box[1] <= p.y() && p.y() <= box[3];
}

// The mean normalised 2D error over the label's keypoints, or for a box the centroid's
// distance from the box centre, over the diagonal.
double Cost(const RealLabel& label, const PredictedHand& hand) {
  if (!label.labelled.empty()) {
    double sum = 0.0;
    for (int k : label.labelled) sum += (hand.keypoints_2d[k] - *label.keypoints_2d[k]).norm();
    return sum / label.labelled.size() / label.diag;
  }
  const Eigen::Vector2d centre((label.box[0] + label.box[2]) / 2, (label.box[1] + label.box[3]) / 2);
  return (Centroid(hand.keypoints_2d) - centre).norm() / label.diag;
}

// The one-to-one assignment of predicted hands to labelled hands with the most pairs, then
// the smallest summed cost: for each label the index of its hand, or -1. Exhaustive, in the
// reference's order (so ties go the same way); images hold a few hands.
std::vector<int> Match(const std::vector<const RealLabel*>& labels, const std::vector<PredictedHand>& hands) {
  const size_t n = labels.size();
  std::vector<std::vector<int>> eligible(n);
  std::vector<std::vector<double>> cost(n, std::vector<double>(hands.size(), 0.0));
  for (size_t i = 0; i < n; ++i) {
    for (size_t j = 0; j < hands.size(); ++j) {
      if (!Inside(Centroid(hands[j].keypoints_2d), labels[i]->region)) continue;
      eligible[i].push_back(static_cast<int>(j));
      cost[i][j] = Cost(*labels[i], hands[j]);
    }
  }
  std::vector<int> best, assign;
  int best_pairs = -1;
  double best_cost = 0.0;
  std::vector<bool> used(hands.size(), false);
  const auto search = [&](auto&& self, size_t i, int pairs, double total) -> void {
    if (i == n) {
      if (pairs > best_pairs || (pairs == best_pairs && -total > -best_cost)) {
        best_pairs = pairs;
        best_cost = total;
        best = assign;
      }
      return;
    }
    for (int j : eligible[i]) {
      if (used[j]) continue;
      used[j] = true;
      assign.push_back(j);
      self(self, i + 1, pairs + 1, total + cost[i][j]);
      assign.pop_back();
      used[j] = false;
    }
    assign.push_back(-1);
    self(self, i + 1, pairs, total);
    assign.pop_back();
  };
  search(search, 0, 0, 0.0);
  return best;
}

// How many of the four fingers' states agree.
int FingersAgreeing(const std::array<bool, 4>& a, const std::array<bool, 4>& b) {
  return static_cast<int>(std::inner_product(a.begin(), a.end(), b.begin(), 0, std::plus<>(), std::equal_to<>()));
}

std::optional<double> MeanOf(const std::vector<double>& values) {
  if (values.empty()) return std::nullopt;
  return std::accumulate(values.begin(), values.end(), 0.0) / values.size();
}

RealAggregate Aggregate(const std::vector<const RealHandScore*>& rows, int extra, int images) {
  RealAggregate a;
  a.hands = static_cast<int>(rows.size());
  a.images = images;
  a.extra = extra;
  std::vector<double> pck_01, pck_02, errors, errors_px, pa;
  double pck_01_all = 0.0, pck_02_all = 0.0;
  for (const RealHandScore* r : rows) {
    a.found += r->found;
    a.not_run += !r->run;
    if (!r->found) ++a.misses[r->miss];
    const bool keypoints = !r->label->labelled.empty();
    a.kp_hands += keypoints;
    if (r->label->source == "interhand" || r->label->source == "asl_video") ++a.hands_with_3d_label;
    if (keypoints && r->found) {
      ++a.kp_found;
      pck_01.push_back(*r->pck_01);
      pck_02.push_back(*r->pck_02);
      errors.push_back(*r->mean_norm_err);
      errors_px.push_back(*r->mean_err_px);
    }
    if (keypoints) {
      pck_01_all += r->pck_01.value_or(0.0);
      pck_02_all += r->pck_02.value_or(0.0);
    }
    if (r->found && r->handedness_ok.has_value()) {
      ++a.handedness_n;
      a.handedness_correct += *r->handedness_ok;
      if (r->label->hand_side_by == "source") {
        ++a.handedness_source_n;
        a.handedness_source_correct += *r->handedness_ok;
      }
    }
    if (r->found && r->pa_mpjpe_mm.has_value()) pa.push_back(*r->pa_mpjpe_mm);
    if (r->found && r->finger_agree.has_value()) {
      a.finger_agree += *r->finger_agree;
      a.finger_total += 4;
    }
    if (r->found && r->gesture_finger_agree.has_value()) {
      a.gesture_finger_agree += *r->gesture_finger_agree;
      a.gesture_finger_total += 4;
    }
    if (r->found && r->facing_ok.has_value()) {
      ++a.facing_n;
      a.facing_correct += *r->facing_ok;
    }
  }
  a.pck_01_found = MeanOf(pck_01);
  a.pck_02_found = MeanOf(pck_02);
  if (a.kp_hands > 0) {
    a.pck_01_all = pck_01_all / a.kp_hands;
    a.pck_02_all = pck_02_all / a.kp_hands;
  }
  a.mean_norm_err_found = MeanOf(errors);
  a.median_norm_err_found = TrueMedian(errors);
  a.mean_err_px_found = MeanOf(errors_px);
  a.pa_mpjpe_n = static_cast<int>(pa.size());
  a.pa_mpjpe_mm = MeanOf(pa);
  return a;
}

nlohmann::json Optional(const std::optional<double>& v) { return v.has_value() ? nlohmann::json(*v) : nlohmann::json(nullptr); }

nlohmann::json ToJson(const RealAggregate& a) {
  return {{"hands", a.hands},
          {"images", a.images},
          {"found", a.found},
          {"found_rate", Optional(a.found_rate())},
          {"misses", a.misses},
          {"not_run", a.not_run},
          {"extra_predictions", a.extra},
          {"kp_hands", a.kp_hands},
          {"kp_found", a.kp_found},
          {"pck@0.1_found", Optional(a.pck_01_found)},
          {"pck@0.1_all", Optional(a.pck_01_all)},
          {"pck@0.2_found", Optional(a.pck_02_found)},
          {"pck@0.2_all", Optional(a.pck_02_all)},
          {"mean_norm_err_found", Optional(a.mean_norm_err_found)},
          {"median_norm_err_found", Optional(a.median_norm_err_found)},
          {"mean_err_px_found", Optional(a.mean_err_px_found)},
          {"handedness_n", a.handedness_n},
          {"handedness_correct", a.handedness_correct},
          {"handedness_acc", a.handedness_n > 0 ? nlohmann::json(double(a.handedness_correct) / a.handedness_n) : nlohmann::json(nullptr)},
          {"handedness_source_labelled",
           std::to_string(a.handedness_source_correct) + "/" + std::to_string(a.handedness_source_n)},
          {"pa_mpjpe_n", a.pa_mpjpe_n},
          {"pa_mpjpe_hands_with_3d_label", a.hands_with_3d_label},
          {"pa_mpjpe_mm", Optional(a.pa_mpjpe_mm)},
          {"finger_agree", a.finger_agree},
          {"finger_total", a.finger_total},
          {"gesture_finger_agree", a.gesture_finger_agree},
          {"gesture_finger_total", a.gesture_finger_total},
          {"palm_back_n", a.facing_n},
          {"palm_back_correct", a.facing_correct}};
}

}  // namespace

std::optional<std::array<bool, 4>> RealGestureFingers(const std::string& gesture) {
  constexpr bool S = true, C = false;  // straight, curled: index, middle, ring, little
  static const std::map<std::string, std::array<bool, 4>> kFingers = {
      {"call", {C, C, C, S}},       {"dislike", {C, C, C, C}},   {"fist", {C, C, C, C}},
      {"four", {S, S, S, S}},       {"gun", {S, S, C, C}},       {"like", {C, C, C, C}},
      {"mid. finger", {C, S, C, C}}, {"mute", {S, C, C, C}},     {"ok", {C, S, S, S}},
      {"one", {S, C, C, C}},        {"palm", {S, S, S, S}},      {"peace", {S, S, C, C}},
      {"point", {S, C, C, C}},      {"Thumb_Up", {C, C, C, C}},
      {"peace inv.", {S, S, C, C}}, {"pinkie", {C, C, C, S}},    {"rock", {S, C, C, S}},
      {"stop", {S, S, S, S}},       {"stop inv.", {S, S, S, S}}, {"three", {S, S, S, C}},
      {"three2", {S, S, C, C}},     {"thumb index", {S, C, C, C}}, {"two up", {S, S, C, C}},
      {"two up inv.", {S, S, C, C}},
  };
  const auto it = kFingers.find(gesture);
  return it == kFingers.end() ? std::nullopt : std::optional(it->second);
}

std::string RealSourceOf(const std::string& file) {
  const std::string base = std::filesystem::path(file).filename().string();
  if (file.rfind("videos/", 0) == 0 || base.rfind("asl_hand", 0) == 0) return "asl_video";
  for (const char* source : {"freihand", "onehand10k", "panoptic", "interhand", "hagrid", "tfjs_hands", "mediapipe_thumbs_up"}) {
    if (base.rfind(source, 0) == 0) return source;
  }
  return "other";
}

bool IsGroundTruthSource(const std::string& source) {
  return std::find(kGroundTruthSources.begin(), kGroundTruthSources.end(), source) != kGroundTruthSources.end();
}

std::vector<RealLabel> ReadRealLabels(const std::filesystem::path& path) {
  std::vector<RealLabel> labels;
  for (const auto& [line, j] : ReadJsonLines(path)) {
    const std::string where = path.string() + ": line " + std::to_string(line);
    RealLabel label;
    label.line = line - 1;
    NPHAND_THROW_CHECK(j.contains("file") && j["file"].is_string() && !j["file"].get<std::string>().empty(), where,
                       ": no 'file'");
    label.file = j["file"].get<std::string>();
    if (j.contains("frame") && !j["frame"].is_null()) {
      NPHAND_THROW_CHECK(j["frame"].is_number_integer() && j["frame"].get<int64_t>() >= 0, where,
                         ": 'frame' must be a frame number (0 or more)");
      label.frame = j["frame"].get<int>();
    }
    label.source = RealSourceOf(label.file);
    label.hand = Side(j.value("hand", nlohmann::json()), where);
    if (j.contains("hand_side_by") && j["hand_side_by"].is_string()) label.hand_side_by = j["hand_side_by"].get<std::string>();
    if (j.contains("gesture") && j["gesture"].is_string()) label.gesture = j["gesture"].get<std::string>();
    if (j.contains("keypoints_2d_px") && !j["keypoints_2d_px"].is_null()) {
      label.keypoints_2d = Points2(j["keypoints_2d_px"], true, where);
      for (int k = 0; k < kNumKeypoints; ++k) {
        if (label.keypoints_2d[k].has_value()) label.labelled.push_back(k);
      }
    }
    if (j.contains("keypoints_3d_camera_m") && !j["keypoints_3d_camera_m"].is_null()) {
      label.keypoints_3d = Points3(j["keypoints_3d_camera_m"], "keypoints_3d_camera_m", where);
    } else if (j.contains("keypoints_3d_world_m") && !j["keypoints_3d_world_m"].is_null()) {
      label.keypoints_3d = Points3(j["keypoints_3d_world_m"], "keypoints_3d_world_m", where);
      label.world_3d = true;
    }
    if (!label.labelled.empty()) {
      label.box = {1e300, 1e300, -1e300, -1e300};
      for (int k : label.labelled) {
        const Eigen::Vector2d& p = *label.keypoints_2d[k];
        label.box = {std::min(label.box[0], p.x()), std::min(label.box[1], p.y()), std::max(label.box[2], p.x()),
                     std::max(label.box[3], p.y())};
      }
    } else {
      const nlohmann::json box = j.value("bbox_px", nlohmann::json());
      NPHAND_THROW_CHECK(box.is_array() && box.size() == 4 && std::all_of(box.begin(), box.end(), IsNumber), where,
                         ": has neither keypoints_2d_px nor bbox_px [x_min, y_min, x_max, y_max]");
      for (int c = 0; c < 4; ++c) label.box[c] = box[c].get<double>();
    }
    label.diag = std::hypot(label.box[2] - label.box[0], label.box[3] - label.box[1]);
    NPHAND_THROW_CHECK(label.diag > 0.0, where, ": the hand's box is empty");
    const double w = label.box[2] - label.box[0], h = label.box[3] - label.box[1];
    label.region = {label.box[0] - kGrow * w, label.box[1] - kGrow * h, label.box[2] + kGrow * w, label.box[3] + kGrow * h};
    labels.push_back(std::move(label));
  }
  NPHAND_THROW_CHECK(!labels.empty(), path.string(), ": no labels");
  return labels;
}

nlohmann::json ToJson(const RealPrediction& prediction) {
  nlohmann::json hands = nlohmann::json::array();
  for (const PredictedHand& hand : prediction.hands) {
    nlohmann::json h;
    for (const Eigen::Vector2d& p : hand.keypoints_2d) h["keypoints_2d_px"].push_back({p.x(), p.y()});
    if (hand.keypoints_3d.has_value()) {
      for (const Eigen::Vector3d& p : *hand.keypoints_3d) h["keypoints_3d"].push_back({p.x(), p.y(), p.z()});
    }
    h["hand"] = hand.hand.empty() ? nlohmann::json(nullptr) : nlohmann::json(hand.hand);
    hands.push_back(h);
  }
  return {{"file", prediction.file},
          {"frame", prediction.frame.has_value() ? nlohmann::json(*prediction.frame) : nlohmann::json(nullptr)},
          {"hands", hands},
          {"ms", prediction.ms.has_value() ? nlohmann::json(*prediction.ms) : nlohmann::json(nullptr)}};
}

std::vector<RealPrediction> ReadRealPredictions(const std::filesystem::path& path, const std::vector<RealLabel>& labels) {
  std::set<std::string> files;
  std::map<std::string, std::string> by_stem;  // stills
  for (const RealLabel& label : labels) {
    files.insert(label.file);
    if (!label.frame.has_value()) by_stem.emplace(Stem(label.file), label.file);
  }
  std::vector<RealPrediction> predictions;
  std::set<std::pair<std::string, int>> seen;
  for (const auto& [line, j] : ReadJsonLines(path)) {
    const std::string where = path.string() + ": line " + std::to_string(line);
    RealPrediction p;
    NPHAND_THROW_CHECK(j.contains("file") && j["file"].is_string(), where, ": no 'file'");
    const std::string file = j["file"].get<std::string>();
    if (j.contains("frame") && !j["frame"].is_null()) {
      NPHAND_THROW_CHECK(j["frame"].is_number_integer(), where, ": 'frame' must be a frame number");
      p.frame = j["frame"].get<int>();
      p.file = files.count(file) ? file : "videos/" + std::filesystem::path(file).filename().string();
    } else if (files.count(file)) {
      p.file = file;
    } else {
      const auto it = by_stem.find(Stem(file));
      NPHAND_THROW_CHECK(it != by_stem.end(), where, ": file '", file, "' matches no labelled image");
      p.file = it->second;
    }
    NPHAND_THROW_CHECK(seen.insert(p.key()).second, where, ": a second prediction for ", p.file,
                       p.frame.has_value() ? " frame " + std::to_string(*p.frame) : std::string());
    if (j.contains("hands") && !j["hands"].is_null()) {
      NPHAND_THROW_CHECK(j["hands"].is_array(), where, ": 'hands' must be a list");
      for (const nlohmann::json& h : j["hands"]) {
        NPHAND_THROW_CHECK(h.is_object() && h.contains("keypoints_2d_px"), where,
                           ": every hand needs keypoints_2d_px with 21 [x, y] entries");
        PredictedHand hand;
        const auto points = Points2(h["keypoints_2d_px"], false, where);
        for (int k = 0; k < kNumKeypoints; ++k) hand.keypoints_2d[k] = *points[k];
        if (h.contains("keypoints_3d") && !h["keypoints_3d"].is_null()) hand.keypoints_3d = Points3(h["keypoints_3d"], "keypoints_3d", where);
        hand.hand = Side(h.value("hand", nlohmann::json()), where);
        p.hands.push_back(std::move(hand));
      }
    }
    if (j.contains("ms") && IsNumber(j["ms"])) p.ms = j["ms"].get<double>();
    predictions.push_back(std::move(p));
  }
  return predictions;
}

RealScore ScoreReal(const std::vector<RealLabel>& labels, const std::vector<RealPrediction>& predictions) {
  // Images in the order of their first label, as the reference's dict keeps them.
  std::vector<std::pair<std::string, int>> order;
  std::map<std::pair<std::string, int>, std::vector<const RealLabel*>> by_image;
  for (const RealLabel& label : labels) {
    auto [it, fresh] = by_image.try_emplace(label.key());
    if (fresh) order.push_back(label.key());
    it->second.push_back(&label);
  }
  std::map<std::pair<std::string, int>, const RealPrediction*> by_key;
  for (const RealPrediction& p : predictions) {
    NPHAND_THROW_CHECK(by_image.count(p.key()), "a prediction for an image with no label: ", p.file,
                       p.frame.has_value() ? " frame " + std::to_string(*p.frame) : std::string());
    by_key[p.key()] = &p;
  }
  RealScore score;
  std::vector<std::pair<std::string, int>> extra_keys;
  for (const auto& key : order) {
    const std::vector<const RealLabel*>& image = by_image[key];
    const auto found = by_key.find(key);
    const RealPrediction* prediction = found == by_key.end() ? nullptr : found->second;
    static const std::vector<PredictedHand> kNone;
    const std::vector<PredictedHand>& hands = prediction != nullptr ? prediction->hands : kNone;
    const std::vector<int> assign = Match(image, hands);
    // Each estimate that found nothing answers for one hand not found of its side.
    std::vector<bool> miss_used(prediction != nullptr ? prediction->missed.size() : 0, false);
    for (size_t i = 0; i < image.size(); ++i) {
      const RealLabel& label = *image[i];
      RealHandScore r;
      r.label = &label;
      r.hands_in_image = static_cast<int>(image.size());
      r.run = prediction != nullptr;
      r.found = assign[i] >= 0;
      if (!r.found && prediction == nullptr) {
        r.miss = "not_run";
      } else if (!r.found) {
        const std::vector<RealPrediction::Miss>& missed = prediction->missed;
        size_t m = 0;
        while (m < missed.size() && (miss_used[m] || !(missed[m].hand.empty() || missed[m].hand == label.hand))) ++m;
        if (m < missed.size()) {
          miss_used[m] = true;
          r.miss = missed[m].status;
          r.miss_reason = missed[m].reason;
        } else {
          r.miss = hands.empty() ? "no_hand" : "elsewhere";
        }
      } else {
        const PredictedHand& hand = hands[assign[i]];
        r.keypoints_2d = hand.keypoints_2d;
        if (!hand.hand.empty()) r.handedness_ok = hand.hand == label.hand;
        if (!label.labelled.empty()) {
          std::vector<double> e;
          for (int k : label.labelled) e.push_back((hand.keypoints_2d[k] - *label.keypoints_2d[k]).norm() / label.diag);
          const double mean = std::accumulate(e.begin(), e.end(), 0.0) / e.size();
          r.mean_norm_err = mean;
          r.mean_err_px = mean * label.diag;
          r.pck_01 = static_cast<double>(std::count_if(e.begin(), e.end(), [](double v) { return v < 0.1; })) / e.size();
          r.pck_02 = static_cast<double>(std::count_if(e.begin(), e.end(), [](double v) { return v < 0.2; })) / e.size();
        }
        const Facing truth = FacingOf(label.keypoints_2d, label.hand);
        if (truth != Facing::kUnknown) r.facing_ok = FacingOf(hand.keypoints_2d, hand.hand.empty() ? label.hand : hand.hand) == truth;
        if (hand.keypoints_3d.has_value() && label.keypoints_3d.has_value()) {
          r.pa_mpjpe_mm = 1000.0 * ProcrustesError(*hand.keypoints_3d, *label.keypoints_3d);
          r.finger_agree = FingersAgreeing(FingerStates(*label.keypoints_3d), FingerStates(*hand.keypoints_3d));
        }
        const std::optional<std::array<bool, 4>> shown = RealGestureFingers(label.gesture);
        if (shown.has_value() && hand.keypoints_3d.has_value()) {
          r.gesture_finger_agree = FingersAgreeing(*shown, FingerStates(*hand.keypoints_3d));
        }
      }
      score.hands.push_back(r);
    }
    for (size_t j = 0; j < hands.size(); ++j) {
      if (std::find(assign.begin(), assign.end(), static_cast<int>(j)) == assign.end()) score.extras.push_back(key);
    }
  }
  // Aggregates over a set of hands, with the extra hands of their images.
  const auto aggregate = [&](const auto& keep, bool count_files) {
    std::vector<const RealHandScore*> rows;
    std::set<std::pair<std::string, int>> images;
    std::set<std::string> files;
    for (const RealHandScore& r : score.hands) {
      if (!keep(r)) continue;
      rows.push_back(&r);
      images.insert(r.label->key());
      files.insert(r.label->file);
    }
    const int extra = static_cast<int>(std::count_if(score.extras.begin(), score.extras.end(),
                                                     [&](const auto& key) { return images.count(key) > 0; }));
    return Aggregate(rows, extra, static_cast<int>(count_files ? files.size() : images.size()));
  };
  for (const char* source : {"freihand", "onehand10k", "panoptic", "interhand", "hagrid", "tfjs_hands", "mediapipe_thumbs_up",
                             "asl_video"}) {
    const auto keep = [&](const RealHandScore& r) { return r.label->source == source; };
    if (std::any_of(score.hands.begin(), score.hands.end(), keep)) score.per_source[source] = aggregate(keep, false);
  }
  const auto gt = [](const RealHandScore& r) { return IsGroundTruthSource(r.label->source); };
  score.gt_all = aggregate(gt, false);
  score.gt_one_hand = aggregate([&](const RealHandScore& r) { return gt(r) && r.hands_in_image == 1; }, true);
  score.gt_two_hand = aggregate([&](const RealHandScore& r) { return gt(r) && r.hands_in_image >= 2; }, true);
  // Each video's steadiness, by side, in frame order.
  std::map<std::pair<std::string, std::string>, std::vector<const RealHandScore*>> tracks;
  for (const RealHandScore& r : score.hands) {
    if (r.label->frame.has_value()) tracks[{r.label->file, r.label->hand}].push_back(&r);
  }
  for (auto& [key, rows] : tracks) {
    std::stable_sort(rows.begin(), rows.end(),
                     [](const RealHandScore* a, const RealHandScore* b) { return *a->label->frame < *b->label->frame; });
    RealSteadiness s;
    s.file = key.first;
    s.hand = key.second;
    s.frames = static_cast<int>(rows.size());
    double jitter = 0.0, label_jitter = 0.0;
    for (size_t t = 1; t + 1 < rows.size(); ++t) {
      const RealHandScore &a = *rows[t - 1], &b = *rows[t], &c = *rows[t + 1];
      if (!a.found || !b.found || !c.found || *a.label->frame + 1 != *b.label->frame || *b.label->frame + 1 != *c.label->frame) {
        continue;
      }
      double sum = 0.0, label_sum = 0.0;
      int n = 0;
      for (int k = 0; k < kNumKeypoints; ++k) {
        if (!a.label->keypoints_2d[k] || !b.label->keypoints_2d[k] || !c.label->keypoints_2d[k]) continue;
        sum += ((*c.keypoints_2d)[k] - 2.0 * (*b.keypoints_2d)[k] + (*a.keypoints_2d)[k]).norm();
        label_sum += (*c.label->keypoints_2d[k] - 2.0 * *b.label->keypoints_2d[k] + *a.label->keypoints_2d[k]).norm();
        ++n;
      }
      if (n == 0) continue;
      jitter += sum / n / b.label->diag;
      label_jitter += label_sum / n / b.label->diag;
      ++s.second_differences;
    }
    if (s.second_differences > 0) {
      s.jitter = jitter / s.second_differences;
      s.label_jitter = label_jitter / s.second_differences;
    }
    score.videos.push_back(s);
  }
  std::vector<double> stills, video;
  for (const RealPrediction& p : predictions) {
    if (p.ms.has_value()) (p.frame.has_value() ? video : stills).push_back(*p.ms);
  }
  score.stills_median_ms = TrueMedian(stills);
  score.video_median_ms = TrueMedian(video);
  return score;
}

nlohmann::json ToJson(const RealScore& score) {
  nlohmann::json per_source = nlohmann::json::object();
  for (const auto& [source, a] : score.per_source) per_source[source] = ToJson(a);
  nlohmann::json hands = nlohmann::json::array();
  for (const RealHandScore& r : score.hands) {
    nlohmann::json h = {{"file", r.label->file},
                        {"frame", r.label->frame.has_value() ? nlohmann::json(*r.label->frame) : nlohmann::json(nullptr)},
                        {"line", r.label->line},
                        {"source", r.label->source},
                        {"hand", r.label->hand},
                        {"labelled_hands_in_image", r.hands_in_image},
                        {"run", r.run},
                        {"found", r.found}};
    if (!r.found) {
      h["miss"] = r.miss;
      if (!r.miss_reason.empty()) h["miss_reason"] = r.miss_reason;
    } else {
      const Eigen::Vector2d centroid = Centroid(*r.keypoints_2d);
      h["pred_centroid"] = {centroid.x(), centroid.y()};
      h["handedness_ok"] = r.handedness_ok.has_value() ? nlohmann::json(*r.handedness_ok) : nlohmann::json(nullptr);
      if (r.mean_norm_err.has_value()) {
        h["mean_norm_err"] = *r.mean_norm_err;
        h["mean_err_px"] = *r.mean_err_px;
        h["pck@0.1"] = *r.pck_01;
        h["pck@0.2"] = *r.pck_02;
      }
      if (r.pa_mpjpe_mm.has_value()) {
        h["pa_mpjpe_mm"] = *r.pa_mpjpe_mm;
        h["pa_ref"] = r.label->world_3d ? "keypoints_3d_world_m (MediaPipe output)" : "keypoints_3d_camera_m";
        h["finger_agree"] = *r.finger_agree;
      }
      if (r.gesture_finger_agree.has_value()) h["gesture_finger_agree"] = *r.gesture_finger_agree;
      h["palm_back_ok"] = r.facing_ok.has_value() ? nlohmann::json(*r.facing_ok) : nlohmann::json(nullptr);
    }
    hands.push_back(h);
  }
  nlohmann::json videos = nlohmann::json::array();
  for (const RealSteadiness& s : score.videos) {
    videos.push_back({{"file", s.file},
                      {"hand", s.hand},
                      {"frames", s.frames},
                      {"second_differences", s.second_differences},
                      {"jitter_diag", Optional(s.jitter)},
                      {"label_jitter_diag", Optional(s.label_jitter)}});
  }
  return {{"per_source", per_source},
          {"overall",
           {{"gt_all", ToJson(score.gt_all)},
            {"gt_one_hand_images", ToJson(score.gt_one_hand)},
            {"gt_two_hand_images", ToJson(score.gt_two_hand)}}},
          {"videos", videos},
          {"timing", {{"stills_median_ms", Optional(score.stills_median_ms)}, {"video_median_ms", Optional(score.video_median_ms)}}},
          {"per_hand", hands}};
}

std::string FormatTable(const RealScore& score) {
  std::ostringstream out;
  const auto figure = [](const std::optional<double>& v, int precision = 3) {
    if (!v.has_value()) return std::string("-");
    std::ostringstream s;
    s << std::fixed << std::setprecision(precision) << *v;
    return s.str();
  };
  out << std::left << std::setw(20) << "source" << std::right << std::setw(6) << "hands" << std::setw(12) << "found"
      << std::setw(10) << "PCK.1 fnd" << std::setw(10) << "PCK.2 fnd" << std::setw(10) << "PCK.2 all" << std::setw(9)
      << "err/diag" << std::setw(11) << "handed." << std::setw(18) << "PA-MPJPE" << std::setw(10) << "fingers" << std::setw(10)
      << "palm/back" << std::setw(10) << "gesture" << std::setw(6) << "extra" << "\n";
  const auto row = [&](const std::string& name, const RealAggregate& a) {
    const std::string found = std::to_string(a.found) + " " + figure(a.found_rate().has_value() ? std::optional(100.0 * *a.found_rate()) : std::nullopt, 0) + "%";
    const std::string handed = a.handedness_n > 0 ? std::to_string(a.handedness_correct) + "/" + std::to_string(a.handedness_n) : "-";
    const std::string pa = a.pa_mpjpe_mm.has_value() ? figure(a.pa_mpjpe_mm, 1) + " (" + std::to_string(a.pa_mpjpe_n) + "/" +
                                                           std::to_string(a.hands_with_3d_label) + ")"
                                                     : "-";
    const std::string fingers = a.finger_total > 0 ? std::to_string(a.finger_agree) + "/" + std::to_string(a.finger_total) : "-";
    const std::string facing = a.facing_n > 0 ? std::to_string(a.facing_correct) + "/" + std::to_string(a.facing_n) : "-";
    const std::string gesture = a.gesture_finger_total > 0
                                    ? std::to_string(a.gesture_finger_agree) + "/" + std::to_string(a.gesture_finger_total)
                                    : "-";
    out << std::left << std::setw(20) << name << std::right << std::setw(6) << a.hands << std::setw(12) << found << std::setw(10)
        << figure(a.pck_01_found) << std::setw(10) << figure(a.pck_02_found) << std::setw(10) << figure(a.pck_02_all)
        << std::setw(9) << figure(a.mean_norm_err_found) << std::setw(11) << handed << std::setw(18) << pa << std::setw(10)
        << fingers << std::setw(10) << facing << std::setw(10) << gesture << std::setw(6) << a.extra << "\n";
  };
  out << "-- ground-truth labels\n";
  for (const char* source : kGroundTruthSources) {
    if (score.per_source.count(source)) row(source, score.per_source.at(source));
  }
  row("GT overall", score.gt_all);
  row(" in 1-hand images", score.gt_one_hand);
  row(" in 2-hand images", score.gt_two_hand);
  out << "-- labels that are MediaPipe's own outputs (agreement with MediaPipe, not accuracy)\n";
  for (const char* source : kMediaPipeSources) {
    if (score.per_source.count(source)) row(source, score.per_source.at(source));
  }
  // Why the ground-truth hands not found were not.
  for (const auto& [name, a] : {std::pair<const char*, const RealAggregate&>{"GT overall", score.gt_all},
                                {"1-hand images", score.gt_one_hand}}) {
    if (a.misses.empty()) continue;
    out << "not found, " << name << ":";
    const char* separator = " ";
    for (const auto& [miss, n] : a.misses) {
      out << separator << miss << " " << n;
      separator = ", ";
    }
    out << "\n";
  }
  for (const RealSteadiness& s : score.videos) {
    out << "steadiness, " << s.file << " (" << s.hand << "): 2D jitter " << figure(s.jitter, 4)
        << " of the hand box's diagonal per frame^2, the labels' own " << figure(s.label_jitter, 4) << " (" << s.second_differences
        << " second differences over runs of found frames, of " << s.frames << " frames)\n";
  }
  out << "timing: stills median " << figure(score.stills_median_ms, 1) << " ms, video frames median "
      << figure(score.video_median_ms, 1) << " ms\n";
  return out.str();
}

}  // namespace nphand
