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

// The backend of an index file from its name, parameters and body, over the entries of
// `db` with a hand (`ids`).
std::unique_ptr<KnnIndex> LoadBackend(const std::string& backend, const nlohmann::json& parameters,
                                      const Database& db, std::vector<entry_id_t> ids,
                                      const std::vector<uint8_t>& body, const std::string& source) {
  const bool has_body =
      backend == "faiss-hnsw" || backend == "faiss-ivf" || backend == "hnswlib" || backend == "hnswlib-sq8";
  NPHAND_THROW_CHECK(has_body || body.empty(), source, ": the ", backend, " backend has no body, the file holds ",
                     body.size(), " bytes");
  if (backend == "hnswlib-sq8") {
    const HnswOptions options = HnswOptions::FromJson(parameters, source);
    NPHAND_THROW_CHECK(options.pca == 0, source, ": an hnswlib-sq8 index has no PCA projection");
    return LoadHnswlibSq8(db, std::move(ids), options, body, source);
  }
  IndexedSet set = DatabaseDescriptors(db, std::move(ids));
  if (backend == "exact") {
    NPHAND_THROW_CHECK(parameters.empty(), source, ": an exact index has no parameters");
    return std::make_unique<ExactIndex>(std::move(set));
  }
  if (backend == "lsh") {
    return LshIndex::FromParameters(std::move(set), parameters, source);
  }
  if (backend == "faiss-hnsw") {
    const HnswOptions options = HnswOptions::FromJson(parameters, source);
    NPHAND_THROW_CHECK(options.pca == 0, source, ": a faiss-hnsw index has no PCA projection");
    return LoadFaissHnsw(std::move(set), options, body, source);
  }
  if (backend == "hnswlib") return LoadHnswlib(std::move(set), HnswOptions::FromJson(parameters, source), body, source);
  if (backend == "faiss-ivf") return LoadFaissIvf(std::move(set), IvfOptions::FromJson(parameters, source), body, source);
  if (backend == "flann") return BuildFlann(std::move(set), FlannOptions::FromJson(parameters, source), nullptr);
  NPHAND_THROW(source, ": unknown index backend '", backend, "'");
}

}  // namespace

const std::vector<std::string>& IndexBackends() {
  static const std::vector<std::string> backends = {"exact",   "lsh",         "faiss-hnsw", "faiss-ivf",
                                                     "hnswlib", "hnswlib-sq8", "flann"};
  return backends;
}

IndexOptions IndexOptions::Exact() {
  IndexOptions options;
  options.backend = "exact";
  return options;
}

bool IndexOptions::Check(std::string* why) const {
  const std::vector<std::string>& known = IndexBackends();
  if (std::find(known.begin(), known.end(), backend) == known.end()) {
    *why = "unknown index backend '" + backend + "' (known:";
    for (const std::string& name : known) *why += (why->back() == ':' ? " " : ", ") + name;
    *why += ")";
    return false;
  }
  if (backend == "lsh") return lsh.Check(why);
  if ((backend == "faiss-hnsw" || backend == "hnswlib-sq8") && hnsw.pca != 0) {
    *why = "the PCA projection (hnsw pca) is an option of hnswlib, not of " + backend;
    return false;
  }
  if (backend == "faiss-hnsw" || backend == "hnswlib" || backend == "hnswlib-sq8") return hnsw.Check(why);
  if (backend == "faiss-ivf") return ivf.Check(why);
  if (backend == "flann") return flann.Check(why);
  return true;
}

std::unique_ptr<KnnIndex> BuildIndex(const Database& db, const IndexOptions& options, std::ostream* progress) {
  return BuildIndex(DatabaseDescriptors(db), options, progress);
}

std::unique_ptr<KnnIndex> BuildIndex(IndexedSet set, const IndexOptions& options, std::ostream* progress) {
  std::string why;
  NPHAND_THROW_CHECK(options.Check(&why), "index build: ", why);
  NPHAND_THROW_CHECK(!set.ids.empty(), "index build: the database has no entry with a hand to index");
  if (options.backend == "lsh") return std::make_unique<LshIndex>(std::move(set), options.lsh, progress);
  if (options.backend == "faiss-hnsw") return BuildFaissHnsw(std::move(set), options.hnsw, progress);
  if (options.backend == "hnswlib") return BuildHnswlib(std::move(set), options.hnsw, progress);
  if (options.backend == "hnswlib-sq8") return BuildHnswlibSq8(std::move(set), options.hnsw, progress);
  if (options.backend == "faiss-ivf") return BuildFaissIvf(std::move(set), options.ivf, progress);
  if (options.backend == "flann") return BuildFlann(std::move(set), options.flann, progress);
  return std::make_unique<ExactIndex>(std::move(set));
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
  return LoadBackend(file.meta["backend"].get<std::string>(), file.meta["parameters"], db, std::move(ids), file.body,
                     source);
}

nlohmann::json ReadIndexMeta(const std::filesystem::path& path) { return ReadIndexFile(path).meta; }

}  // namespace nphand
