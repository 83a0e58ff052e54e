// The nearest-neighbour study of the paper (Fig. 5): for every index backend and for growing
// fractions of the database, the recall of the true K = 500 nearest (exact search on the same
// fraction), the milliseconds per query (one thread, one query at a time, as the estimator
// asks), the index's build time and memory, and the pose error of the arg-max neighbour.
// Queries are held-out renders: a grasp of the database at a pose between two of its steps,
// seen from a random direction (between its directions) with a random camera roll, with or
// without the object; never database entries.
#pragma once

#include <cstdint>
#include <ostream>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "nphand/db/database.h"
#include "nphand/index/backends.h"
#include "nphand/model/hand_model.h"

namespace nphand {

struct HeldOutQuery {
  Descriptor descriptor;
  JointAngles angles;                 // the rendered pose
  Eigen::Matrix3d camera_from_hand;   // the rendered wrist orientation
};

// `count` held-out queries rendered like `db`'s entries (its grasps, camera and descriptor),
// drawn with `seed`; renders whose hand the object hides are drawn again.
std::vector<HeldOutQuery> RenderHeldOutQueries(const HandModel& hand, const Database& db, int count, uint64_t seed);

// One backend setting of the study.
struct AnnConfig {
  std::string name;
  IndexOptions index;
};
// exact, lsh (the paper's L = 10, T = 50, R = 0.95), faiss-hnsw, hnswlib (on the descriptors,
// and on their 64 principal components with exact re-ranking), faiss-ivf (flat and sq8),
// flann (kdtree and kmeans).
std::vector<AnnConfig> StudyConfigs();

struct AnnStudyOptions {
  std::vector<double> fractions = {0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0};
  std::vector<std::string> configs;  // names from StudyConfigs(); empty: all
  int queries = 200;
  int k = 500;
  uint64_t seed = 1;  // the queries and the fractions' samples

  bool Check(std::string* why) const;
};

struct AnnRow {
  std::string config, backend;
  double fraction = 0.0;
  size_t entries = 0;
  nlohmann::json parameters;
  double recall = 0.0;              // of the true k nearest, mean over queries
  double ms_median = 0.0, ms_p95 = 0.0;
  double build_s = 0.0;
  size_t index_bytes = 0;           // memory beyond the shared descriptors
  double joint_deg = 0.0;           // arg-max neighbour: mean absolute joint-angle error
  double wrist_deg = 0.0;           // and wrist-orientation error, mean over queries answered
  size_t unanswered = 0;            // queries the backend found no neighbour for
};

struct AnnStudyResult {
  AnnStudyOptions options;
  std::vector<AnnRow> rows;
  double seconds = 0.0;
};

AnnStudyResult RunAnnStudy(const HandModel& hand, const Database& db, const AnnStudyOptions& options,
                           std::ostream* progress);

nlohmann::json ToJson(const AnnStudyResult& result);
std::string FormatTable(const AnnStudyResult& result);
// Two panels against database entries: milliseconds per query (log scale) and the arg-max
// neighbour's joint error; one colour per backend setting.
cv::Mat PlotAnnStudy(const AnnStudyResult& result);

}  // namespace nphand
