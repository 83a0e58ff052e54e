// Fuzzes the index backends' body decoders behind a valid checksum: the first byte picks a
// backend with a body (faiss-hnsw, hnswlib, hnswlib-sq8, faiss-ivf), the rest is its body.
// The meta is that of a real index of the seed database scripts/fuzz.sh names in
// NPHAND_FUZZ_DB, so every input reaches the decoder; a decoded index is searched.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <memory>
#include <vector>

#include "nphand/index/backends.h"
#include "nphand/index/index_file.h"
#include "nphand/util/check.h"
#include "tests/fuzz/fuzz_support.h"

namespace {

const char* const kBackends[] = {"faiss-hnsw", "hnswlib", "hnswlib-sq8", "faiss-ivf"};

struct Seed {
  std::unique_ptr<nphand::Database> db;
  std::vector<nlohmann::json> metas;  // per backend
};

const Seed& TheSeed() {
  static const Seed seed = [] {
    Seed s;
    const char* path = std::getenv("NPHAND_FUZZ_DB");
    if (path == nullptr) return s;
    s.db = std::make_unique<nphand::Database>(nphand::Database::Open(path));
    for (const char* backend : kBackends) {
      nphand::IndexOptions options;
      options.backend = backend;
      const std::filesystem::path real = nphand::fuzz::ScratchPath("real.idx");
      nphand::BuildIndex(*s.db, options)->Save(real, *s.db);
      s.metas.push_back(nphand::ReadIndexFile(real).meta);
    }
    return s;
  }();
  return seed;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const Seed& seed = TheSeed();
  if (seed.db == nullptr || size < 1) return 0;
  const size_t backend = data[0] % seed.metas.size();
  const std::filesystem::path path = nphand::fuzz::ScratchPath("body.idx");
  nphand::fuzz::WriteBytes(path, nphand::EncodeIndexFile(seed.metas[backend], std::vector<uint8_t>(data + 1, data + size)));
  try {
    const std::unique_ptr<nphand::KnnIndex> index = nphand::LoadIndex(path, *seed.db);
    nphand::Descriptor query{seed.db->descriptor(), std::vector<float>(seed.db->Hog(0).begin(), seed.db->Hog(0).end()),
                             0.0};
    index->Search(query, 5);
  } catch (const nphand::Error&) {
  }
  return 0;
}
