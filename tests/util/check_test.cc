#include "nphand/util/check.h"

#include <gtest/gtest.h>

namespace nphand {
namespace {

TEST(CheckTest, ThrowCheckNamesTheProblemAndWhereItWasRaised) {
  try {
    NPHAND_THROW_CHECK(1 + 1 == 3, "db.nph: checksum ", 42, " is wrong");
    FAIL() << "no exception";
  } catch (const Error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("db.nph: checksum 42 is wrong"), std::string::npos) << what;
    EXPECT_NE(what.find("check_test.cc:"), std::string::npos) << what;
  }
}

TEST(CheckTest, ThrowCheckPassesWhenTrue) { EXPECT_NO_THROW(NPHAND_THROW_CHECK(true, "never")); }

TEST(CheckDeathTest, InternalCheckAborts) {
  EXPECT_DEATH(NPHAND_CHECK(false, "broken invariant"), "broken invariant");
}

}  // namespace
}  // namespace nphand
