#include "nphand/util/random.h"

#include <cmath>

#include <gtest/gtest.h>

namespace nphand {
namespace {

TEST(RandomTest, SameSeedSameSequenceOtherSeedOtherSequence) {
  Random a(7), b(7), c(8);
  bool differs = false;
  for (int i = 0; i < 100; ++i) {
    const uint64_t x = a.Next();
    EXPECT_EQ(x, b.Next());
    differs |= x != c.Next();
  }
  EXPECT_TRUE(differs);
}

TEST(RandomTest, DistributionsStayInRangeWithTheRightMoments) {
  Random random(1);
  double sum = 0.0, sum_sq = 0.0;
  const int n = 20000;
  for (int i = 0; i < n; ++i) {
    const double u = random.Uniform(-2.0, 3.0);
    ASSERT_GE(u, -2.0);
    ASSERT_LT(u, 3.0);
    ASSERT_LT(random.UniformIndex(5), 5u);
    const double g = random.Normal();
    sum += g;
    sum_sq += g * g;
  }
  EXPECT_NEAR(sum / n, 0.0, 0.05);
  EXPECT_NEAR(sum_sq / n, 1.0, 0.05);
}

}  // namespace
}  // namespace nphand
