// A tiny database built in well under a second, for tests of the db stage and above.
#pragma once

#include <filesystem>

#include <gtest/gtest.h>

#include "nphand/db/builder.h"

namespace nphand::testing {

// Grasps 1 (Large Diameter) and 13 (Precision Sphere), 8 directions: 160 entries.
DatabaseBuildOptions TinyDatabaseOptions();
// Builds the tiny database at `path` (quietly) and returns it.
std::filesystem::path BuildTinyDatabase(const std::filesystem::path& path);

// A test suite sharing one tiny database, built once for the suite.
class TinyDatabaseTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite();
  static void TearDownTestSuite();
  static const Database& db() { return *db_; }
  // Entry `i`'s stored descriptor, as a query.
  static Descriptor QueryOf(size_t i);
  // Where the database file is.
  static std::filesystem::path Path();

 private:
  static Database* db_;
};

}  // namespace nphand::testing
