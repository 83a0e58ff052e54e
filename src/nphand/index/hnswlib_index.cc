#include "nphand/index/hnswlib_index.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <numeric>
#include <optional>
#include <queue>

#include <Eigen/Core>
#include <Eigen/Eigenvalues>
// hnswlib 0.6.2's SSE path prefetches one link past the end of a full upper-level list (a
// heap over-read AddressSanitizer reports); its SIMD distances are not used here (nphand's
// own spaces: RowPointerSpace, CodeSpace), so it is switched off.
#define NO_MANUAL_VECTORIZATION
#include <hnswlib/hnswlib.h>

#include "nphand/index/body.h"
#include "nphand/index/exact_index.h"
#include "nphand/util/check.h"
#include "nphand/util/progress.h"
#include "nphand/util/random.h"

namespace nphand {
namespace {

using Graph = hnswlib::HierarchicalNSW<float>;

// hnswlib's space over pointers to descriptor rows: a node stores the row's address.
class RowPointerSpace : public hnswlib::SpaceInterface<float> {
 public:
  explicit RowPointerSpace(size_t dimension) : dimension_(dimension) {}
  size_t get_data_size() override { return sizeof(const float*); }
  hnswlib::DISTFUNC<float> get_dist_func() override { return &Distance; }
  void* get_dist_func_param() override { return &dimension_; }

 private:
  static float Distance(const void* a, const void* b, const void* parameter) {
    const size_t dimension = *static_cast<const size_t*>(parameter);
    // hnswlib packs a node's data after its links: the pointer may be unaligned.
    const float* x;
    const float* y;
    std::memcpy(&x, a, sizeof(x));
    std::memcpy(&y, b, sizeof(y));
    return SquaredDistance({x, dimension}, {y, dimension});
  }
  size_t dimension_;
};

// The squared distance of two rows of 8-bit codes, exact in integers (at most 65,025 per
// value). Compiled for AVX-512 (x86-64-v4) and AVX2 too and chosen by the CPU at load time;
// the sum is the same. AVX-512 takes the search from 1.15 to 0.9-1.0 ms a frame (K = 500).
__attribute__((target_clones("arch=x86-64-v4", "avx2", "default"))) uint32_t CodeDistance(const uint8_t* a, const uint8_t* b,
                                                                         size_t dimension) {
  uint32_t sum = 0;
  for (size_t i = 0; i < dimension; ++i) {
    const int d = static_cast<int>(a[i]) - static_cast<int>(b[i]);
    sum += static_cast<uint32_t>(d * d);
  }
  return sum;
}

// hnswlib's space over 8-bit codes held in the nodes: code = value / step, rounded,
// clamped to 0..255; the distance is the codes' squared distance times step^2.
class CodeSpace : public hnswlib::SpaceInterface<float> {
 public:
  CodeSpace(size_t dimension, float step) : parameter_{dimension, step * step} {}
  size_t get_data_size() override { return parameter_.dimension; }
  hnswlib::DISTFUNC<float> get_dist_func() override { return &Distance; }
  void* get_dist_func_param() override { return &parameter_; }

