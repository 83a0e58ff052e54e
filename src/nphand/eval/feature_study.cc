#include "nphand/eval/feature_study.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <map>
#include <numbers>
#include <sstream>

#include <opencv2/imgproc.hpp>

#include "nphand/features/crop.h"
#include "nphand/features/distance.h"
#include "nphand/index/exact_index.h"
#include "nphand/util/check.h"
#include "nphand/util/parallel.h"
#include "nphand/util/random.h"

namespace nphand {
namespace {

constexpr double kDegPerRad = 180.0 / std::numbers::pi;
constexpr int kRerank = 200;  // HOG candidates that chamfer re-ranks

// The paper's Fig. 4 table: average joint error (degrees) at neighbours 1, 2, 5, 10.
const std::map<std::string, std::vector<double>>& PaperFigures() {
  static const std::map<std::string, std::vector<double>> kFigures = {
      {"joints", {0.61, 0.87, 1.42, 1.87}},       {"hog8x8x8", {1.32, 2.04, 3.25, 4.19}},
      {"hog8x8x8_pyr", {1.29, 1.99, 3.20, 4.14}}, {"hog8x8x4", {7.59, 8.27, 9.07, 9.99}},
      {"hog8x8x8_nh", {3.57, 5.05, 7.03, 8.27}},  {"hog8x8x16", {1.42}},
      {"hog4x4x8", {1.57}},                       {"hog16x16x8", {1.39}},
      {"dist32", {1.64}},                         {"chamfer_rerank", {2.07}},
  };
  return kFigures;
}

// A crop kept as 8-bit coverage (a quarter of the float's memory: 0.9 GB for the default
// database), turned back into CV_32FC1 coverage where a feature needs it.
struct StudyCrop {
  cv::Mat coverage;  // CV_8UC1 64 x 64, 255 = hand
  double roll = 0.0;
  cv::Mat image() const {
    cv::Mat image;
    coverage.convertTo(image, CV_32FC1, 1.0 / 255.0);
    return image;
  }
};

StudyCrop Recrop(const cv::Mat& mask, double margin, bool normalize_roll, size_t entry) {
  const std::optional<HandCrop> crop = CropHand(mask, {kCropBitsSide, margin, normalize_roll});
  NPHAND_THROW_CHECK(crop.has_value(), "feature study: database entry ", entry, " has a hand but an empty crop");
  StudyCrop study;
  crop->image.convertTo(study.coverage, CV_8UC1, 255.0);
  study.roll = crop->roll;
  return study;
}

std::vector<float> Describe(const StudyFeature& feature, const cv::Mat& crop) {
  return feature.kind == StudyFeature::Kind::kDistance ? DistanceTransformFeature(crop, 32) : ComputeHog(crop, feature.hog);
}

// A query's nearest candidates so far: (distance, candidate), sorted, at most `fetch`.
using Nearest = std::vector<std::pair<float, size_t>>;

// Adds one chunk's search results (candidate positions from `first`) to each query's list.
void MergeNearest(const std::vector<float>& distances, const std::vector<int64_t>& labels, int found,
                  size_t first, int fetch, std::vector<Nearest>* nearest) {
  for (size_t q = 0; q < nearest->size(); ++q) {
    Nearest& list = (*nearest)[q];
    for (int r = 0; r < found; ++r) {
      if (labels[q * found + r] >= 0) list.emplace_back(distances[q * found + r], first + labels[q * found + r]);
    }
    const size_t keep = std::min<size_t>(fetch, list.size());
    std::partial_sort(list.begin(), list.begin() + keep, list.end());
    list.resize(keep);
  }
}

// Reorders each query's list by symmetric chamfer distance between contours.
void RerankByChamfer(const Database& db, const std::vector<size_t>& candidates, double margin, bool normalize_roll,
                     const std::vector<StudyCrop>& query_crops, std::vector<Nearest>* nearest) {
  ParallelFor(query_crops.size(), 0, [&](size_t q, int) {
    const cv::Mat query_edges = EdgeMap(query_crops[q].image());
    const cv::Mat query_distance = ContourDistance(query_edges);
    for (auto& [distance, c] : (*nearest)[q]) {
      const cv::Mat edges = EdgeMap(Recrop(db.Crop(candidates[c]), margin, normalize_roll, candidates[c]).image());
      distance = static_cast<float>(
          0.5 * (ChamferDistance(query_edges, ContourDistance(edges)) + ChamferDistance(edges, query_distance)));
    }
    std::stable_sort((*nearest)[q].begin(), (*nearest)[q].end());
  });
}

}  // namespace

std::vector<StudyFeature> PaperFeatures() {
  using K = StudyFeature::Kind;
  const auto hog = [](int cells, int bins, bool pyramid = false, HogNormalization n = HogNormalization::kGlobalL2) {
    HogOptions o;
    o.cells = cells;
    o.bins = bins;
    o.pyramid = pyramid;
    o.normalization = n;
    return StudyFeature{o.Name(), K::kHog, o};
  };
  return {{"joints", K::kJoints, {}},
          hog(8, 8),
          hog(8, 4),
          hog(8, 16),
          hog(4, 8),
          hog(16, 8),
          hog(8, 8, true),
          hog(8, 8, false, HogNormalization::kCellSum),
          {"dist32", K::kDistance, {}},
          {"chamfer_rerank", K::kChamferRerank, {}}};
}

bool FeatureStudyOptions::Check(std::string* why) const {
  if (queries < 1 || neighbours < 1 || neighbours > 1000 || chunk < 1) {
    *why = "the study needs at least one query, 1 to 1000 neighbours and a chunk of at least one entry";
    return false;
  }
  for (const std::string& name : features) {
    const auto all = PaperFeatures();
    if (std::none_of(all.begin(), all.end(), [&](const StudyFeature& f) { return f.name == name; })) {
      *why = "unknown feature '" + name + "'";
      return false;
    }
  }
  return true;
}

FeatureStudyResult RunFeatureStudy(const Database& db, const FeatureStudyOptions& options, std::ostream* progress) {
  std::string why;
  NPHAND_THROW_CHECK(options.Check(&why), "feature study: ", why);
  const auto start = std::chrono::steady_clock::now();
  FeatureStudyResult result;
  result.options = options;

  std::vector<size_t> candidates;
  for (size_t i = 0; i < db.size(); ++i) {
    if (db.Meta(i).has_hand) candidates.push_back(i);
  }
  result.candidates = candidates.size();
  NPHAND_THROW_CHECK(candidates.size() > static_cast<size_t>(options.neighbours) + 2,
                     "feature study: the database has too few entries with a hand");
  NPHAND_THROW_CHECK(static_cast<size_t>(options.queries) <= candidates.size(), "feature study: ", options.queries,
                     " queries asked, but the database has only ", candidates.size(), " entries with a hand");

  // Queries: a seeded sample of the candidates (positions in `candidates`), each with a roll.
  Random random(options.seed);
  std::vector<size_t> order(candidates.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  const size_t query_count = options.queries;
  for (size_t i = 0; i < query_count; ++i) std::swap(order[i], order[i + random.UniformIndex(order.size() - i)]);
  std::vector<size_t> queries(order.begin(), order.begin() + query_count);
  std::vector<double> query_turn(query_count, 0.0);
  for (double& turn : query_turn) turn = options.roll_queries ? random.Uniform(-std::numbers::pi, std::numbers::pi) : 0.0;

  // The crops of the (turned) queries, as the study sees them.
  const double margin = db.descriptor().crop_margin;
  std::vector<StudyCrop> query_crops(query_count);
  ParallelFor(query_count, 0, [&](size_t q, int) {
    const size_t entry = candidates[queries[q]];
    const cv::Mat mask = db.Crop(entry);
    query_crops[q] =
        Recrop(query_turn[q] == 0.0 ? mask : RotateMask(mask, query_turn[q]), margin, options.normalize_roll, entry);
  });

  // The truth of each query: its joint angles and its (turned) camera rotation. Turning the
  // image content counter-clockwise by a is rolling the camera by -a about its z axis.
  const auto camera_roll = [](double angle) { return AxisAngle(Eigen::Vector3d::UnitZ(), angle); };
  std::vector<Eigen::Matrix3d> query_rotation(query_count);
  for (size_t q = 0; q < query_count; ++q) {
    query_rotation[q] = camera_roll(-query_turn[q]) *
                        FromPoseVector(db.Pose(candidates[queries[q]]), Handedness::kRight).camera_from_hand;
  }

  // Each feature's query vectors and, per query, its nearest candidates so far.
  struct Search {
    StudyFeature feature;
    int dimension = 0;
    int fetch = 0;  // neighbours kept: K and room for the query and its twin, or the re-ranked list
    std::vector<float> probe;
    std::vector<Nearest> nearest;
  };
  const int k = options.neighbours;
  const auto pose_row = [](const PoseVector& pose, float* row) {
    for (int d = 0; d < kPoseVectorSize; ++d) row[d] = static_cast<float>(pose[d]);
  };
  std::vector<Search> searches;
  for (const StudyFeature& feature : PaperFeatures()) {
    if (!options.features.empty() &&
        std::find(options.features.begin(), options.features.end(), feature.name) == options.features.end()) {
      continue;
    }
    Search search;
    search.feature = feature;
    const bool rerank = feature.kind == StudyFeature::Kind::kChamferRerank;
    search.fetch = static_cast<int>(std::min<size_t>(rerank ? std::max(kRerank, k + 4) : k + 4, candidates.size()));
    search.nearest.resize(query_count);
    if (feature.kind == StudyFeature::Kind::kJoints) {
      search.dimension = kPoseVectorSize;
      search.probe.resize(query_count * kPoseVectorSize);
      for (size_t q = 0; q < query_count; ++q) {
        HandPose truth = FromPoseVector(db.Pose(candidates[queries[q]]), Handedness::kRight);
        truth.camera_from_hand = query_rotation[q];
        pose_row(ToPoseVector(truth), search.probe.data() + q * kPoseVectorSize);
      }
    } else {
      search.dimension = static_cast<int>(Describe(feature, query_crops[0].image()).size());
      search.probe.resize(query_count * search.dimension);
      ParallelFor(query_count, 0, [&](size_t q, int) {
        const std::vector<float> v = Describe(feature, query_crops[q].image());
        std::copy(v.begin(), v.end(), search.probe.begin() + q * search.dimension);
      });
    }
    searches.push_back(std::move(search));
  }

  // Exact search over the candidates a chunk at a time: only a chunk's crops and features
  // are in memory, however many entries the database holds.
  std::vector<double> candidate_roll(candidates.size(), 0.0);
  std::vector<StudyCrop> crops;
  std::vector<float> base, distances;
  std::vector<int64_t> labels;
  for (size_t first = 0; first < candidates.size(); first += options.chunk) {
    const size_t count = std::min(options.chunk, candidates.size() - first);
    if (progress != nullptr) {
      *progress << "\rfeature study: searching entries " << first + count << "/" << candidates.size() << std::flush;
    }
    crops.assign(count, {});
    ParallelFor(count, 0, [&](size_t c, int) {
      const size_t entry = candidates[first + c];
      crops[c] = Recrop(db.Crop(entry), margin, options.normalize_roll, entry);
      candidate_roll[first + c] = crops[c].roll;
    });
    for (Search& search : searches) {
      base.resize(count * search.dimension);
      if (search.feature.kind == StudyFeature::Kind::kJoints) {
        for (size_t c = 0; c < count; ++c) pose_row(db.Pose(candidates[first + c]), base.data() + c * kPoseVectorSize);
      } else {
        ParallelFor(count, 0, [&](size_t c, int) {
          const std::vector<float> v = Describe(search.feature, crops[c].image());
          std::copy(v.begin(), v.end(), base.begin() + c * search.dimension);
        });
      }
      const int found = static_cast<int>(std::min<size_t>(search.fetch, count));
      distances.resize(query_count * found);
      labels.resize(query_count * found);
      BatchNearestRows(base, search.probe, search.dimension, found, distances.data(), labels.data());
      MergeNearest(distances, labels, found, first, search.fetch, &search.nearest);
    }
  }
  if (progress != nullptr) *progress << "\n";

  for (Search& search : searches) {
    const StudyFeature& feature = search.feature;
    if (feature.kind == StudyFeature::Kind::kChamferRerank) {
      RerankByChamfer(db, candidates, margin, options.normalize_roll, query_crops, &search.nearest);
    }
    FeatureCurve curve;
    curve.name = feature.name;
    curve.dimension = search.dimension;
    std::vector<double> joint_sum(k, 0.0), wrist_sum(k, 0.0);
    for (size_t q = 0; q < query_count; ++q) {
      const size_t query_entry = candidates[queries[q]];
      const EntryMeta query_meta = db.Meta(query_entry);
      const JointAngles query_angles = db.Angles(query_entry);
      double joint_total = 0.0, wrist_total = 0.0;
      int found = 0;
      for (size_t r = 0; r < search.nearest[q].size() && found < k; ++r) {
        const size_t c = search.nearest[q][r].second;
        const size_t entry = candidates[c];
        const EntryMeta meta = db.Meta(entry);
        if (meta.grasp == query_meta.grasp && meta.step == query_meta.step && meta.viewpoint == query_meta.viewpoint) {
          continue;  // the query itself or its twin
        }
        const JointAngles angles = db.Angles(entry);
        double joint = 0.0;
        for (int d = 0; d < kNumDofs; ++d) joint += std::abs(angles[d] - query_angles[d]);
        Eigen::Matrix3d rotation = FromPoseVector(db.Pose(entry), Handedness::kRight).camera_from_hand;
        if (options.normalize_roll && feature.kind != StudyFeature::Kind::kJoints) {
          rotation = camera_roll(query_crops[q].roll - candidate_roll[c]) * rotation;  // undo the alignment
        }
        joint_total += joint / kNumDofs * kDegPerRad;
        wrist_total += RotationAngleDeg(rotation, query_rotation[q]);
        joint_sum[found] += joint_total / (found + 1);
        wrist_sum[found] += wrist_total / (found + 1);
        ++found;
      }
      NPHAND_THROW_CHECK(found == k, "feature study: fewer than ", k, " neighbours of entry ", query_entry,
                         " are left after removing it and its twin");
    }
    for (int i = 0; i < k; ++i) {
      curve.joint_deg.push_back(joint_sum[i] / query_count);
      curve.wrist_deg.push_back(wrist_sum[i] / query_count);
    }
    if (progress != nullptr) {
      *progress << "feature study: " << std::setw(14) << std::left << curve.name << " neighbour 1: " << std::fixed
                << std::setprecision(2) << curve.joint_deg[0] << " deg joints, " << curve.wrist_deg[0] << " deg wrist\n";
    }
    result.curves.push_back(std::move(curve));
  }
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

nlohmann::json ToJson(const FeatureStudyResult& result) {
  nlohmann::json curves = nlohmann::json::array();
  for (const FeatureCurve& c : result.curves) {
    nlohmann::json curve = {{"name", c.name}, {"dimension", c.dimension}, {"joint_deg", c.joint_deg},
                            {"wrist_deg", c.wrist_deg}};
    if (PaperFigures().count(c.name) != 0) curve["paper_joint_deg"] = PaperFigures().at(c.name);
    curves.push_back(curve);
  }
  const FeatureStudyOptions& o = result.options;
  return {{"queries", o.queries},
          {"neighbours", o.neighbours},
          {"seed", o.seed},
          {"roll_queries", o.roll_queries},
          {"normalize_roll", o.normalize_roll},
          {"candidates", result.candidates},
          {"seconds", result.seconds},
          {"measure", "cumulative mean over neighbours 1..k of the mean absolute joint-angle error (degrees); "
                      "wrist: angle of the relative camera rotation (degrees)"},
          {"curves", curves}};
}

std::string FormatTable(const FeatureStudyResult& result) {
  std::ostringstream out;
  out << std::fixed << std::setprecision(2);
  out << "feature         dim   joint error, neighbour 1 (2, 5, 10)   wrist 1 (10)      paper 1 (2, 5, 10)\n";
  for (const FeatureCurve& c : result.curves) {
    const auto at = [&](const std::vector<double>& v, int k) { return k <= static_cast<int>(v.size()) ? v[k - 1] : NAN; };
    out << std::left << std::setw(14) << c.name << std::right << std::setw(5) << c.dimension << "   " << std::setw(6)
        << at(c.joint_deg, 1) << " (" << at(c.joint_deg, 2) << ", " << at(c.joint_deg, 5) << ", " << at(c.joint_deg, 10)
        << ")        " << std::setw(6) << at(c.wrist_deg, 1) << " (" << at(c.wrist_deg, 10) << ")    ";
    if (PaperFigures().count(c.name) != 0) {
      const std::vector<double>& p = PaperFigures().at(c.name);
      out << p[0];
      if (p.size() == 4) out << " (" << p[1] << ", " << p[2] << ", " << p[3] << ")";
    }
    out << "\n";
  }
  return out.str();
}

cv::Mat PlotCurves(const FeatureStudyResult& result) {
  const int width = 900, height = 560, left = 70, right = 190, top = 30, bottom = 60;
  cv::Mat plot(height, width, CV_8UC3, cv::Scalar(255, 255, 255));
  double top_value = 1.0;
  size_t k = 1;
  for (const FeatureCurve& c : result.curves) {
    for (double v : c.joint_deg) top_value = std::max(top_value, v);
    k = std::max(k, c.joint_deg.size());
  }
  top_value = std::ceil(top_value);
  const auto x_of = [&](double n) { return left + (width - left - right) * (n - 1) / std::max<double>(1, k - 1); };
  const auto y_of = [&](double v) { return height - bottom - (height - top - bottom) * v / top_value; };
  cv::line(plot, {left, height - bottom}, {width - right, height - bottom}, cv::Scalar(0, 0, 0));
  cv::line(plot, {left, top}, {left, height - bottom}, cv::Scalar(0, 0, 0));
  for (int t = 0; t <= 5; ++t) {
    const double v = top_value * t / 5;
    cv::putText(plot, cv::format("%.1f", v), {8, static_cast<int>(y_of(v)) + 4}, cv::FONT_HERSHEY_SIMPLEX, 0.45,
                cv::Scalar(0, 0, 0));
  }
  for (size_t n : {size_t{1}, size_t{10}, size_t{20}, size_t{30}, size_t{40}, size_t{50}}) {
    if (n > k) continue;
    cv::putText(plot, std::to_string(n), {static_cast<int>(x_of(n)) - 6, height - bottom + 20}, cv::FONT_HERSHEY_SIMPLEX,
                0.45, cv::Scalar(0, 0, 0));
  }
  cv::putText(plot, "neighbour", {width / 2 - 60, height - 15}, cv::FONT_HERSHEY_SIMPLEX, 0.55, cv::Scalar(0, 0, 0));
  cv::putText(plot, "mean joint error (deg), cumulative", {left, 20}, cv::FONT_HERSHEY_SIMPLEX, 0.55, cv::Scalar(0, 0, 0));
  const cv::Scalar palette[] = {{0, 0, 0},     {220, 60, 30},  {40, 160, 40}, {30, 30, 200},  {200, 150, 0},
                                {160, 0, 160}, {0, 140, 220},  {90, 90, 90},  {0, 200, 200}, {120, 60, 0}};
  for (size_t i = 0; i < result.curves.size(); ++i) {
    const FeatureCurve& c = result.curves[i];
    const cv::Scalar colour = palette[i % 10];
    std::vector<cv::Point> points;
    for (size_t n = 0; n < c.joint_deg.size(); ++n) {
      points.emplace_back(static_cast<int>(x_of(n + 1)), static_cast<int>(y_of(c.joint_deg[n])));
    }
    cv::polylines(plot, points, false, colour, 2, cv::LINE_AA);
    cv::putText(plot, c.name, {width - right + 15, top + 20 + 22 * static_cast<int>(i)}, cv::FONT_HERSHEY_SIMPLEX, 0.5,
                colour, 1, cv::LINE_AA);
  }
  return plot;
}

}  // namespace nphand
