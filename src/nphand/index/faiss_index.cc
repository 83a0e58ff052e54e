#include "nphand/index/faiss_index.h"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include <faiss/Clustering.h>
#include <faiss/IndexFlat.h>
#include <faiss/IndexIVFFlat.h>
#include <faiss/IndexScalarQuantizer.h>
#include <faiss/impl/AuxIndexStructures.h>
#include <faiss/impl/DistanceComputer.h>
#include <faiss/impl/HNSW.h>
#include <faiss/utils/random.h>

#include "nphand/index/body.h"
#include "nphand/index/exact_index.h"
#include "nphand/util/check.h"
#include "nphand/util/progress.h"

namespace nphand {
namespace {

// FAISS's parallel regions (k-means, adding to lists) on one thread while an index is
// built, so that the same options give the same bytes; the caller's setting comes back.
class SingleThreaded {
 public:
  SingleThreaded() : threads_(omp_get_max_threads()) { omp_set_num_threads(1); }
  ~SingleThreaded() { omp_set_num_threads(threads_); }
  SingleThreaded(const SingleThreaded&) = delete;
  SingleThreaded& operator=(const SingleThreaded&) = delete;

 private:
  int threads_;
};

// Distances from a query to the rows of nphand's descriptor matrix, for FAISS's HNSW.
class RowDistance : public faiss::DistanceComputer {
 public:
  explicit RowDistance(const DescriptorMatrix& rows) : rows_(rows) {}
  void set_query(const float* x) override { query_ = {x, static_cast<size_t>(rows_.dimension())}; }
  float operator()(idx_t i) override { return SquaredDistance(query_, rows_.Row(static_cast<size_t>(i))); }
  float symmetric_dis(idx_t i, idx_t j) override {
    return SquaredDistance(rows_.Row(static_cast<size_t>(i)), rows_.Row(static_cast<size_t>(j)));
  }

 private:
  const DescriptorMatrix& rows_;
  std::span<const float> query_;
};

class FaissHnswIndex : public KnnIndex {
 public:
  FaissHnswIndex(IndexedSet set, const HnswOptions& options) : KnnIndex(std::move(set)), options_(options), hnsw_(options.m) {
    hnsw_.efConstruction = options.ef_construction;
    hnsw_.efSearch = options.ef_search;
  }

  // Inserts every row in order (FAISS's own add orders by level and runs in parallel).
  void Build(std::ostream* progress) {
    const size_t n = size();
    hnsw_.rng = faiss::RandomGenerator(static_cast<int64_t>(options_.seed));
    hnsw_.prepare_level_tab(n, false);
    std::vector<omp_lock_t> locks(n);
    for (omp_lock_t& lock : locks) omp_init_lock(&lock);
    faiss::VisitedTable visited(static_cast<int>(n));
    RowDistance distance(set().descriptors);
    ProgressLine line(progress, "index build: faiss-hnsw", n, "entries");
    for (size_t i = 0; i < n; ++i) {
      distance.set_query(set().descriptors.Row(i).data());
      hnsw_.add_with_locks(distance, hnsw_.levels[i] - 1, static_cast<int>(i), locks, visited);
      line.Update(i + 1);
    }
    line.Finish();
    for (omp_lock_t& lock : locks) omp_destroy_lock(&lock);
  }

  // The graph of a body, checked: levels within FAISS's table, every link -1 or a node of
  // its level, the entry point a node of the top level.
  void Load(BodyReader& body) {
    const size_t n = size();
    const int entry = body.Get<int32_t>(), top = body.Get<int32_t>();
    std::vector<int32_t> levels = body.GetArray<int32_t>(n, "node levels");
    const int most = static_cast<int>(hnsw_.cum_nneighbor_per_level.size()) - 1;
    hnsw_.offsets.assign(1, 0);
    int highest = -1;
    for (int32_t level : levels) {
      NPHAND_THROW_CHECK(level >= 1 && level <= most, body.source(), ": an HNSW node level ", level,
                         " is outside 1..", most);
      hnsw_.offsets.push_back(hnsw_.offsets.back() + hnsw_.cum_nb_neighbors(level));
      highest = std::max(highest, level - 1);
    }
    std::vector<int32_t> neighbours = body.GetArray<int32_t>(hnsw_.offsets.back(), "graph links");
    for (size_t i = 0; i < n; ++i) {
      for (int layer = 0; layer < levels[i]; ++layer) {
        const size_t begin = hnsw_.offsets[i] + hnsw_.cum_nb_neighbors(layer);
        const size_t end = hnsw_.offsets[i] + hnsw_.cum_nb_neighbors(layer + 1);
        for (size_t j = begin; j < end; ++j) {
          const int32_t v = neighbours[j];  // -1 ends a list; a search follows v on this layer
          NPHAND_THROW_CHECK(v == -1 || (v >= 0 && static_cast<size_t>(v) < n && levels[v] > layer), body.source(),
                             ": an HNSW link at level ", layer, " to node ", v, " of ", n, " that is not on that level");
        }
      }
    }
    NPHAND_THROW_CHECK(n == 0 ? entry == -1 && top == -1
                              : entry >= 0 && static_cast<size_t>(entry) < n && top == highest && levels[entry] - 1 == top,
                       body.source(), ": the HNSW entry point (", entry, " at level ", top, ") is not a node of the top level");
    body.Finish();
    hnsw_.levels = std::move(levels);
    hnsw_.neighbors = std::move(neighbours);
    hnsw_.entry_point = entry;
    hnsw_.max_level = top;
  }

