#include "nphand/index/flann_index.h"

#include <algorithm>

#include <flann/flann.hpp>

#include "nphand/index/exact_index.h"

namespace nphand {
namespace {

using FlannTree = flann::Index<flann::L2<float>>;

class FlannIndex : public KnnIndex {
 public:
  FlannIndex(IndexedSet set, const FlannOptions& options, std::ostream* progress)
      : KnnIndex(std::move(set)), options_(options) {
    if (size() == 0) return;
    if (progress != nullptr) *progress << "index build: flann: " << options_.algorithm << "\n";
    const DescriptorMatrix& rows = KnnIndex::set().descriptors;
    const flann::Matrix<float> data(const_cast<float*>(rows.values().data()), rows.rows(), rows.dimension());
    flann::IndexParams parameters;
    if (options_.algorithm == "kdtree") {
      parameters = flann::KDTreeIndexParams(options_.trees);
    } else {
      parameters = flann::KMeansIndexParams(options_.branching, options_.iterations, flann::FLANN_CENTERS_RANDOM, 0.2f);
    }
    tree_ = std::make_unique<FlannTree>(data, parameters);
    tree_->buildIndex();
  }

  std::string Backend() const override { return "flann"; }
  nlohmann::json Parameters() const override { return options_.ToJson(); }
  size_t MemoryBytes() const override { return tree_ == nullptr ? 0 : static_cast<size_t>(tree_->usedMemory()); }

 protected:
  std::vector<std::pair<float, uint32_t>> SearchRows(std::span<const float> query, int k) const override {
    const size_t kk = std::min<size_t>(k, size());
    if (kk == 0) return {};
    std::vector<size_t> ids(kk, static_cast<size_t>(-1));
    std::vector<float> distances(kk);
    const flann::Matrix<float> q(const_cast<float*>(query.data()), 1, query.size());
    flann::Matrix<size_t> id_matrix(ids.data(), 1, kk);
    flann::Matrix<float> distance_matrix(distances.data(), 1, kk);
    flann::SearchParams parameters(options_.checks);
    parameters.cores = 1;
    tree_->knnSearch(q, id_matrix, distance_matrix, kk, parameters);
    std::vector<uint32_t> rows;
    for (size_t id : ids) {
      if (id < size()) rows.push_back(static_cast<uint32_t>(id));
    }
    return Rerank(set().descriptors, query, rows, static_cast<int>(kk));
  }
  std::vector<uint8_t> Body() const override { return {}; }

 private:
  FlannOptions options_;
  std::unique_ptr<FlannTree> tree_;
};

}  // namespace

std::unique_ptr<KnnIndex> BuildFlann(IndexedSet set, const FlannOptions& options, std::ostream* progress) {
  return std::make_unique<FlannIndex>(std::move(set), options, progress);
}

}  // namespace nphand
