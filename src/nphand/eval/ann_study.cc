#include "nphand/eval/ann_study.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <map>
#include <numbers>
#include <set>
#include <sstream>

#include <opencv2/imgproc.hpp>

#include "nphand/render/renderer.h"
#include "nphand/scene/grasp.h"
#include "nphand/scene/viewpoint.h"
#include "nphand/util/check.h"
#include "nphand/util/random.h"

namespace nphand {
namespace {

constexpr double kDegPerRad = 180.0 / std::numbers::pi;

double Seconds(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

// The rows of `all` at `rows` (ascending).
IndexedSet Subset(const IndexedSet& all, const std::vector<uint32_t>& rows) {
  IndexedSet subset{DescriptorMatrix(all.descriptors.config(), rows.size()), {}};
  for (size_t r = 0; r < rows.size(); ++r) {
    const std::span<const float> row = all.descriptors.Row(rows[r]);
    std::copy(row.begin(), row.end(), subset.descriptors.MutableRow(r).begin());
    subset.ids.push_back(all.ids[rows[r]]);
  }
  return subset;
}

// Joint and wrist error (degrees) of database entry `entry` as the pose of `query`; the
// wrist is turned back by the two rolls when the descriptor normalises roll.
std::pair<double, double> PoseError(const Database& db, entry_id_t entry, const HeldOutQuery& query) {
  const JointAngles angles = db.Angles(entry);
  double joint = 0.0;
  for (int d = 0; d < kNumDofs; ++d) joint += std::abs(angles[d] - query.angles[d]);
  Eigen::Matrix3d rotation = FromPoseVector(db.Pose(entry), Handedness::kRight).camera_from_hand;
  if (db.descriptor().normalize_roll) {
    rotation = AxisAngle(Eigen::Vector3d::UnitZ(), query.descriptor.roll - db.Meta(entry).roll) * rotation;
  }
  return {joint / kNumDofs * kDegPerRad, RotationAngleDeg(rotation, query.camera_from_hand)};
}

double Percentile(std::vector<double> values, double p) {
  std::sort(values.begin(), values.end());
  const size_t at = std::min(values.size() - 1, static_cast<size_t>(std::ceil(p * values.size())) - (p > 0 ? 1 : 0));
  return values[at];
}

}  // namespace

std::vector<HeldOutQuery> RenderHeldOutQueries(const HandModel& hand, const Database& db, int count, uint64_t seed) {
  const nlohmann::json& header = db.header();
  const std::vector<int> grasp_ids = header["grasps"].get<std::vector<int>>();
  const int image_size = header["render"]["image_size"].get<int>();
  const double fov_deg = header["render"]["fov_deg"].get<double>();
  const double distance = header["render"]["distance_m"].get<double>();
  const Intrinsics intrinsics = Intrinsics::FromFieldOfView(image_size, image_size, fov_deg * std::numbers::pi / 180.0);
  std::vector<Grasp> grasps;
  for (int id : grasp_ids) grasps.push_back(MakeGrasp(hand, GraspTaxonomy()[id - 1]));

  Random random(seed);
  Renderer renderer(hand);
  cv::Mat labels;
  std::vector<HeldOutQuery> queries;
  for (int attempt = 0; static_cast<int>(queries.size()) < count; ++attempt) {
    NPHAND_THROW_CHECK(attempt < 10 * count + 100, "held-out queries: the object hides the hand in nearly every render");
    const Grasp& grasp = grasps[random.UniformIndex(grasps.size())];
    const double t = random.Uniform(0.0, kGraspSteps - 1.0);
    const int step = std::min(static_cast<int>(t), kGraspSteps - 2);
    const double a = t - step;
    Scene scene;
    scene.hand.handedness = hand.handedness();
    for (int d = 0; d < kNumDofs; ++d) {
      scene.hand.angles[d] = (1.0 - a) * grasp.steps[step][d] + a * grasp.steps[step + 1][d];
    }
    scene.hand.camera_from_hand = CameraFromHand(RandomViewpoint(random));
    scene.wrist_in_camera = CenteredWristPosition(scene.hand.camera_from_hand, hand.bind_centre(), distance);
    if (random.Uniform() < 0.5) scene.objects = {grasp.object};
    renderer.RenderLabels(scene, intrinsics, &labels);
    std::optional<Descriptor> descriptor = Describe(labels == static_cast<int>(PixelLabel::kHand), db.descriptor());
    if (!descriptor.has_value()) continue;
    queries.push_back({std::move(*descriptor), scene.hand.angles, scene.hand.camera_from_hand});
  }
  return queries;
}

std::vector<AnnConfig> StudyConfigs() {
  std::vector<AnnConfig> configs;
  auto add = [&](const std::string& name, const std::string& backend) -> IndexOptions& {
    configs.push_back({name, IndexOptions::Exact()});
    configs.back().index.backend = backend;
    return configs.back().index;
  };
  add("exact", "exact");
  add("lsh", "lsh").lsh.tune_queries = 100;
  add("faiss-hnsw", "faiss-hnsw");
  add("hnswlib", "hnswlib");
  add("hnswlib-pca64", "hnswlib").hnsw.pca = 64;
  add("hnswlib-sq8", "hnswlib-sq8");
  add("faiss-ivf", "faiss-ivf");
  add("faiss-ivf-sq8", "faiss-ivf").ivf.encoding = "sq8";
  add("flann-kdtree", "flann");
  add("flann-kmeans", "flann").flann.algorithm = "kmeans";
  return configs;
}

bool AnnStudyOptions::Check(std::string* why) const {
  if (fractions.empty()) {
    *why = "no database fractions";
    return false;
  }
  for (double f : fractions) {
    if (!(f > 0.0 && f <= 1.0)) {
      *why = "database fractions must be in (0, 1]";
      return false;
    }
  }
  const std::vector<AnnConfig> known = StudyConfigs();
  for (const std::string& name : configs) {
    if (std::none_of(known.begin(), known.end(), [&](const AnnConfig& c) { return c.name == name; })) {
      *why = "unknown backend setting '" + name + "' (known:";
      for (const AnnConfig& c : known) *why += (why->back() == ':' ? " " : ", ") + c.name;
      *why += ")";
      return false;
    }
  }
  if (queries < 1 || queries > 100000) {
    *why = "queries must be between 1 and 100000";
    return false;
  }
  if (k < 1) {
    *why = "k must be at least 1";
    return false;
  }
  return true;
}

AnnStudyResult RunAnnStudy(const HandModel& hand, const Database& db, const AnnStudyOptions& options,
                           std::ostream* progress) {
  std::string why;
  NPHAND_THROW_CHECK(options.Check(&why), "eval ann: ", why);
  const auto start = std::chrono::steady_clock::now();
  AnnStudyResult result;
  result.options = options;
  std::vector<AnnConfig> configs;
  for (const AnnConfig& c : StudyConfigs()) {
    if (options.configs.empty() || std::count(options.configs.begin(), options.configs.end(), c.name) > 0) {
      configs.push_back(c);
    }
  }
  if (progress != nullptr) *progress << "eval ann: rendering " << options.queries << " held-out queries\n";
  const std::vector<HeldOutQuery> queries = RenderHeldOutQueries(hand, db, options.queries, options.seed);
  const IndexedSet all = DatabaseDescriptors(db);
  NPHAND_THROW_CHECK(!all.ids.empty(), "eval ann: the database has no entry with a hand");

  // Nested samples: each fraction takes the first rows of one seeded permutation.
  std::vector<uint32_t> permutation(all.ids.size());
  for (size_t i = 0; i < permutation.size(); ++i) permutation[i] = static_cast<uint32_t>(i);
  Random random(options.seed + 1);
  for (size_t i = permutation.size(); i > 1; --i) std::swap(permutation[i - 1], permutation[random.UniformIndex(i)]);

  for (double fraction : options.fractions) {
    const size_t count = std::max<size_t>(1, static_cast<size_t>(std::llround(fraction * all.ids.size())));
    std::vector<uint32_t> rows(permutation.begin(), permutation.begin() + count);
    std::sort(rows.begin(), rows.end());
    const std::unique_ptr<KnnIndex> exact = BuildIndex(Subset(all, rows), IndexOptions::Exact());
    std::vector<std::set<entry_id_t>> truth;
    for (const HeldOutQuery& q : queries) {
      const Neighbours n = exact->Search(q.descriptor, options.k);
      truth.emplace_back(n.ids.begin(), n.ids.end());
    }
    for (const AnnConfig& config : configs) {
      AnnRow row;
      row.config = config.name;
      row.backend = config.index.backend;
      row.fraction = fraction;
      row.entries = count;
      const auto built = std::chrono::steady_clock::now();
      const std::unique_ptr<KnnIndex> index = BuildIndex(Subset(all, rows), config.index);
      row.build_s = Seconds(built);
      row.parameters = index->Parameters();
      row.index_bytes = index->MemoryBytes();
      std::vector<double> ms;
      double recall = 0.0, joint = 0.0, wrist = 0.0;
      for (size_t q = 0; q < queries.size(); ++q) {
        const auto asked = std::chrono::steady_clock::now();
        const Neighbours n = index->Search(queries[q].descriptor, options.k);
        ms.push_back(1000.0 * Seconds(asked));
        size_t found = 0;
        for (entry_id_t id : n.ids) found += truth[q].count(id);
        recall += static_cast<double>(found) / truth[q].size();
        if (n.ids.empty()) {  // an LSH query whose buckets are all empty
          ++row.unanswered;
          continue;
        }
        const auto [j, w] = PoseError(db, n.ids.front(), queries[q]);
        joint += j;
        wrist += w;
      }
      const size_t answered = queries.size() - row.unanswered;
      row.recall = recall / queries.size();
      row.ms_median = Percentile(ms, 0.5);
      row.ms_p95 = Percentile(ms, 0.95);
      row.joint_deg = answered == 0 ? 0.0 : joint / answered;
      row.wrist_deg = answered == 0 ? 0.0 : wrist / answered;
      if (progress != nullptr) {
        *progress << "eval ann: " << std::setw(3) << std::lround(100 * fraction) << "% " << std::left << std::setw(14)
                  << config.name << std::right << std::fixed << std::setprecision(3) << " recall " << row.recall
                  << ", " << std::setprecision(2) << row.ms_median << " ms, built in " << std::setprecision(1)
                  << row.build_s << " s\n";
      }
      result.rows.push_back(std::move(row));
    }
  }
  result.seconds = Seconds(start);
  return result;
}

nlohmann::json ToJson(const AnnStudyResult& result) {
  nlohmann::json rows = nlohmann::json::array();
  for (const AnnRow& r : result.rows) {
    rows.push_back({{"config", r.config},           {"backend", r.backend},       {"fraction", r.fraction},
                    {"entries", r.entries},         {"parameters", r.parameters}, {"recall_at_k", r.recall},
                    {"ms_per_query", r.ms_median},  {"ms_p95", r.ms_p95},         {"build_s", r.build_s},
                    {"index_bytes", r.index_bytes}, {"joint_deg", r.joint_deg},   {"wrist_deg", r.wrist_deg},
                    {"unanswered", r.unanswered}});
  }
  return {{"study", "nearest-neighbour backends against database size (paper Fig. 5)"},
          {"k", result.options.k},
          {"queries", result.options.queries},
          {"seed", result.options.seed},
          {"fractions", result.options.fractions},
          {"measures",
           "recall_at_k: share of the exact k nearest found; ms_per_query: median over queries, one thread, one "
           "query at a time; index_bytes: memory beyond the descriptors all backends share; joint_deg, wrist_deg: "
           "error of the arg-max (nearest) neighbour's pose, over the queries that found any (unanswered: those "
           "that found none)"},
          {"seconds", result.seconds},
          {"rows", rows}};
}

std::string FormatTable(const AnnStudyResult& result) {
  std::map<double, double> exact_ms;  // fraction -> exact median
  for (const AnnRow& r : result.rows) {
    if (r.backend == "exact") exact_ms[r.fraction] = r.ms_median;
  }
  std::ostringstream out;
  out << "setting          entries  recall@" << result.options.k
      << "  ms/query (p95)    vs exact  build s  index MB  arg-max joint / wrist deg\n";
  for (const AnnRow& r : result.rows) {
    out << std::left << std::setw(15) << r.config << std::right << std::setw(9) << r.entries << std::fixed
        << std::setprecision(3) << std::setw(11) << r.recall << std::setprecision(2) << std::setw(10) << r.ms_median
        << " (" << std::setw(6) << r.ms_p95 << ")";
    if (exact_ms.count(r.fraction) != 0 && r.ms_median > 0) {
      out << std::setprecision(1) << std::setw(10) << exact_ms[r.fraction] / r.ms_median << "x";
    } else {
      out << std::setw(11) << "-";
    }
    out << std::setprecision(1) << std::setw(9) << r.build_s << std::setw(10) << r.index_bytes / 1e6
        << std::setprecision(2) << std::setw(10) << r.joint_deg << " / " << r.wrist_deg << "\n";
  }
  return out.str();
}

cv::Mat PlotAnnStudy(const AnnStudyResult& result) {
  const int panel = 520, height = 480, left = 70, right = 20, top = 40, bottom = 60, legend = 170;
  cv::Mat plot(height, 2 * panel + legend, CV_8UC3, cv::Scalar(255, 255, 255));
  std::vector<std::string> names;
  size_t most = 1;
  double ms_low = 1e9, ms_high = 1e-9, joint_high = 1.0;
  for (const AnnRow& r : result.rows) {
    if (std::find(names.begin(), names.end(), r.config) == names.end()) names.push_back(r.config);
    most = std::max(most, r.entries);
    ms_low = std::min(ms_low, std::max(r.ms_median, 1e-3));
    ms_high = std::max(ms_high, r.ms_median);
    joint_high = std::max(joint_high, r.joint_deg);
  }
  const double log_low = std::floor(std::log10(ms_low)), log_high = std::ceil(std::log10(std::max(ms_high, ms_low * 10)));
  joint_high = std::ceil(joint_high);
  const auto x_of = [&](int p, double entries) { return p * panel + left + (panel - left - right) * entries / most; };
  const auto y_ms = [&](double ms) {
    return height - bottom - (height - top - bottom) * (std::log10(std::max(ms, 1e-3)) - log_low) / (log_high - log_low);
  };
  const auto y_joint = [&](double deg) { return height - bottom - (height - top - bottom) * deg / joint_high; };
  const cv::Scalar black(0, 0, 0);
  for (int p = 0; p < 2; ++p) {
    cv::line(plot, {p * panel + left, height - bottom}, {p * panel + panel - right, height - bottom}, black);
    cv::line(plot, {p * panel + left, top}, {p * panel + left, height - bottom}, black);
    for (int t = 0; t <= 4; ++t) {
      const double entries = most * t / 4.0;
      cv::putText(plot, cv::format("%.0fk", entries / 1000), {static_cast<int>(x_of(p, entries)) - 12, height - bottom + 20},
                  cv::FONT_HERSHEY_SIMPLEX, 0.42, black);
    }
    cv::putText(plot, "database entries", {p * panel + panel / 2 - 50, height - 15}, cv::FONT_HERSHEY_SIMPLEX, 0.5, black);
  }
  for (double e = log_low; e <= log_high; e += 1.0) {
    cv::putText(plot, cv::format("%g", std::pow(10.0, e)), {8, static_cast<int>(y_ms(std::pow(10.0, e))) + 4},
                cv::FONT_HERSHEY_SIMPLEX, 0.42, black);
  }
  for (int t = 0; t <= 4; ++t) {
    const double deg = joint_high * t / 4;
    cv::putText(plot, cv::format("%.1f", deg), {panel + 15, static_cast<int>(y_joint(deg)) + 4}, cv::FONT_HERSHEY_SIMPLEX,
                0.42, black);
  }
  cv::putText(plot, "ms per query (K = " + std::to_string(result.options.k) + ", log scale)", {left, 25},
              cv::FONT_HERSHEY_SIMPLEX, 0.5, black);
  cv::putText(plot, "arg-max neighbour joint error (deg)", {panel + left, 25}, cv::FONT_HERSHEY_SIMPLEX, 0.5, black);
  const cv::Scalar palette[] = {{0, 0, 0},     {220, 60, 30}, {40, 160, 40}, {30, 30, 200},  {200, 150, 0},
                                {160, 0, 160}, {0, 140, 220}, {90, 90, 90}, {0, 200, 200}, {120, 60, 0}};
  for (size_t i = 0; i < names.size(); ++i) {
    const cv::Scalar colour = palette[i % 10];
    std::vector<cv::Point> time_points, error_points;
    for (const AnnRow& r : result.rows) {
      if (r.config != names[i]) continue;
      time_points.emplace_back(static_cast<int>(x_of(0, r.entries)), static_cast<int>(y_ms(r.ms_median)));
      error_points.emplace_back(static_cast<int>(x_of(1, r.entries)), static_cast<int>(y_joint(r.joint_deg)));
    }
    for (const auto* points : {&time_points, &error_points}) {
      cv::polylines(plot, *points, false, colour, 2, cv::LINE_AA);
      for (const cv::Point& pt : *points) cv::circle(plot, pt, 3, colour, cv::FILLED, cv::LINE_AA);
    }
    cv::putText(plot, names[i], {2 * panel + 10, top + 20 + 22 * static_cast<int>(i)}, cv::FONT_HERSHEY_SIMPLEX, 0.5,
                colour, 1, cv::LINE_AA);
  }
  return plot;
}

}  // namespace nphand