 private:
  struct Parameter {
    size_t dimension;
    float step_squared;
  };
  static float Distance(const void* a, const void* b, const void* parameter) {
    const auto* p = static_cast<const Parameter*>(parameter);
    return static_cast<float>(CodeDistance(static_cast<const uint8_t*>(a), static_cast<const uint8_t*>(b),
                                           p->dimension)) *
           p->step_squared;
  }
  Parameter parameter_;
};

// The step that maps the largest value of the rows to 255 (1 when every value is 0).
float CodeStep(float largest) { return largest > 0.0f ? largest / 255.0f : 1.0f; }

void Encode(std::span<const float> row, float step, uint8_t* codes) {
  for (size_t c = 0; c < row.size(); ++c) {
    codes[c] = static_cast<uint8_t>(std::clamp(row[c] / step, 0.0f, 255.0f) + 0.5f);  // rounded half up
  }
}

// The rows' codes, with their step (hnswlib-sq8).
struct Sq8Codes {
  float step = 1.0f;
  std::vector<uint8_t> codes;  // rows x dimension
};

using RowMatrix = Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

// Rows sampled to fit the PCA projection.
constexpr size_t kPcaSample = 20000;

// The highest node level a file may hold (hnswlib draws about log_M(n)).
constexpr int kMaxLevel = 64;

class HnswlibIndex : public KnnIndex {
 public:
  // "hnswlib": the nodes point to the set's rows, or to their projections.
  HnswlibIndex(IndexedSet set, const HnswOptions& options)
      : KnnIndex(std::move(set)), options_(options),
        space_(std::make_unique<RowPointerSpace>(
            static_cast<size_t>(options.pca > 0 ? options.pca : config().Dimension()))) {
    NPHAND_THROW_CHECK(options.pca <= config().Dimension(), "hnswlib: a PCA to ", options.pca,
                       " dimensions of a ", config().Dimension(), "-dimensional descriptor");
    MakeGraph();
  }
  // "hnswlib-sq8": the nodes hold the rows' codes; `ids` has no descriptor rows. The codes
  // are given to Build; a loaded index gets them from EncodeRows.
  HnswlibIndex(IndexedSet ids, Sq8Codes codes, const HnswOptions& options)
      : KnnIndex(std::move(ids)), options_(options), sq8_(std::move(codes)),
        space_(std::make_unique<CodeSpace>(static_cast<size_t>(config().Dimension()), sq8_->step)) {
    NPHAND_CHECK(options.pca == 0 && (sq8_->codes.empty() || sq8_->codes.size() == size() * config().Dimension()));
    MakeGraph();
  }

  void Build(std::ostream* progress) {
    if (options_.pca > 0) FitPca();
    ProgressLine line(progress, "index build: " + Backend(), size(), "entries");
    for (size_t i = 0; i < size(); ++i) {
      if (sq8_) {
        graph_->addPoint(Codes(i), i);
      } else {
        const float* row = GraphRow(i);
        graph_->addPoint(&row, i);
      }
      line.Update(i + 1);
    }
    line.Finish();
    ReleaseCodes();
  }

