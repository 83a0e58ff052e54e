// Fuzzes the index file loader: the meta and its checks, and LoadIndex (backend bodies)
// against the seed database scripts/fuzz.sh names in NPHAND_FUZZ_DB (the one the seed
// index was built from, so that mutations get past the database check).
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <memory>

#include "nphand/index/backends.h"
#include "nphand/util/check.h"
#include "tests/fuzz/fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::unique_ptr<nphand::Database> db = []() -> std::unique_ptr<nphand::Database> {
    const char* path = std::getenv("NPHAND_FUZZ_DB");
    return path == nullptr ? nullptr : std::make_unique<nphand::Database>(nphand::Database::Open(path));
  }();
  const std::filesystem::path path = nphand::fuzz::ScratchPath("fuzz.idx");
  nphand::fuzz::WriteBytes(path, {data, size});
  try {
    nphand::ReadIndexMeta(path);
    if (db != nullptr) {
      const std::unique_ptr<nphand::KnnIndex> index = nphand::LoadIndex(path, *db);
      if (index->size() > 0) {
        nphand::Descriptor query{db->descriptor(), std::vector<float>(db->Hog(0).begin(), db->Hog(0).end()), 0.0};
        index->Search(query, 5);
      }
    }
  } catch (const nphand::Error&) {
  }
  return 0;
}
