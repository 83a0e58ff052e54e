// The index stage: the K nearest database entries of a descriptor (paper Sec. 5.1). One
// small interface, KnnIndex, with ExactIndex as its exact twin (the ground truth of every
// recall figure); the approximate backends implement the same interface. Third-party
// types stay in the backends' .cc files.
//
// Index file, version 1 (little-endian): "NPHANDIX" | u32 version | u32 meta length M | M
// bytes of JSON meta (backend, parameters, descriptor config, the checksum and size of the
// database it was built from) | u64 body length B | B bytes of the backend's body | u32
// CRC-32 of everything before it. Written atomically; a corrupt, truncated, foreign or
// other-version file, or one built from another database, is refused by name.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "nphand/db/database.h"
#include "nphand/features/descriptor.h"
#include "nphand/util/ids.h"

namespace nphand {

inline constexpr uint32_t kIndexVersion = 1;

// What an index searches: descriptors, one row per database entry with a hand, and the
// entry id of each row.
struct IndexedSet {
  DescriptorMatrix descriptors;
  std::vector<entry_id_t> ids;
};
// The entries of `db` that show a hand, in order.
std::vector<entry_id_t> DatabaseHandIds(const Database& db);
// The stored descriptors of every entry of `db` that shows a hand (one contiguous copy).
IndexedSet DatabaseDescriptors(const Database& db);
// The same for the entries `ids` (ascending) of `db`.
IndexedSet DatabaseDescriptors(const Database& db, std::vector<entry_id_t> ids);
// Calls visit(row, descriptor) for each entry ids[row] (ascending) of `db`, in one pass
// that leaves none of the file resident (see ScanRecords).
void ForEachRow(const Database& db, std::span<const entry_id_t> ids,
                const std::function<void(size_t row, std::span<const float> hog)>& visit);

struct Neighbours {
  std::vector<entry_id_t> ids;   // nearest first
  std::vector<float> distances;  // squared L2, ascending
};

class KnnIndex {
 public:
  virtual ~KnnIndex() = default;
  KnnIndex(const KnnIndex&) = delete;
  KnnIndex& operator=(const KnnIndex&) = delete;

  // "exact", "lsh", "faiss-hnsw", ...
  virtual std::string Backend() const = 0;
  // The backend's parameters, as written in the index file.
  virtual nlohmann::json Parameters() const = 0;

  const DescriptorConfig& config() const { return set_.descriptors.config(); }
  size_t size() const { return set_.ids.size(); }
  // The k nearest entries of `query` (all of them when the index holds fewer). Throws
  // nphand::Error, naming both configs, when the query was described differently.
  Neighbours Search(const Descriptor& query, int k) const;
  // The same with less effort where the backend has a measure of it: hnswlib's candidate
  // list is `effort` (at least k) instead of its ef_search (but through principal
  // components, where it re-ranks). The other backends search as Search does. Throws as
  // Search, and for an effort under 1.
  Neighbours Search(const Descriptor& query, int k, int effort) const;
  // The squared distances from `query` to the entries `ids` (each one the index holds), as
  // its search measures them (an index of 8-bit codes by the codes), into `out`. False,
  // `out` untouched, for a backend that keeps nothing to measure with. Throws as Search.
  bool Distances(const Descriptor& query, std::span<const entry_id_t> ids, std::vector<float>* out) const;
  // The entries the index holds, ascending.
  const std::vector<entry_id_t>& ids() const { return set_.ids; }
  // Search for every row of `queries`, on `threads` threads (0: all cores); equal to one
  // Search per row.
  std::vector<Neighbours> SearchBatch(const DescriptorMatrix& queries, int k, int threads = 1) const;
  // Bytes of memory the backend holds beyond the descriptors it shares with every backend.
  virtual size_t MemoryBytes() const = 0;
  // Backend, parameters, entries, descriptor: for `nphand index info`.
  nlohmann::json Describe() const;

  // Writes the index file (atomically) for the database it was built from.
  void Save(const std::filesystem::path& path, const Database& db) const;

 protected:
  explicit KnnIndex(IndexedSet set);
  const IndexedSet& set() const { return set_; }
  // The k nearest rows of the set: (squared distance, row), ascending, ties by row.
  virtual std::vector<std::pair<float, uint32_t>> SearchRows(std::span<const float> query, int k) const = 0;
  // SearchRows with a candidate list of `effort` where the backend keeps one; this one
  // ignores it.
  virtual std::vector<std::pair<float, uint32_t>> SearchRowsWithEffort(std::span<const float> query, int k, int effort) const;
  // Distances for rows; this one measures the set's descriptor rows (false without them).
  virtual bool RowDistances(std::span<const float> query, std::span<const uint32_t> rows, float* out) const;
  // What the backend needs, beyond the set, to be loaded again.
  virtual std::vector<uint8_t> Body() const = 0;

 private:
  // Rows (squared distance, row) as entries.
  Neighbours NeighboursOf(const std::vector<std::pair<float, uint32_t>>& rows) const;
  IndexedSet set_;
  // By entry id, up to the largest the set holds: its row, or kNoRow. Distances looks up a
  // track's thousand-odd entries a frame; a binary search of the ids cost a quarter of a
  // millisecond of it (their cache misses), this table a few microseconds. It takes 4 bytes
  // per database entry up to the largest held (about 1 MB), shared by every backend and so
  // not in MemoryBytes.
  static constexpr uint32_t kNoRow = UINT32_MAX;
  std::vector<uint32_t> row_of_;
};

}  // namespace nphand