  std::string Backend() const override { return "faiss-hnsw"; }
  nlohmann::json Parameters() const override { return options_.ToJson(); }
  size_t MemoryBytes() const override {
    return hnsw_.neighbors.size() * sizeof(int32_t) + hnsw_.levels.size() * sizeof(int) +
           hnsw_.offsets.size() * sizeof(size_t);
  }

 protected:
  std::vector<std::pair<float, uint32_t>> SearchRows(std::span<const float> query, int k) const override {
    const int kk = static_cast<int>(std::min<size_t>(k, size()));
    if (kk == 0) return {};
    RowDistance distance(set().descriptors);
    distance.set_query(query.data());
    faiss::VisitedTable visited(static_cast<int>(size()));
    std::vector<faiss::HNSW::idx_t> ids(kk, -1);  // a max-heap of size k, as FAISS expects
    std::vector<float> distances(kk, std::numeric_limits<float>::infinity());
    hnsw_.search(distance, kk, ids.data(), distances.data(), visited);
    std::vector<std::pair<float, uint32_t>> found;
    for (int i = 0; i < kk; ++i) {
      if (ids[i] >= 0) found.emplace_back(distances[i], static_cast<uint32_t>(ids[i]));
    }
    std::sort(found.begin(), found.end());
    return found;
  }

  std::vector<uint8_t> Body() const override {
    BodyWriter body;
    body.Put<int32_t>(hnsw_.entry_point);
    body.Put<int32_t>(hnsw_.max_level);
    body.PutArray<int32_t>(hnsw_.levels);
    body.PutArray<int32_t>(hnsw_.neighbors);
    return body.Take();
  }

 private:
  HnswOptions options_;
  faiss::HNSW hnsw_;
};

class FaissIvfIndex : public KnnIndex {
 public:
  FaissIvfIndex(IndexedSet set, const IvfOptions& options) : KnnIndex(std::move(set)), options_(options) {
    const size_t n = size();
    if (options_.lists == 0) options_.lists = static_cast<int>(std::lround(4.0 * std::sqrt(static_cast<double>(n))));
    options_.lists = static_cast<int>(std::clamp<size_t>(options_.lists, 1, std::max<size_t>(n, 1)));
    quantizer_ = std::make_unique<faiss::IndexFlatL2>(config().Dimension());
  }

  void Build(std::ostream* progress) {
    const SingleThreaded single;
    const size_t n = size();
    const int d = config().Dimension();
    const float* data = set().descriptors.values().data();
    if (progress != nullptr) *progress << "index build: faiss-ivf: k-means, " << options_.lists << " cells\n";
    faiss::ClusteringParameters parameters;
    parameters.niter = options_.iterations;
    parameters.seed = static_cast<int>(options_.seed);  // IvfOptions::Check keeps it below 2^31
    faiss::Clustering clustering(d, options_.lists, parameters);
    clustering.train(static_cast<faiss::Index::idx_t>(n), data, *quantizer_);
    cells_.resize(n);
    std::vector<faiss::Index::idx_t> assigned(n);
    quantizer_->assign(static_cast<faiss::Index::idx_t>(n), data, assigned.data());
    for (size_t i = 0; i < n; ++i) cells_[i] = static_cast<int32_t>(assigned[i]);
    MakeLists();
    if (options_.encoding == "sq8") {
      auto* sq = static_cast<faiss::IndexIVFScalarQuantizer*>(ivf_.get());
      sq->train_residual(static_cast<faiss::Index::idx_t>(n), data);
    }
    Fill();
  }

  // Centroids, every row's cell and (sq8) the quantiser's ranges, checked.
  void Load(BodyReader& body) {
    const size_t n = size(), d = static_cast<size_t>(config().Dimension());
    const std::vector<float> centroids = body.GetArray<float>(static_cast<uint64_t>(options_.lists) * d, "centroid values");
    NPHAND_THROW_CHECK(std::all_of(centroids.begin(), centroids.end(), [](float v) { return std::isfinite(v); }),
                       body.source(), ": a centroid value is not a finite number");
    cells_ = body.GetArray<int32_t>(n, "cell numbers");
    for (int32_t cell : cells_) {
      NPHAND_THROW_CHECK(cell >= 0 && cell < options_.lists, body.source(), ": a row's cell ", cell, " is not one of the ",
                         options_.lists);
    }
    quantizer_->add(options_.lists, centroids.data());
    MakeLists();
    if (options_.encoding == "sq8") {
      auto* sq = static_cast<faiss::IndexIVFScalarQuantizer*>(ivf_.get());
      std::vector<float> ranges = body.GetArray<float>(sq->sq.trained.size(), "quantiser ranges");
      NPHAND_THROW_CHECK(std::all_of(ranges.begin(), ranges.end(), [](float v) { return std::isfinite(v); }),
                         body.source(), ": a quantiser range is not a finite number");
      sq->sq.trained = std::move(ranges);
    }
    body.Finish();
    const SingleThreaded single;
    Fill();
  }

