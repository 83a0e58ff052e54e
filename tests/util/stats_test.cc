#include "nphand/util/stats.h"

#include <gtest/gtest.h>

namespace nphand {
namespace {

TEST(StatsTest, TheMedianIsTheMiddleOrTheMeanOfTheTwoMiddleValues) {
  EXPECT_FALSE(TrueMedian({}).has_value());
  EXPECT_EQ(*TrueMedian({3.0}), 3.0);
  EXPECT_EQ(*TrueMedian({5.0, 1.0, 3.0}), 3.0);
  EXPECT_EQ(*TrueMedian({4.0, 1.0, 3.0, 2.0}), 2.5);
}

}  // namespace
}  // namespace nphand