  // The graph of a body, checked: levels, link counts within hnswlib's limits, links to
  // nodes, the entry point a node of the top level. Written into hnswlib's structures as its
  // addPoint would have left them.
  void Load(BodyReader& body) {
    if (options_.pca > 0) {
      const size_t d = static_cast<size_t>(config().Dimension());
      mean_ = body.GetArray<float>(d, "PCA mean values");
      components_ = body.GetArray<float>(d * options_.pca, "PCA component values");
      NPHAND_THROW_CHECK(std::all_of(mean_.begin(), mean_.end(), [](float v) { return std::isfinite(v); }) &&
                             std::all_of(components_.begin(), components_.end(), [](float v) { return std::isfinite(v); }),
                         body.source(), ": a PCA value is not a finite number");
      Project();
    }
    Graph& g = *graph_;
    const size_t n = size();
    const int top = body.Get<int32_t>();
    const uint32_t entry = body.Get<uint32_t>();
    const std::vector<int32_t> levels = body.GetArray<int32_t>(n, "node levels");
    uint64_t most_links = 0;
    int highest = -1;
    for (int32_t level : levels) {
      NPHAND_THROW_CHECK(level >= 0 && level <= kMaxLevel, body.source(), ": an HNSW node level ", level,
                         " is outside 0..", kMaxLevel);
      most_links += 1 + g.maxM0_ + static_cast<uint64_t>(level) * (1 + g.maxM_);
      highest = std::max(highest, level);
    }
    // hnswlib draws a node's level with P(level >= l) = M^-l: the levels sum to about
    // n / (M - 1). A file claiming far more would only make Load allocate upper lists.
    const uint64_t level_sum = std::accumulate(levels.begin(), levels.end(), uint64_t{0});
    NPHAND_THROW_CHECK(level_sum <= 2 * n + kMaxLevel, body.source(), ": the HNSW node levels sum to ", level_sum,
                       ", more than a graph of ", n, " nodes has");
    const std::vector<uint32_t> links = body.GetArrayAtMost<uint32_t>(most_links, "link values");
    body.Finish();
    NPHAND_THROW_CHECK(n == 0 ? top == -1 : entry < n && top == highest && levels[entry] == top, body.source(),
                       ": the HNSW entry point (", entry, " at level ", top, ") is not a node of the top level");
    size_t at = 0;
    // The link list of `level` from the stream into `list` (count, then the nodes, each a
    // node of that level: a search follows it there).
    auto read_list = [&](hnswlib::linklistsizeint* list, int level, size_t limit) {
      NPHAND_THROW_CHECK(at < links.size(), body.source(), ": the HNSW link lists end early");
      const uint32_t count = links[at++];
      NPHAND_THROW_CHECK(count <= limit && links.size() - at >= count, body.source(), ": an HNSW link list of ", count,
                         " nodes (at most ", limit, ")");
      auto* nodes = reinterpret_cast<hnswlib::tableint*>(list + 1);
      for (uint32_t j = 0; j < count; ++j) {
        NPHAND_THROW_CHECK(links[at] < n && levels[links[at]] >= level, body.source(), ": an HNSW link at level ", level,
                           " to node ", links[at], " of ", n, " that is not on that level");
        nodes[j] = links[at++];
      }
      g.setListCount(list, static_cast<unsigned short>(count));
    };
    for (size_t i = 0; i < n; ++i) {
      std::memset(g.data_level0_memory_ + i * g.size_data_per_element_, 0, g.size_data_per_element_);
      g.element_levels_[i] = levels[i];
      g.linkLists_[i] = nullptr;
      g.cur_element_count = i + 1;  // from here the destructor frees node i's upper lists
      if (levels[i] > 0) {
        const size_t bytes = g.size_links_per_element_ * levels[i] + 1;
        g.linkLists_[i] = static_cast<char*>(std::calloc(bytes, 1));
        NPHAND_THROW_CHECK(g.linkLists_[i] != nullptr, body.source(), ": out of memory for the HNSW graph");
      }
      if (!sq8_) {
        const float* row = GraphRow(i);
        std::memcpy(g.getDataByInternalId(static_cast<hnswlib::tableint>(i)), &row, sizeof(row));
      }
      g.setExternalLabel(static_cast<hnswlib::tableint>(i), i);
      read_list(g.get_linklist0(static_cast<hnswlib::tableint>(i)), 0, g.maxM0_);
      for (int level = 1; level <= levels[i]; ++level) {
        read_list(g.get_linklist(static_cast<hnswlib::tableint>(i), level), level, g.maxM_);
      }
    }
    NPHAND_THROW_CHECK(at == links.size(), body.source(), ": ", links.size() - at, " link values after the last list");
    g.enterpoint_node_ = n == 0 ? static_cast<hnswlib::tableint>(-1) : entry;
    g.maxlevel_ = top;
  }

  // hnswlib-sq8, after Load: every node's codes, encoded from `db` in one pass straight into
  // the graph (no second copy of them, however briefly).
  void EncodeRows(const Database& db) {
    ForEachRow(db, set().ids, [&](size_t row, std::span<const float> hog) {
      Encode(hog, sq8_->step,
             reinterpret_cast<uint8_t*>(graph_->getDataByInternalId(static_cast<hnswlib::tableint>(row))));
    });
  }

  bool RowDistances(std::span<const float> query, std::span<const uint32_t> rows, float* out) const override {
    if (!sq8_) return KnnIndex::RowDistances(query, rows, out);
    std::vector<uint8_t> codes(query.size());
    Encode(query, sq8_->step, codes.data());
    const float step_squared = sq8_->step * sq8_->step;
    // The rows lie anywhere in the graph: each one's codes are asked for a few rows ahead.
    constexpr size_t kAhead = 4;
    auto node = [&](size_t i) {
      return reinterpret_cast<const uint8_t*>(graph_->getDataByInternalId(static_cast<hnswlib::tableint>(rows[i])));
    };
    for (size_t i = 0; i < rows.size(); ++i) {
      if (i + kAhead < rows.size()) {
        const uint8_t* ahead = node(i + kAhead);
        for (size_t line = 0; line < codes.size(); line += 64) __builtin_prefetch(ahead + line);
        __builtin_prefetch(ahead + codes.size() - 1);  // the codes need not start on a cache line
      }
      out[i] = static_cast<float>(CodeDistance(codes.data(), node(i), codes.size())) * step_squared;
    }
    return true;
  }

