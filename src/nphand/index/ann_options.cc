#include "nphand/index/ann_options.h"

#include "nphand/util/check.h"

namespace nphand {
namespace {

// Runs `read`, turning a missing field or a wrong type into an error naming
// the file and the backend, then checks the result.
template <typename Options, typename Read>
Options FromJsonChecked(const std::string& source, const char* backend, Read read) {
  Options options;
  try {
    read(options);
  } catch (const nlohmann::json::exception& e) {
    NPHAND_THROW(source, ": the ", backend, " parameters lack a field or have one of the wrong type (", e.what(), ")");
  }
  std::string why;
  NPHAND_THROW_CHECK(options.Check(&why), source, ": invalid ", backend, " parameters (", why, ")");
  return options;
}

bool Fail(std::string* why, const std::string& text) {
  *why = text;
  return false;
}

}  // namespace

bool HnswOptions::Check(std::string* why) const {
  if (m < 2 || m > 256) return Fail(why, "HNSW M must be between 2 and 256");
  if (ef_construction < 1 || ef_construction > 100000) return Fail(why, "HNSW ef_construction must be between 1 and 100000");
  if (ef_search < 1 || ef_search > 1000000) return Fail(why, "HNSW ef_search must be between 1 and 1000000");
  if (pca < 0 || pca > 4096) return Fail(why, "HNSW pca must be between 0 (none) and 4096 dimensions");
  return true;
}

nlohmann::json HnswOptions::ToJson() const {
  return {{"m", m}, {"ef_construction", ef_construction}, {"ef_search", ef_search}, {"seed", seed}, {"pca", pca}};
}

HnswOptions HnswOptions::FromJson(const nlohmann::json& json, const std::string& source) {
  return FromJsonChecked<HnswOptions>(source, "HNSW", [&](HnswOptions& o) {
    o.m = json.at("m").get<int>();
    o.ef_construction = json.at("ef_construction").get<int>();
    o.ef_search = json.at("ef_search").get<int>();
    o.seed = json.at("seed").get<uint64_t>();
    o.pca = json.at("pca").get<int>();
  });
}

bool IvfOptions::Check(std::string* why) const {
  if (lists < 0 || lists > (1 << 20)) return Fail(why, "IVF lists must be between 0 (automatic) and 1048576");
  if (probes < 1 || probes > (1 << 20)) return Fail(why, "IVF probes must be between 1 and 1048576");
  if (encoding != "flat" && encoding != "sq8") return Fail(why, "IVF encoding must be flat or sq8, not '" + encoding + "'");
  if (rerank < 1 || rerank > 1000) return Fail(why, "IVF rerank must be between 1 and 1000");
  if (iterations < 1 || iterations > 1000) return Fail(why, "IVF k-means iterations must be between 1 and 1000");
  if (seed >= (uint64_t{1} << 31)) return Fail(why, "the IVF seed must be below 2^31 (FAISS's k-means takes an int)");
  return true;
}

nlohmann::json IvfOptions::ToJson() const {
  return {{"lists", lists}, {"probes", probes}, {"encoding", encoding}, {"rerank", rerank}, {"iterations", iterations}, {"seed", seed}};
}

IvfOptions IvfOptions::FromJson(const nlohmann::json& json, const std::string& source) {
  return FromJsonChecked<IvfOptions>(source, "IVF", [&](IvfOptions& o) {
    o.lists = json.at("lists").get<int>();
    o.probes = json.at("probes").get<int>();
    o.encoding = json.at("encoding").get<std::string>();
    o.rerank = json.at("rerank").get<int>();
    o.iterations = json.at("iterations").get<int>();
    o.seed = json.at("seed").get<uint64_t>();
  });
}

bool FlannOptions::Check(std::string* why) const {
  if (algorithm != "kdtree" && algorithm != "kmeans") {
    return Fail(why, "FLANN algorithm must be kdtree or kmeans, not '" + algorithm + "'");
  }
  if (trees < 1 || trees > 64) return Fail(why, "FLANN trees must be between 1 and 64");
  if (branching < 2 || branching > 1024) return Fail(why, "FLANN branching must be between 2 and 1024");
  if (iterations < 1 || iterations > 1000) return Fail(why, "FLANN k-means iterations must be between 1 and 1000");
  if (checks != -1 && checks < 1) return Fail(why, "FLANN checks must be at least 1, or -1 for an exact search");
  return true;
}

nlohmann::json FlannOptions::ToJson() const {
  return {{"algorithm", algorithm}, {"trees", trees},   {"branching", branching},
          {"iterations", iterations}, {"checks", checks}};
}

FlannOptions FlannOptions::FromJson(const nlohmann::json& json, const std::string& source) {
  return FromJsonChecked<FlannOptions>(source, "FLANN", [&](FlannOptions& o) {
    o.algorithm = json.at("algorithm").get<std::string>();
    o.trees = json.at("trees").get<int>();
    o.branching = json.at("branching").get<int>();
    o.iterations = json.at("iterations").get<int>();
    o.checks = json.at("checks").get<int>();
  });
}

}  // namespace nphand