  std::string Backend() const override { return "faiss-ivf"; }
  nlohmann::json Parameters() const override { return options_.ToJson(); }
  size_t MemoryBytes() const override {
    size_t bytes = quantizer_->codes.size() + cells_.size() * sizeof(int32_t);
    for (size_t list = 0; list < ivf_->nlist; ++list) {
      bytes += ivf_->invlists->list_size(list) * (ivf_->code_size + sizeof(faiss::Index::idx_t));
    }
    return bytes;
  }

 protected:
  std::vector<std::pair<float, uint32_t>> SearchRows(std::span<const float> query, int k) const override {
    const int kk = static_cast<int>(std::min<size_t>(k, size()));
    if (kk == 0) return {};
    const size_t fetch = std::min<size_t>(options_.encoding == "sq8" ? size_t{1} * kk * options_.rerank : kk, size());
    std::vector<faiss::Index::idx_t> ids(fetch);
    std::vector<float> distances(fetch);
    // The cells first, then a search of them with no statistics: IndexIVF::search adds to
    // FAISS's global, unsynchronised indexIVF_stats, which concurrent searches would race on.
    const size_t probes = std::min<size_t>(options_.probes, ivf_->nlist);
    std::vector<faiss::Index::idx_t> cells(probes);
    std::vector<float> cell_distances(probes);
    quantizer_->search(1, query.data(), static_cast<faiss::Index::idx_t>(probes), cell_distances.data(), cells.data());
    faiss::SearchParametersIVF parameters;
    parameters.nprobe = probes;
    ivf_->search_preassigned(1, query.data(), static_cast<faiss::Index::idx_t>(fetch), cells.data(),
                             cell_distances.data(), distances.data(), ids.data(), false, &parameters, nullptr);
    std::vector<uint32_t> rows;
    for (faiss::Index::idx_t id : ids) {
      if (id >= 0) rows.push_back(static_cast<uint32_t>(id));
    }
    return Rerank(set().descriptors, query, rows, kk);
  }

  std::vector<uint8_t> Body() const override {
    BodyWriter body;
    const auto* centroids = reinterpret_cast<const float*>(quantizer_->codes.data());
    body.PutArray<float>({centroids, quantizer_->codes.size() / sizeof(float)});
    body.PutArray<int32_t>(cells_);
    if (options_.encoding == "sq8") body.PutArray<float>(static_cast<const faiss::IndexIVFScalarQuantizer*>(ivf_.get())->sq.trained);
    return body.Take();
  }

 private:
  void MakeLists() {
    const int d = config().Dimension();
    if (options_.encoding == "sq8") {
      ivf_ = std::make_unique<faiss::IndexIVFScalarQuantizer>(quantizer_.get(), d, options_.lists,
                                                              faiss::ScalarQuantizer::QT_8bit);
      auto* sq = static_cast<faiss::IndexIVFScalarQuantizer*>(ivf_.get());
      sq->sq.trained.assign(2 * static_cast<size_t>(d), 0.0f);
    } else {
      ivf_ = std::make_unique<faiss::IndexIVFFlat>(quantizer_.get(), d, options_.lists);
    }
  }
  // Every row into its cell (row numbers are the ids).
  void Fill() {
    ivf_->is_trained = true;
    std::vector<faiss::Index::idx_t> cells(cells_.begin(), cells_.end());
    ivf_->add_core(static_cast<faiss::Index::idx_t>(size()), set().descriptors.values().data(), nullptr, cells.data());
  }

  IvfOptions options_;
  std::unique_ptr<faiss::IndexFlatL2> quantizer_;
  std::unique_ptr<faiss::IndexIVF> ivf_;
  std::vector<int32_t> cells_;
};

}  // namespace

std::unique_ptr<KnnIndex> BuildFaissHnsw(IndexedSet set, const HnswOptions& options, std::ostream* progress) {
  return BuildAdapter<FaissHnswIndex>(std::move(set), options, progress);
}

std::unique_ptr<KnnIndex> LoadFaissHnsw(IndexedSet set, const HnswOptions& options, std::span<const uint8_t> body,
                                        const std::string& source) {
  return LoadAdapter<FaissHnswIndex>(std::move(set), options, body, source);
}

std::unique_ptr<KnnIndex> BuildFaissIvf(IndexedSet set, const IvfOptions& options, std::ostream* progress) {
  return BuildAdapter<FaissIvfIndex>(std::move(set), options, progress);
}

std::unique_ptr<KnnIndex> LoadFaissIvf(IndexedSet set, const IvfOptions& options, std::span<const uint8_t> body,
                                       const std::string& source) {
  return LoadAdapter<FaissIvfIndex>(std::move(set), options, body, source);
}

}  // namespace nphand