  std::string Backend() const override { return sq8_ ? "hnswlib-sq8" : "hnswlib"; }
  nlohmann::json Parameters() const override { return options_.ToJson(); }
  size_t MemoryBytes() const override {
    // Per node: its level-0 block, its upper-list pointer, its level, its lock and its slot
    // in the visited list; hnswlib's 65,536 update locks; the PCA, if any.
    size_t bytes = graph_->max_elements_ * (graph_->size_data_per_element_ + sizeof(void*) + sizeof(int) +
                                            sizeof(std::mutex) + sizeof(hnswlib::vl_type)) +
                   graph_->link_list_update_locks_.size() * sizeof(std::mutex) +
                   (mean_.size() + components_.size() + reduced_.size()) * sizeof(float);
    for (size_t i = 0; i < graph_->cur_element_count; ++i) {
      bytes += graph_->size_links_per_element_ * graph_->element_levels_[i];
    }
    return bytes;
  }

 protected:
  std::vector<std::pair<float, uint32_t>> SearchRows(std::span<const float> query, int k) const override {
    const size_t kk = std::min<size_t>(k, size());
    if (kk == 0) return {};
    if (options_.pca > 0) {
      const Eigen::Map<const Eigen::VectorXf> q(query.data(), query.size());
      const Eigen::Map<const Eigen::VectorXf> mean(mean_.data(), mean_.size());
      const Eigen::Map<const RowMatrix> components(components_.data(), options_.pca, query.size());
      const Eigen::VectorXf projected = components * (q - mean);
      const float* row = projected.data();
      auto heap = graph_->searchKnn(&row, std::min<size_t>(std::max<size_t>(options_.ef_search, kk), size()));
      std::vector<uint32_t> rows;
      for (; !heap.empty(); heap.pop()) rows.push_back(static_cast<uint32_t>(heap.top().second));
      return Rerank(set().descriptors, query, rows, static_cast<int>(kk));
    }
    std::vector<uint8_t> codes;
    const float* row = nullptr;
    return Found(graph_->searchKnn(GraphQuery(query, &codes, &row), kk));
  }

  // The 8-bit or float path only (an index through principal components searches as
  // SearchRows does): hnswlib's greedy descent of the upper layers, then its base layer's
  // search with a candidate list of max(effort, k), where searchKnn takes its ef_search.
  std::vector<std::pair<float, uint32_t>> SearchRowsWithEffort(std::span<const float> query, int k, int effort) const override {
    const size_t kk = std::min<size_t>(k, size());
    if (kk == 0) return {};
    if (options_.pca > 0) return SearchRows(query, k);
    std::vector<uint8_t> codes;
    const float* row = nullptr;
    const void* graph_query = GraphQuery(query, &codes, &row);
    const Graph& g = *graph_;
    hnswlib::tableint node = g.enterpoint_node_;
    float best = g.fstdistfunc_(graph_query, g.getDataByInternalId(node), g.dist_func_param_);
    for (int level = g.maxlevel_; level > 0; --level) {
      for (bool moved = true; moved;) {
        moved = false;
        unsigned int* links = g.get_linklist(node, level);
        const hnswlib::tableint* next = reinterpret_cast<const hnswlib::tableint*>(links + 1);
        for (int i = 0; i < g.getListCount(links); ++i) {
          const float d = g.fstdistfunc_(graph_query, g.getDataByInternalId(next[i]), g.dist_func_param_);
          if (d < best) {
            best = d;
            node = next[i];
            moved = true;
          }
        }
      }
    }
    // hnswlib 0.6's template arguments: no deletions, no metrics (later versions read them
    // otherwise).
    auto candidates = g.searchBaseLayerST<false, false>(node, graph_query, std::max<size_t>(effort, kk));
    while (candidates.size() > kk) candidates.pop();
    std::priority_queue<std::pair<float, hnswlib::labeltype>> heap;
    for (; !candidates.empty(); candidates.pop()) heap.emplace(candidates.top().first, g.getExternalLabel(candidates.top().second));
    return Found(std::move(heap));
  }

