// A tiny database built in well under a second, for tests of the db stage and above.
#pragma once

#include <filesystem>

#include "nphand/db/builder.h"

namespace nphand::testing {

// Grasps 1 (Large Diameter) and 13 (Precision Sphere), 8 directions: 160 entries.
DatabaseBuildOptions TinyDatabaseOptions();
// Builds the tiny database at `path` (quietly) and returns it.
std::filesystem::path BuildTinyDatabase(const std::filesystem::path& path);

}  // namespace nphand::testing
