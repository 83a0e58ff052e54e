#include "nphand/index/lsh_index.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <queue>

#include <Eigen/Core>

#include "nphand/index/exact_index.h"
#include "nphand/util/check.h"
#include "nphand/util/random.h"

namespace nphand {
namespace {

using RowMatrix = Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

uint64_t Mix(uint64_t x) {
  x ^= x >> 30;
  x *= 0xbf58476d1ce4e5b9ULL;
  x ^= x >> 27;
  x *= 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

// The bucket key of M hash values.
uint64_t KeyOf(const int32_t* hashes, int m) {
  uint64_t key = 0x2545f4914f6cdd1dULL;
  for (int j = 0; j < m; ++j) key = Mix(key ^ static_cast<uint32_t>(hashes[j]));
  return key;
}

// The hash value of a scaled projection plus offset: floor, kept within int32 whatever the
// input (a tiny W or an extreme descriptor must not overflow the conversion).
int32_t HashOf(float f) { return static_cast<int32_t>(std::floor(std::clamp(f, -2.0e9f, 2.0e9f))); }

// A perturbation set of the probing sequence: indices into the sorted boundaries.
struct Perturbation {
  float score = 0.0f;
  std::vector<int> picks;
  bool operator>(const Perturbation& other) const { return score > other.score; }
};

// The first `count` perturbations of a query's M hash values after its home bucket, by
// Lv et al.'s query-directed sequence: each is a list of (hash, +-1), in increasing sum of
// squared distances to the crossed boundaries. `fraction[j]` is where the query's
// projection lies within its bucket, in [0, 1).
std::vector<std::vector<std::pair<int, int>>> ProbeSequence(const float* fraction, int m, int count) {
  struct Boundary {
    float distance;
    int hash;
    int delta;
  };
  std::vector<Boundary> z;
  for (int j = 0; j < m; ++j) {
    z.push_back({fraction[j], j, -1});
    z.push_back({1.0f - fraction[j], j, +1});
  }
  std::sort(z.begin(), z.end(), [](const Boundary& a, const Boundary& b) {
    return a.distance != b.distance ? a.distance < b.distance : a.hash != b.hash ? a.hash < b.hash : a.delta < b.delta;
  });
  const auto square = [&](int i) { return z[i].distance * z[i].distance; };
  std::priority_queue<Perturbation, std::vector<Perturbation>, std::greater<>> heap;
  heap.push({square(0), {0}});
  std::vector<std::vector<std::pair<int, int>>> sequence;
  std::vector<int> seen(m);
  while (static_cast<int>(sequence.size()) < count && !heap.empty()) {
    Perturbation top = heap.top();
    heap.pop();
    const int last = top.picks.back();
    if (last + 1 < 2 * m) {
      Perturbation shift = top, expand = top;
      shift.picks.back() = last + 1;
      shift.score += square(last + 1) - square(last);
      expand.picks.push_back(last + 1);
      expand.score += square(last + 1);
      heap.push(std::move(shift));
      heap.push(std::move(expand));
    }
    std::fill(seen.begin(), seen.end(), 0);
    bool valid = true;
    std::vector<std::pair<int, int>> probe;
    for (int i : top.picks) {
      valid &= seen[z[i].hash]++ == 0;
      probe.emplace_back(z[i].hash, z[i].delta);
    }
    if (valid) sequence.push_back(std::move(probe));
  }
  return sequence;
}

}  // namespace

bool LshOptions::Check(std::string* why) const {
  if (tables < 1 || tables > 64 || probes < 1 || probes > 10000) {
    *why = "LSH needs 1 to 64 tables and 1 to 10000 probes per table";
    return false;
  }
  if (hashes < 0 || hashes > kMaxLshHashes || !(bucket_width == 0.0 || (bucket_width >= 1e-6 && bucket_width <= 1e6))) {
    *why = "LSH hashes per table must be 0 (tuned) to " + std::to_string(kMaxLshHashes) +
           " and the bucket width 0 (tuned) or within [1e-6, 1e6]";
    return false;
  }
  if (!(target_recall > 0.0 && target_recall <= 1.0) || tune_k < 1 || tune_queries < 1) {
    *why = "LSH tuning needs a target recall in (0, 1], k >= 1 and at least one query";
    return false;
  }
  return true;
}

LshIndex::LshIndex(IndexedSet set, const LshOptions& options, std::ostream* progress)
    : KnnIndex(std::move(set)), options_(options) {
  std::string why;
  NPHAND_THROW_CHECK(options.Check(&why), "lsh: ", why);
  NPHAND_THROW_CHECK(!this->set().ids.empty(), "lsh: the database has no entry with a hand to index");
  NPHAND_THROW_CHECK(this->set().ids.size() < (1ull << 32), "lsh: too many rows");
  const int dimension = config().Dimension();
  const int columns = options_.tables * kMaxLshHashes;
  Random random(options_.seed);
  projections_.resize(static_cast<size_t>(columns) * dimension);
  for (float& a : projections_) a = static_cast<float>(random.Normal());
  offsets_.resize(columns);
  for (float& u : offsets_) u = static_cast<float>(random.Uniform());

  // Every row's projections, once: rows x columns.
  const DescriptorMatrix& base = this->set().descriptors;
  const Eigen::Map<const RowMatrix> x(base.values().data(), static_cast<Eigen::Index>(base.rows()), dimension);
  const Eigen::Map<const RowMatrix> a(projections_.data(), columns, dimension);
  std::vector<float> projected(base.rows() * columns);
  Eigen::Map<RowMatrix>(projected.data(), static_cast<Eigen::Index>(base.rows()), columns).noalias() = x * a.transpose();

  if (options_.hashes == 0 || options_.bucket_width == 0.0) Tune(projected, progress);
  tables_ = BuildTables(projected);
}

std::vector<LshIndex::Table> LshIndex::BuildTables(const std::vector<float>& projected) const {
  const size_t rows = set().ids.size();
  const int m = options_.hashes, columns = options_.tables * kMaxLshHashes;
  const float inverse_width = static_cast<float>(1.0 / options_.bucket_width);
  std::vector<Table> tables(options_.tables);
  std::vector<std::pair<uint64_t, uint32_t>> keyed(rows);
  std::vector<int32_t> hashes(m);
  for (int t = 0; t < options_.tables; ++t) {
    for (size_t r = 0; r < rows; ++r) {
      const float* p = projected.data() + r * columns + t * kMaxLshHashes;
      for (int j = 0; j < m; ++j) {
        hashes[j] = HashOf(p[j] * inverse_width + offsets_[t * kMaxLshHashes + j]);
      }
      keyed[r] = {KeyOf(hashes.data(), m), static_cast<uint32_t>(r)};
    }
    std::sort(keyed.begin(), keyed.end());
    tables[t].keys.resize(rows);
    tables[t].rows.resize(rows);
    for (size_t r = 0; r < rows; ++r) std::tie(tables[t].keys[r], tables[t].rows[r]) = keyed[r];
  }
  return tables;
}

std::vector<uint32_t> LshIndex::Candidates(const std::vector<Table>& tables, std::span<const float> projected) const {
  const int m = options_.hashes;
  const float inverse_width = static_cast<float>(1.0 / options_.bucket_width);
  // A bit per row: buckets overlap across tables, and reading the set bits in order gives
  // the candidates ascending, so that re-ranking reads the rows in memory order.
  std::vector<uint64_t> seen((set().ids.size() + 63) / 64, 0);
  std::vector<int32_t> home(m), probe(m);
  std::vector<float> fraction(m);
  for (int t = 0; t < options_.tables; ++t) {
    for (int j = 0; j < m; ++j) {
      const float f = projected[t * kMaxLshHashes + j] * inverse_width + offsets_[t * kMaxLshHashes + j];
      home[j] = HashOf(f);
      fraction[j] = std::clamp(f - std::floor(f), 0.0f, 1.0f);
    }
    const auto visit = [&](const std::vector<int32_t>& hashes) {
      const uint64_t key = KeyOf(hashes.data(), m);
      const Table& table = tables[t];
      const auto [first, last] = std::equal_range(table.keys.begin(), table.keys.end(), key);
      for (auto row = table.rows.begin() + (first - table.keys.begin()); row != table.rows.begin() + (last - table.keys.begin());
           ++row) {
        seen[*row / 64] |= uint64_t{1} << (*row % 64);
      }
    };
    visit(home);
    for (const auto& perturbation : ProbeSequence(fraction.data(), m, options_.probes - 1)) {
      probe = home;
      for (const auto& [j, delta] : perturbation) probe[j] += delta;
      visit(probe);
    }
  }
  std::vector<uint32_t> candidates;
  for (size_t word = 0; word < seen.size(); ++word) {
    for (uint64_t bits = seen[word]; bits != 0; bits &= bits - 1) {
      candidates.push_back(static_cast<uint32_t>(64 * word + std::countr_zero(bits)));
    }
  }
  return candidates;
}

void LshIndex::Tune(const std::vector<float>& projected, std::ostream* progress) {
  const DescriptorMatrix& base = set().descriptors;
  const size_t rows = base.rows();
  const int columns = options_.tables * kMaxLshHashes;
  const int k = static_cast<int>(std::min<size_t>(options_.tune_k, rows));
  // The sampled queries and their true k nearest.
  Random random(options_.seed ^ 0x7475ULL);
  const size_t count = std::min<size_t>(options_.tune_queries, rows);
  std::vector<uint32_t> queries(count);
  std::vector<std::vector<uint32_t>> truth(count);
  for (size_t q = 0; q < count; ++q) {
    queries[q] = static_cast<uint32_t>(random.UniformIndex(rows));
    for (const auto& [distance, row] : NearestRows(base, base.Row(queries[q]), k)) truth[q].push_back(row);
    std::sort(truth[q].begin(), truth[q].end());
  }
  // Recall of the candidates (re-ranking is exact, so it is the search's recall) and their
  // mean number, for the current M and W.
  const auto measure = [&]() {
    const std::vector<Table> tables = BuildTables(projected);
    double found = 0.0, gathered = 0.0;
    for (size_t q = 0; q < count; ++q) {
      const std::vector<uint32_t> candidates =
          Candidates(tables, {projected.data() + static_cast<size_t>(queries[q]) * columns, static_cast<size_t>(columns)});
      std::vector<uint32_t> common;
      std::set_intersection(candidates.begin(), candidates.end(), truth[q].begin(), truth[q].end(),
                            std::back_inserter(common));
      found += static_cast<double>(common.size()) / k;
      gathered += candidates.size();
    }
    return std::make_pair(found / count, gathered / count);
  };
  const std::vector<int> hash_counts =
      options_.hashes > 0 ? std::vector<int>{options_.hashes} : std::vector<int>{4, 6, 8, 10, 12, 14, 16, 20};
  const double fixed_width = options_.bucket_width;
  double best_candidates = HUGE_VAL;
  LshOptions best = options_;
  for (int m : hash_counts) {
    options_.hashes = m;
    double width = fixed_width, recall = 0.0, candidates = 0.0;
    if (fixed_width > 0.0) {
      std::tie(recall, candidates) = measure();
    } else {
      // The smallest width (within 3 %) that reaches the target: recall grows with W.
      double low = 1e-3, high = 1e-3;
      for (;; high *= 2.0) {
        options_.bucket_width = high;
        std::tie(recall, candidates) = measure();
        if (recall >= options_.target_recall || high > 1e3) break;
        low = high;
      }
      while (recall >= options_.target_recall && high / low > 1.03) {
        options_.bucket_width = std::sqrt(low * high);
        const auto [mid_recall, mid_candidates] = measure();
        if (mid_recall >= options_.target_recall) {
          high = options_.bucket_width;
          std::tie(recall, candidates) = std::make_pair(mid_recall, mid_candidates);
        } else {
          low = options_.bucket_width;
        }
      }
      width = high;
    }
    if (progress != nullptr) {
      *progress << "lsh tuning: M = " << m << ", W = " << width << ": recall@" << k << " " << recall << ", "
                << candidates << " candidates per query\n";
    }
    if (recall >= options_.target_recall && candidates < best_candidates) {
      best_candidates = candidates;
      best = options_;
      best.bucket_width = width;
      tuned_recall_ = recall;
      tuned_candidates_ = candidates;
    }
  }
  NPHAND_THROW_CHECK(best_candidates < HUGE_VAL, "lsh: no bucket width reaches recall ", options_.target_recall,
                     " with ", options_.tables, " tables and ", options_.probes, " probes");
  options_ = best;
}

std::vector<std::pair<float, uint32_t>> LshIndex::SearchRows(std::span<const float> query, int k) const {
  const int dimension = config().Dimension(), columns = options_.tables * kMaxLshHashes;
  const Eigen::Map<const RowMatrix> a(projections_.data(), columns, dimension);
  const Eigen::Map<const Eigen::VectorXf> q(query.data(), dimension);
  const Eigen::VectorXf projected = a * q;
  return Rerank(set().descriptors, query, Candidates(tables_, {projected.data(), static_cast<size_t>(columns)}), k);
}

size_t LshIndex::MemoryBytes() const {
  size_t bytes = (projections_.size() + offsets_.size()) * sizeof(float);
  for (const Table& table : tables_) bytes += table.keys.size() * sizeof(uint64_t) + table.rows.size() * sizeof(uint32_t);
  return bytes;
}

nlohmann::json LshIndex::Parameters() const {
  return {{"tables", options_.tables},
          {"probes", options_.probes},
          {"hashes", options_.hashes},
          {"bucket_width", options_.bucket_width},
          {"seed", options_.seed},
          {"target_recall", options_.target_recall},
          {"tune_k", options_.tune_k},
          {"tuned_recall", tuned_recall_},
          {"tuned_candidates", tuned_candidates_}};
}

LshOptions LshIndex::OptionsFromParameters(const nlohmann::json& parameters, const std::string& source) {
  LshOptions options;
  try {
    options.tables = parameters.at("tables").get<int>();
    options.probes = parameters.at("probes").get<int>();
    options.hashes = parameters.at("hashes").get<int>();
    options.bucket_width = parameters.at("bucket_width").get<double>();
    options.seed = parameters.at("seed").get<uint64_t>();
    options.target_recall = parameters.at("target_recall").get<double>();
    options.tune_k = parameters.at("tune_k").get<int>();
  } catch (const nlohmann::json::exception& e) {
    NPHAND_THROW(source, ": the LSH parameters lack a field or have one of the wrong type (", e.what(), ")");
  }
  std::string why;
  NPHAND_THROW_CHECK(options.Check(&why) && options.hashes > 0 && options.bucket_width > 0.0, source,
                     ": invalid LSH parameters (", why.empty() ? "M and W must be set" : why, ")");
  return options;
}

std::unique_ptr<LshIndex> LshIndex::FromParameters(IndexedSet set, const nlohmann::json& parameters,
                                                   const std::string& source) {
  auto index = std::make_unique<LshIndex>(std::move(set), OptionsFromParameters(parameters, source), nullptr);
  const nlohmann::json recall = parameters.value("tuned_recall", nlohmann::json()),
                       candidates = parameters.value("tuned_candidates", nlohmann::json());
  NPHAND_THROW_CHECK(recall.is_number() && candidates.is_number() && recall.get<double>() >= 0.0 &&
                         recall.get<double>() <= 1.0 && candidates.get<double>() >= 0.0,
                     source, ": the LSH parameters' tuned_recall and tuned_candidates must be numbers, the recall in [0, 1]");
  index->tuned_recall_ = recall.get<double>();
  index->tuned_candidates_ = candidates.get<double>();
  return index;
}

}  // namespace nphand