  std::vector<uint8_t> Body() const override {
    const Graph& g = *graph_;
    BodyWriter body;
    if (sq8_) body.Put<float>(sq8_->step);
    if (options_.pca > 0) {
      body.PutArray<float>(mean_);
      body.PutArray<float>(components_);
    }
    body.Put<int32_t>(size() == 0 ? -1 : g.maxlevel_);
    body.Put<uint32_t>(size() == 0 ? 0 : g.enterpoint_node_);
    std::vector<int32_t> levels(g.element_levels_.begin(), g.element_levels_.begin() + size());
    body.PutArray<int32_t>(levels);
    std::vector<uint32_t> links;
    auto write_list = [&](hnswlib::linklistsizeint* list) {
      const unsigned short count = g.getListCount(list);
      const auto* nodes = reinterpret_cast<const hnswlib::tableint*>(list + 1);
      links.push_back(count);
      links.insert(links.end(), nodes, nodes + count);
    };
    for (size_t i = 0; i < size(); ++i) {
      write_list(g.get_linklist0(static_cast<hnswlib::tableint>(i)));
      for (int level = 1; level <= levels[i]; ++level) write_list(g.get_linklist(static_cast<hnswlib::tableint>(i), level));
    }
    body.PutArray<uint32_t>(links);
    return body.Take();
  }

 private:
  // hnswlib's result heap as rows, nearest first.
  static std::vector<std::pair<float, uint32_t>> Found(std::priority_queue<std::pair<float, hnswlib::labeltype>> heap) {
    std::vector<std::pair<float, uint32_t>> found;
    found.reserve(heap.size());
    for (; !heap.empty(); heap.pop()) found.emplace_back(heap.top().first, static_cast<uint32_t>(heap.top().second));
    std::sort(found.begin(), found.end());
    return found;
  }

  // What the graph measures a query by: its 8-bit codes (into `codes`) or, as hnswlib's
  // float spaces take it, a pointer to the pointer `row` to its values.
  const void* GraphQuery(std::span<const float> query, std::vector<uint8_t>* codes, const float** row) const {
    *row = query.data();
    if (!sq8_) return row;
    codes->resize(query.size());
    Encode(query, sq8_->step, codes->data());
    return codes->data();
  }

  void MakeGraph() {
    graph_ = std::make_unique<Graph>(space_.get(), std::max<size_t>(size(), 1), options_.m, options_.ef_construction,
                                     options_.seed);
    graph_->setEf(options_.ef_search);
  }

  // Row i's codes, until the graph holds them.
  const uint8_t* Codes(size_t i) const { return sq8_->codes.data() + i * config().Dimension(); }
  void ReleaseCodes() {
    if (sq8_) std::vector<uint8_t>().swap(sq8_->codes);
  }

  // The row a graph node points to: the descriptor, or its projection.
  const float* GraphRow(size_t i) const {
    return options_.pca > 0 ? reduced_.data() + i * options_.pca : set().descriptors.Row(i).data();
  }

