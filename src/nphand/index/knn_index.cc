#include "nphand/index/knn_index.h"

#include <cstring>

#include <zlib.h>

#include "nphand/index/exact_index.h"
#include "nphand/util/check.h"
#include "nphand/util/io.h"
#include "nphand/util/parallel.h"

namespace nphand {
namespace {

constexpr char kMagic[8] = {'N', 'P', 'H', 'A', 'N', 'D', 'I', 'X'};

template <typename T>
void Put(std::vector<uint8_t>* out, T value) {
  const size_t at = out->size();
  out->resize(at + sizeof(T));
  std::memcpy(out->data() + at, &value, sizeof(T));
}

template <typename T>
T Get(const uint8_t* p) {
  T value;
  std::memcpy(&value, p, sizeof(T));
  return value;
}

uint32_t Crc(const uint8_t* data, size_t size) {
  uint32_t crc = 0;
  while (size > 0) {
    const uInt chunk = static_cast<uInt>(std::min<size_t>(size, 1u << 30));
    crc = static_cast<uint32_t>(crc32(crc, data, chunk));
    data += chunk;
    size -= chunk;
  }
  return crc;
}

// An index file taken apart: its meta (checked) and its backend's body.
struct IndexFile {
  nlohmann::json meta;
  DescriptorConfig descriptor;
  std::vector<uint8_t> body;
};

IndexFile ReadIndexFile(const std::filesystem::path& path) {
  const std::string source = path.string();
  const std::vector<uint8_t> bytes = ReadFileBytes(path);
  const size_t size = bytes.size();
  NPHAND_THROW_CHECK(size >= 12 && std::memcmp(bytes.data(), kMagic, 8) == 0, source,
                     ": not an nphand index (bad magic)");
  const uint32_t version = Get<uint32_t>(bytes.data() + 8);
  NPHAND_THROW_CHECK(version == kIndexVersion, source, ": index format version ", version,
                     " is not supported (this nphand reads version ", kIndexVersion, "; rebuild with nphand index build)");
  NPHAND_THROW_CHECK(size >= 16, source, ": truncated");
  const uint64_t meta_bytes = Get<uint32_t>(bytes.data() + 12);
  NPHAND_THROW_CHECK(16 + meta_bytes + 8 <= size, source, ": truncated");
  const uint64_t body_bytes = Get<uint64_t>(bytes.data() + 16 + meta_bytes);
  const uint64_t body = 16 + meta_bytes + 8;
  NPHAND_THROW_CHECK(body_bytes <= size && body + body_bytes + 4 <= size, source, ": truncated");
  NPHAND_THROW_CHECK(body + body_bytes + 4 == size, source, ": ", size - body - body_bytes - 4,
                     " bytes after the end of the index");
  NPHAND_THROW_CHECK(Crc(bytes.data(), size - 4) == Get<uint32_t>(bytes.data() + size - 4), source,
                     ": checksum mismatch (the file is corrupt)");

  IndexFile file;
  file.meta = nlohmann::json::parse(bytes.begin() + 16, bytes.begin() + 16 + meta_bytes, nullptr, false);
  const nlohmann::json& m = file.meta;
  const bool valid = m.is_object() && m.contains("backend") && m["backend"].is_string() && m.contains("parameters") &&
                     m["parameters"].is_object() && m.contains("entries") && m["entries"].is_number_unsigned() &&
                     m.contains("descriptor") && m.contains("database") && m["database"].is_object() &&
                     m["database"].contains("checksum") && m["database"]["checksum"].is_string() &&
                     m["database"].contains("entries") && m["database"]["entries"].is_number_unsigned();
  NPHAND_THROW_CHECK(valid, source, ": the index's meta lacks a field or has one of the wrong type");
  file.descriptor = DescriptorConfigFromJson(m["descriptor"], source);
  file.body.assign(bytes.begin() + body, bytes.begin() + body + body_bytes);
  return file;
}

std::unique_ptr<KnnIndex> MakeIndex(const std::string& backend, const nlohmann::json& parameters, IndexedSet set,
                                    const std::vector<uint8_t>& body, const std::string& source) {
  if (backend == "exact") {
    NPHAND_THROW_CHECK(body.empty() && parameters.empty(), source, ": an exact index has no body or parameters");
    return std::make_unique<ExactIndex>(std::move(set));
  }
  NPHAND_THROW(source, ": unknown index backend '", backend, "'");
}

}  // namespace

IndexedSet DatabaseDescriptors(const Database& db) {
  std::vector<entry_id_t> ids;
  for (size_t i = 0; i < db.size(); ++i) {
    if (db.Meta(i).has_hand) ids.push_back(static_cast<entry_id_t>(i));
  }
  DescriptorMatrix descriptors(db.descriptor(), ids.size());
  for (size_t r = 0; r < ids.size(); ++r) {
    const std::span<const float> hog = db.Hog(ids[r]);
    std::copy(hog.begin(), hog.end(), descriptors.MutableRow(r).begin());
  }
  return {std::move(descriptors), std::move(ids)};
}

Neighbours KnnIndex::Search(const Descriptor& query, int k) const {
  CheckSameDescriptor(config(), query.config, "the query");
  NPHAND_THROW_CHECK(k >= 1, "search: k must be at least 1, not ", k);
  NPHAND_THROW_CHECK(query.values.size() == static_cast<size_t>(config().Dimension()), "search: the query has ",
                     query.values.size(), " values, the index ", config().Dimension());
  Neighbours neighbours;
  for (const auto& [distance, row] : SearchRows(query.values, k)) {
    neighbours.ids.push_back(set_.ids[row]);
    neighbours.distances.push_back(distance);
  }
  return neighbours;
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
  const std::string text = meta.dump();
  const std::vector<uint8_t> body = Body();
  std::vector<uint8_t> bytes(kMagic, kMagic + 8);
  Put<uint32_t>(&bytes, kIndexVersion);
  Put<uint32_t>(&bytes, static_cast<uint32_t>(text.size()));
  bytes.insert(bytes.end(), text.begin(), text.end());
  Put<uint64_t>(&bytes, body.size());
  bytes.insert(bytes.end(), body.begin(), body.end());
  Put<uint32_t>(&bytes, Crc(bytes.data(), bytes.size()));
  WriteFileAtomic(path, bytes);
}

bool IndexOptions::Check(std::string* why) const {
  if (backend != "exact") {
    *why = "unknown index backend '" + backend + "' (known: exact)";
    return false;
  }
  return true;
}

std::unique_ptr<KnnIndex> BuildIndex(const Database& db, const IndexOptions& options) {
  std::string why;
  NPHAND_THROW_CHECK(options.Check(&why), "index build: ", why);
  return MakeIndex(options.backend, nlohmann::json::object(), DatabaseDescriptors(db), {}, "index build");
}

std::unique_ptr<KnnIndex> LoadIndex(const std::filesystem::path& path, const Database& db) {
  IndexFile file = ReadIndexFile(path);
  const std::string source = path.string();
  NPHAND_THROW_CHECK(file.meta["database"]["checksum"].get<std::string>() == db.checksum(), source,
                     ": built from another database (checksum ", file.meta["database"]["checksum"].get<std::string>(),
                     "; this one's is ", db.checksum(), "); rebuild it with nphand index build");
  CheckSameDescriptor(db.descriptor(), file.descriptor, source);
  IndexedSet set = DatabaseDescriptors(db);
  NPHAND_THROW_CHECK(file.meta["entries"].get<uint64_t>() == set.ids.size(), source, ": indexes ",
                     file.meta["entries"].get<uint64_t>(), " entries, the database has ", set.ids.size(), " with a hand");
  return MakeIndex(file.meta["backend"].get<std::string>(), file.meta["parameters"], std::move(set), file.body, source);
}

nlohmann::json ReadIndexMeta(const std::filesystem::path& path) { return ReadIndexFile(path).meta; }

}  // namespace nphand
