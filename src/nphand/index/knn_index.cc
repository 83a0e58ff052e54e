#include "nphand/index/knn_index.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Core>

#include "nphand/index/index_file.h"
#include "nphand/util/check.h"
#include "nphand/util/parallel.h"

namespace nphand {

std::vector<entry_id_t> DatabaseHandIds(const Database& db) {
  std::vector<entry_id_t> ids;
  ScanRecords(db, [&](size_t i) {
    if (db.Meta(i).has_hand) ids.push_back(static_cast<entry_id_t>(i));
  });
  return ids;
}

void ForEachRow(const Database& db, std::span<const entry_id_t> ids,
                const std::function<void(size_t row, std::span<const float> hog)>& visit) {
  size_t row = 0;
  ScanRecords(db, [&](size_t i) {
    if (row < ids.size() && ids[row] == i) {
      visit(row, db.Hog(i));
      ++row;
    }
  });
  NPHAND_CHECK(row == ids.size(), "the ids are not ascending entries of the database");
}

IndexedSet DatabaseDescriptors(const Database& db) { return DatabaseDescriptors(db, DatabaseHandIds(db)); }

IndexedSet DatabaseDescriptors(const Database& db, std::vector<entry_id_t> ids) {
  DescriptorMatrix descriptors(db.descriptor(), ids.size());
  ForEachRow(db, ids, [&](size_t row, std::span<const float> hog) {
    std::copy(hog.begin(), hog.end(), descriptors.MutableRow(row).begin());
  });
  return {std::move(descriptors), std::move(ids)};
}

namespace {

void CheckQuery(const DescriptorConfig& config, const Descriptor& query) {
  CheckSameDescriptor(config, query.config, "the query");
  NPHAND_THROW_CHECK(query.values.size() == static_cast<size_t>(config.Dimension()), "search: the query has ",
                     query.values.size(), " values, the index ", config.Dimension());
  NPHAND_THROW_CHECK(std::all_of(query.values.begin(), query.values.end(), [](float v) { return std::isfinite(v); }),
                     "search: the query has a value that is not a finite number");
}

}  // namespace

KnnIndex::KnnIndex(IndexedSet set) : set_(std::move(set)) {
  NPHAND_THROW_CHECK(std::adjacent_find(set_.ids.begin(), set_.ids.end(), std::greater_equal<>()) == set_.ids.end(),
                     "index: its entries must be ascending");
  row_of_.assign(set_.ids.empty() ? 0 : static_cast<size_t>(set_.ids.back()) + 1, kNoRow);
  for (size_t row = 0; row < set_.ids.size(); ++row) row_of_[set_.ids[row]] = static_cast<uint32_t>(row);
}

Neighbours KnnIndex::Search(const Descriptor& query, int k) const {
  NPHAND_THROW_CHECK(k >= 1, "search: k must be at least 1, not ", k);
  CheckQuery(config(), query);
  return NeighboursOf(SearchRows(query.values, k));
}

Neighbours KnnIndex::Search(const Descriptor& query, int k, int effort) const {
  NPHAND_THROW_CHECK(k >= 1, "search: k must be at least 1, not ", k);
  NPHAND_THROW_CHECK(effort >= 1, "search: the effort must be at least 1, not ", effort);
  CheckQuery(config(), query);
  return NeighboursOf(SearchRowsWithEffort(query.values, k, effort));
}

std::vector<std::pair<float, uint32_t>> KnnIndex::SearchRowsWithEffort(std::span<const float> query, int k, int) const {
  return SearchRows(query, k);
}

Neighbours KnnIndex::NeighboursOf(const std::vector<std::pair<float, uint32_t>>& rows) const {
  Neighbours neighbours;
  for (const auto& [distance, row] : rows) {
    neighbours.ids.push_back(set_.ids[row]);
    neighbours.distances.push_back(distance);
  }
  return neighbours;
}

bool KnnIndex::Distances(const Descriptor& query, std::span<const entry_id_t> ids, std::vector<float>* out) const {
  CheckQuery(config(), query);
  std::vector<uint32_t> rows(ids.size());
  for (size_t i = 0; i < ids.size(); ++i) {
    rows[i] = ids[i] < row_of_.size() ? row_of_[ids[i]] : kNoRow;
    NPHAND_THROW_CHECK(rows[i] != kNoRow, "search: entry ", ids[i], " is not in the index");
  }
  std::vector<float> distances(ids.size());
  if (!RowDistances(query.values, rows, distances.data())) return false;
  *out = std::move(distances);
  return true;
}

bool KnnIndex::RowDistances(std::span<const float> query, std::span<const uint32_t> rows, float* out) const {
  if (set_.descriptors.rows() != size()) return false;
  const Eigen::Map<const Eigen::VectorXf> q(query.data(), static_cast<Eigen::Index>(query.size()));
  for (size_t i = 0; i < rows.size(); ++i) {
    const std::span<const float> row = set_.descriptors.Row(rows[i]);
    out[i] = (q - Eigen::Map<const Eigen::VectorXf>(row.data(), static_cast<Eigen::Index>(row.size()))).squaredNorm();
  }
  return true;
}

std::vector<Neighbours> KnnIndex::SearchBatch(const DescriptorMatrix& queries, int k, int threads) const {
  CheckSameDescriptor(config(), queries.config(), "the queries");
  std::vector<Neighbours> results(queries.rows());
  ParallelFor(queries.rows(), threads, [&](size_t q, int) {
    const std::span<const float> row = queries.Row(q);
    results[q] = Search(Descriptor{queries.config(), std::vector<float>(row.begin(), row.end()), 0.0}, k);
  });
  return results;
}

nlohmann::json KnnIndex::Describe() const {
  return {{"backend", Backend()}, {"parameters", Parameters()}, {"entries", size()}, {"descriptor", ToJson(config())}};
}

void KnnIndex::Save(const std::filesystem::path& path, const Database& db) const {
  CheckSameDescriptor(config(), db.descriptor(), path.string() + ": the database");
  nlohmann::json meta = Describe();
  meta["database"] = {{"checksum", db.checksum()}, {"entries", db.size()}};
  WriteIndexFile(path, meta, Body());
}

}  // namespace nphand
