#include "tests/fuzz/fuzz_support.h"

#include <unistd.h>

#include <cstdio>

#include "nphand/db/builder.h"
#include "nphand/util/check.h"

namespace nphand::fuzz {

std::filesystem::path ScratchPath(const char* name) {
  static const std::filesystem::path dir = [] {
    const std::filesystem::path base =
        std::filesystem::is_directory("/dev/shm") ? std::filesystem::path("/dev/shm") : std::filesystem::temp_directory_path();
    const std::filesystem::path d = base / ("nphand_fuzz_" + std::to_string(::getpid()));
    std::filesystem::create_directories(d);
    return d;
  }();
  return dir / name;
}

void WriteBytes(const std::filesystem::path& path, std::span<const uint8_t> bytes) {
  std::FILE* file = std::fopen(path.c_str(), "wb");
  if (file == nullptr) std::abort();
  if (!bytes.empty() && std::fwrite(bytes.data(), 1, bytes.size(), file) != bytes.size()) std::abort();
  std::fclose(file);
}

const nlohmann::json& SeedHeader() {
  static const nlohmann::json header = [] {
    DatabaseBuildOptions options;
    options.grasps = {1};
    options.gestures = {};
    options.directions = 2;
    return options.Header();
  }();
  return header;
}

bool OpenAndReadEverything(const std::filesystem::path& path) {
  try {
    const Database db = Database::Open(path);
    double sum = 0.0;
    for (size_t i = 0; i < db.size(); ++i) {
      const EntryMeta meta = db.Meta(i);
      sum += meta.roll + db.Pose(i).sum() + db.Angles(i)[0] + db.Keypoints(i)[20].x();
      for (float v : db.Hog(i)) sum += v;
      sum += cv::countNonZero(db.Crop(i));
    }
    const nlohmann::json info = DescribeDatabase(db);
    if (info.dump().empty() || sum != sum) std::abort();  // a NaN reached a reader
    return true;
  } catch (const Error&) {
    return false;
  }
}

}  // namespace nphand::fuzz
