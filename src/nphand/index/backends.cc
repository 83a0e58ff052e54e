#include "nphand/index/backends.h"

#include "nphand/index/exact_index.h"
#include "nphand/index/index_file.h"
#include "nphand/util/check.h"

namespace nphand {
namespace {

// A backend from its name, parameters and body: at build (body empty) or load.
std::unique_ptr<KnnIndex> MakeIndex(const std::string& backend, const nlohmann::json& parameters, IndexedSet set,
                                    const std::vector<uint8_t>& body, const std::string& source) {
  NPHAND_THROW_CHECK(body.empty(), source, ": the ", backend, " backend has no body, the file holds ", body.size(),
                     " bytes");
  if (backend == "exact") {
    NPHAND_THROW_CHECK(parameters.empty(), source, ": an exact index has no parameters");
    return std::make_unique<ExactIndex>(std::move(set));
  }
  if (backend == "lsh") {
    return std::make_unique<LshIndex>(std::move(set), LshIndex::OptionsFromParameters(parameters, source), nullptr);
  }
  NPHAND_THROW(source, ": unknown index backend '", backend, "'");
}

}  // namespace

bool IndexOptions::Check(std::string* why) const {
  if (backend != "exact" && backend != "lsh") {
    *why = "unknown index backend '" + backend + "' (known: exact, lsh)";
    return false;
  }
  return backend != "lsh" || lsh.Check(why);
}

std::unique_ptr<KnnIndex> BuildIndex(const Database& db, const IndexOptions& options, std::ostream* progress) {
  std::string why;
  NPHAND_THROW_CHECK(options.Check(&why), "index build: ", why);
  if (options.backend == "lsh") return std::make_unique<LshIndex>(DatabaseDescriptors(db), options.lsh, progress);
  return MakeIndex(options.backend, nlohmann::json::object(), DatabaseDescriptors(db), {}, "index build");
}

std::unique_ptr<KnnIndex> LoadIndex(const std::filesystem::path& path, const Database& db) {
  IndexFile file = ReadIndexFile(path);
  const std::string source = path.string();
  const std::string built_from = file.meta["database"]["checksum"].get<std::string>();
  NPHAND_THROW_CHECK(built_from == db.checksum(), source, ": built from another database (checksum ", built_from,
                     "; this one's is ", db.checksum(), "); rebuild it with nphand index build");
  CheckSameDescriptor(db.descriptor(), file.descriptor, source);
  IndexedSet set = DatabaseDescriptors(db);
  NPHAND_THROW_CHECK(file.meta["entries"].get<uint64_t>() == set.ids.size(), source, ": indexes ",
                     file.meta["entries"].get<uint64_t>(), " entries, the database has ", set.ids.size(), " with a hand");
  return MakeIndex(file.meta["backend"].get<std::string>(), file.meta["parameters"], std::move(set), file.body, source);
}

nlohmann::json ReadIndexMeta(const std::filesystem::path& path) { return ReadIndexFile(path).meta; }

}  // namespace nphand
