#include "nphand/index/backends.h"

#include <algorithm>

#include "nphand/index/exact_index.h"
#include "nphand/index/faiss_index.h"
#include "nphand/index/flann_index.h"
#include "nphand/index/hnswlib_index.h"
#include "nphand/index/index_file.h"
#include "nphand/util/check.h"

namespace nphand {
namespace {

using Parameters = nlohmann::json;
using Body = std::vector<uint8_t>;

// One backend: its name, whether its index file holds a body, how its options are checked,
// how it builds an index and how it loads one (over the entries of `db` with a hand, `ids`).
struct BackendRow {
  const char* name;
  bool has_body;
  bool (*check)(const IndexOptions& options, std::string* why);
  std::unique_ptr<KnnIndex> (*build)(IndexedSet set, const IndexOptions& options, std::ostream* progress);
  std::unique_ptr<KnnIndex> (*load)(const Parameters& parameters, const Database& db, std::vector<entry_id_t> ids,
                                    const Body& body, const std::string& source);
};

// HNSW options without a PCA projection (only hnswlib has one).
bool CheckHnswWithoutPca(const IndexOptions& options, std::string* why) {
  if (options.hnsw.pca != 0) {
    *why = "the PCA projection (hnsw pca) is an option of hnswlib, not of " + options.backend;
    return false;
  }
  return options.hnsw.Check(why);
}

HnswOptions HnswWithoutPca(const Parameters& parameters, const char* backend, const std::string& source) {
  const HnswOptions options = HnswOptions::FromJson(parameters, source);
  NPHAND_THROW_CHECK(options.pca == 0, source, ": ", backend, " index has no PCA projection");
  return options;
}

const std::vector<BackendRow>& Registry() {
  static const std::vector<BackendRow> rows = {
      {"exact", false, [](const IndexOptions&, std::string*) { return true; },
       [](IndexedSet set, const IndexOptions&, std::ostream*) -> std::unique_ptr<KnnIndex> {
         return std::make_unique<ExactIndex>(std::move(set));
       },
       [](const Parameters& parameters, const Database& db, std::vector<entry_id_t> ids, const Body&,
          const std::string& source) -> std::unique_ptr<KnnIndex> {
         NPHAND_THROW_CHECK(parameters.empty(), source, ": an exact index has no parameters");
         return std::make_unique<ExactIndex>(DatabaseDescriptors(db, std::move(ids)));
       }},
      {"lsh", false, [](const IndexOptions& options, std::string* why) { return options.lsh.Check(why); },
       [](IndexedSet set, const IndexOptions& options, std::ostream* progress) -> std::unique_ptr<KnnIndex> {
         return std::make_unique<LshIndex>(std::move(set), options.lsh, progress);
       },
       [](const Parameters& parameters, const Database& db, std::vector<entry_id_t> ids, const Body&,
          const std::string& source) -> std::unique_ptr<KnnIndex> {
         return LshIndex::FromParameters(DatabaseDescriptors(db, std::move(ids)), parameters, source);
       }},
      {"faiss-hnsw", true, CheckHnswWithoutPca,
       [](IndexedSet set, const IndexOptions& options, std::ostream* progress) {
         return BuildFaissHnsw(std::move(set), options.hnsw, progress);
       },
       [](const Parameters& parameters, const Database& db, std::vector<entry_id_t> ids, const Body& body,
          const std::string& source) {
         const HnswOptions options = HnswWithoutPca(parameters, "a faiss-hnsw", source);
         return LoadFaissHnsw(DatabaseDescriptors(db, std::move(ids)), options, body, source);
       }},
      {"faiss-ivf", true, [](const IndexOptions& options, std::string* why) { return options.ivf.Check(why); },
       [](IndexedSet set, const IndexOptions& options, std::ostream* progress) {
         return BuildFaissIvf(std::move(set), options.ivf, progress);
       },
       [](const Parameters& parameters, const Database& db, std::vector<entry_id_t> ids, const Body& body,
          const std::string& source) {
         return LoadFaissIvf(DatabaseDescriptors(db, std::move(ids)), IvfOptions::FromJson(parameters, source), body,
                             source);
       }},
      {"hnswlib", true, [](const IndexOptions& options, std::string* why) { return options.hnsw.Check(why); },
       [](IndexedSet set, const IndexOptions& options, std::ostream* progress) {
         return BuildHnswlib(std::move(set), options.hnsw, progress);
       },
       [](const Parameters& parameters, const Database& db, std::vector<entry_id_t> ids, const Body& body,
          const std::string& source) {
         return LoadHnswlib(DatabaseDescriptors(db, std::move(ids)), HnswOptions::FromJson(parameters, source), body,
                            source);
       }},
      {"hnswlib-sq8", true, CheckHnswWithoutPca,
       [](IndexedSet set, const IndexOptions& options, std::ostream* progress) {
         return BuildHnswlibSq8(std::move(set), options.hnsw, progress);
       },
       [](const Parameters& parameters, const Database& db, std::vector<entry_id_t> ids, const Body& body,
          const std::string& source) {
         const HnswOptions options = HnswWithoutPca(parameters, "an hnswlib-sq8", source);
         return LoadHnswlibSq8(db, std::move(ids), options, body, source);
       }},
      {"flann", false, [](const IndexOptions& options, std::string* why) { return options.flann.Check(why); },
       [](IndexedSet set, const IndexOptions& options, std::ostream* progress) {
         return BuildFlann(std::move(set), options.flann, progress);
       },
       [](const Parameters& parameters, const Database& db, std::vector<entry_id_t> ids, const Body&,
          const std::string& source) {
         return BuildFlann(DatabaseDescriptors(db, std::move(ids)), FlannOptions::FromJson(parameters, source), nullptr);
       }},
  };
  return rows;
}

const BackendRow* FindBackend(const std::string& name) {
  for (const BackendRow& row : Registry()) {
    if (name == row.name) return &row;
  }
  return nullptr;
}

}  // namespace

const std::vector<std::string>& IndexBackends() {
  static const std::vector<std::string> backends = [] {
    std::vector<std::string> names;
    for (const BackendRow& row : Registry()) names.push_back(row.name);
    return names;
  }();
  return backends;
}

IndexOptions IndexOptions::Exact() {
  IndexOptions options;
  options.backend = "exact";
  return options;
}

bool IndexOptions::Check(std::string* why) const {
  const BackendRow* row = FindBackend(backend);
  if (row == nullptr) {
    *why = "unknown index backend '" + backend + "' (known:";
    for (const std::string& name : IndexBackends()) *why += (why->back() == ':' ? " " : ", ") + name;
    *why += ")";
    return false;
  }
  return row->check(*this, why);
}

std::unique_ptr<KnnIndex> BuildIndex(const Database& db, const IndexOptions& options, std::ostream* progress) {
  return BuildIndex(DatabaseDescriptors(db), options, progress);
}

std::unique_ptr<KnnIndex> BuildIndex(IndexedSet set, const IndexOptions& options, std::ostream* progress) {
  std::string why;
  NPHAND_THROW_CHECK(options.Check(&why), "index build: ", why);
  NPHAND_THROW_CHECK(!set.ids.empty(), "index build: the database has no entry with a hand to index");
  return FindBackend(options.backend)->build(std::move(set), options, progress);
}

std::unique_ptr<KnnIndex> LoadIndex(const std::filesystem::path& path, const Database& db) {
  IndexFile file = ReadIndexFile(path);
  const std::string source = path.string();
  const std::string built_from = file.meta["database"]["checksum"].get<std::string>();
  NPHAND_THROW_CHECK(built_from == db.checksum(), source, ": built from another database (checksum ", built_from,
                     "; this one's is ", db.checksum(), "); rebuild it with nphand index build");
  CheckSameDescriptor(db.descriptor(), file.descriptor, source);
  std::vector<entry_id_t> ids = DatabaseHandIds(db);
  NPHAND_THROW_CHECK(file.meta["entries"].get<uint64_t>() == ids.size(), source, ": indexes ",
                     file.meta["entries"].get<uint64_t>(), " entries, the database has ", ids.size(), " with a hand");
  const std::string backend = file.meta["backend"].get<std::string>();
  const BackendRow* row = FindBackend(backend);
  NPHAND_THROW_CHECK(row != nullptr, source, ": unknown index backend '", backend, "'");
  NPHAND_THROW_CHECK(row->has_body || file.body.empty(), source, ": the ", backend, " backend has no body, the file holds ",
                     file.body.size(), " bytes");
  return row->load(file.meta["parameters"], db, std::move(ids), file.body, source);
}

nlohmann::json ReadIndexMeta(const std::filesystem::path& path) { return ReadIndexFile(path).meta; }

}  // namespace nphand
