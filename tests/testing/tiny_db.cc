#include "testing/tiny_db.h"

#include "testing/testing.h"

namespace nphand::testing {

DatabaseBuildOptions TinyDatabaseOptions() {
  DatabaseBuildOptions options;
  options.grasps = {1, 13};
  options.directions = 8;
  options.image_size = 96;
  options.threads = 2;
  return options;
}

std::filesystem::path BuildTinyDatabase(const std::filesystem::path& path) {
  BuildDatabase(RightHand(), TinyDatabaseOptions(), path, nullptr);
  return path;
}

}  // namespace nphand::testing