  // The mean and the first `pca` principal axes of up to kPcaSample rows drawn with the seed.
  void FitPca() {
    const size_t n = size(), d = static_cast<size_t>(config().Dimension());
    std::vector<size_t> sample(n);
    for (size_t i = 0; i < n; ++i) sample[i] = i;
    Random random(options_.seed);
    for (size_t i = 0; i < std::min(n, kPcaSample); ++i) std::swap(sample[i], sample[i + random.UniformIndex(n - i)]);
    sample.resize(std::min(n, kPcaSample));
    Eigen::MatrixXd rows(sample.size(), d);
    for (size_t r = 0; r < sample.size(); ++r) {
      const std::span<const float> row = set().descriptors.Row(sample[r]);
      for (size_t c = 0; c < d; ++c) rows(r, c) = row[c];
    }
    const Eigen::RowVectorXd mean = rows.colwise().mean();
    rows.rowwise() -= mean;
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> solver(rows.transpose() * rows);
    mean_.assign(mean.data(), mean.data() + d);
    components_.resize(static_cast<size_t>(options_.pca) * d);
    for (int p = 0; p < options_.pca; ++p) {  // eigenvalues ascend: the largest are last
      const Eigen::VectorXd axis = solver.eigenvectors().col(static_cast<Eigen::Index>(d) - 1 - p);
      for (size_t c = 0; c < d; ++c) components_[p * d + c] = static_cast<float>(axis[c]);
    }
    Project();
  }

  // Every row's projection onto the components.
  void Project() {
    const size_t n = size(), d = static_cast<size_t>(config().Dimension());
    const Eigen::Map<const RowMatrix> rows(set().descriptors.values().data(), n, d);
    const Eigen::Map<const Eigen::RowVectorXf> mean(mean_.data(), d);
    const Eigen::Map<const RowMatrix> components(components_.data(), options_.pca, d);
    reduced_.resize(n * options_.pca);
    Eigen::Map<RowMatrix> reduced(reduced_.data(), n, options_.pca);
    reduced.noalias() = (rows.rowwise() - mean) * components.transpose();
  }

  HnswOptions options_;
  std::optional<Sq8Codes> sq8_;  // hnswlib-sq8: the step (and, while building, the codes)
  std::unique_ptr<hnswlib::SpaceInterface<float>> space_;
  std::unique_ptr<Graph> graph_;
  std::vector<float> mean_, components_;  // PCA: d, and pca x d row-major
  std::vector<float> reduced_;            // PCA: the rows projected, n x pca
};

}  // namespace

std::unique_ptr<KnnIndex> BuildHnswlib(IndexedSet set, const HnswOptions& options, std::ostream* progress) {
  return BuildAdapter<HnswlibIndex>(std::move(set), options, progress);
}

std::unique_ptr<KnnIndex> LoadHnswlib(IndexedSet set, const HnswOptions& options, std::span<const uint8_t> body,
                                      const std::string& source) {
  return LoadAdapter<HnswlibIndex>(std::move(set), options, body, source);
}

std::unique_ptr<KnnIndex> BuildHnswlibSq8(IndexedSet set, const HnswOptions& options, std::ostream* progress) {
  const std::vector<float>& values = set.descriptors.values();
  Sq8Codes codes;
  codes.step = CodeStep(values.empty() ? 0.0f : *std::max_element(values.begin(), values.end()));
  const size_t d = static_cast<size_t>(set.descriptors.dimension());
  codes.codes.resize(set.descriptors.rows() * d);
  for (size_t r = 0; r < set.descriptors.rows(); ++r) Encode(set.descriptors.Row(r), codes.step, codes.codes.data() + r * d);
  IndexedSet ids{DescriptorMatrix(set.descriptors.config(), 0), std::move(set.ids)};
  set.descriptors = DescriptorMatrix(ids.descriptors.config(), 0);  // the float rows are not kept
  auto index = std::make_unique<HnswlibIndex>(std::move(ids), std::move(codes), options);
  index->Build(progress);
  return index;
}

std::unique_ptr<KnnIndex> LoadHnswlibSq8(const Database& db, std::vector<entry_id_t> ids, const HnswOptions& options,
                                         std::span<const uint8_t> body, const std::string& source) {
  BodyReader reader(body, source);
  Sq8Codes codes;
  codes.step = reader.Get<float>();
  NPHAND_THROW_CHECK(std::isfinite(codes.step) && codes.step > 0.0f, source, ": the 8-bit code step ", codes.step,
                     " is not a positive number");
  auto index = std::make_unique<HnswlibIndex>(IndexedSet{DescriptorMatrix(db.descriptor(), 0), std::move(ids)},
                                              std::move(codes), options);
  index->Load(reader);
  index->EncodeRows(db);
  return index;
}

}  // namespace nphand
