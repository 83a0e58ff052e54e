// The options of the library-backed index backends (FAISS, hnswlib, FLANN). Each is stored
// in the index file as JSON and read back, checked, when the file is loaded.
#pragma once

#include <cstdint>
#include <string>

#include <nlohmann/json.hpp>

namespace nphand {

// A hierarchical navigable small-world graph (Malkov & Yashunin): faiss-hnsw and hnswlib.
struct HnswOptions {
  int m = 16;                 // links per node above level 0 (2 M at level 0)
  int ef_construction = 200;  // candidate list while inserting
  int ef_search = 500;        // candidate list while searching (at least k is used)
  uint64_t seed = 1;          // the levels drawn for the nodes
  // hnswlib only: the graph links and searches the descriptors projected onto their first
  // `pca` principal components, and the max(ef_search, k) candidates it finds are re-ranked
  // by exact distance; 0: the graph uses the descriptors themselves.
  int pca = 0;

  bool Check(std::string* why) const;
  nlohmann::json ToJson() const;
  static HnswOptions FromJson(const nlohmann::json& json, const std::string& source);
};

// An inverted file over k-means cells (faiss-ivf): the query's `probes` nearest cells are
// scanned, storing the descriptors as they are ("flat") or as 8-bit scalars ("sq8", its
// candidates re-ranked by exact distance).
struct IvfOptions {
  int lists = 0;               // cells; 0: 4 sqrt(n), at most n
  int probes = 32;             // cells scanned per query
  std::string encoding = "flat";
  int rerank = 4;              // sq8: rerank x k candidates by 8-bit distance, re-ranked exactly
  int iterations = 10;         // k-means iterations
  uint64_t seed = 1;           // k-means sample and initial centroids; below 2^31

  bool Check(std::string* why) const;
  nlohmann::json ToJson() const;
  static IvfOptions FromJson(const nlohmann::json& json, const std::string& source);
};

// FLANN: randomised k-d trees ("kdtree") or a hierarchical k-means tree ("kmeans"),
// searched for `checks` leaves (-1: all, an exact search). No seed: Debian's FLANN 1.9.2
// draws its shuffles from std::random_device, so no seed would make its trees repeatable.
struct FlannOptions {
  std::string algorithm = "kdtree";
  int trees = 4;          // kdtree
  int branching = 32;     // kmeans
  int iterations = 11;    // kmeans
  int checks = 4096;

  bool Check(std::string* why) const;
  nlohmann::json ToJson() const;
  static FlannOptions FromJson(const nlohmann::json& json, const std::string& source);
};

}  // namespace nphand
