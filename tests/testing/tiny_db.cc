#include "testing/tiny_db.h"

#include <unistd.h>

#include "testing/testing.h"

namespace nphand::testing {

DatabaseBuildOptions TinyDatabaseOptions() {
  DatabaseBuildOptions options;
  options.grasps = {1, 13};
  options.gestures = {};
  options.directions = 8;
  options.image_size = 96;
  options.threads = 2;
  return options;
}

std::filesystem::path BuildTinyDatabase(const std::filesystem::path& path) {
  BuildDatabase(RightHand(), TinyDatabaseOptions(), path, nullptr);
  return path;
}

Database* TinyDatabaseTest::db_ = nullptr;

std::filesystem::path TinyDatabaseTest::Path() {
  return std::filesystem::temp_directory_path() / ("nphand_tiny_" + std::to_string(::getpid()) + ".db");
}

void TinyDatabaseTest::SetUpTestSuite() { db_ = new Database(Database::Open(BuildTinyDatabase(Path()))); }

void TinyDatabaseTest::TearDownTestSuite() {
  delete db_;
  db_ = nullptr;
  std::filesystem::remove(Path());
}

Descriptor TinyDatabaseTest::QueryOf(size_t i) {
  return {db_->descriptor(), std::vector<float>(db_->Hog(i).begin(), db_->Hog(i).end()), 0.0};
}

}  // namespace nphand::testing
