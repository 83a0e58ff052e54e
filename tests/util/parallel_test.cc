#include "nphand/util/parallel.h"

#include <atomic>
#include <stdexcept>

#include <gtest/gtest.h>

namespace nphand {
namespace {

TEST(ParallelTest, EveryItemRunsOnceOnItsWorker) {
  for (int threads : {1, 2, 3, 8}) {
    std::vector<int> runs(101, 0), worker_of(101, -1);
    ParallelFor(runs.size(), threads, [&](size_t i, int worker) {
      ++runs[i];
      worker_of[i] = worker;
    });
    for (size_t i = 0; i < runs.size(); ++i) {
      EXPECT_EQ(runs[i], 1);
      EXPECT_EQ(worker_of[i], static_cast<int>(i % threads)) << "items go to worker i % workers";
    }
  }
  ParallelFor(0, 4, [](size_t, int) { FAIL() << "no items, no calls"; });
}

TEST(ParallelTest, AnExceptionReachesTheCallerAndStopsTheWork) {
  std::atomic<int> calls = 0;
  EXPECT_THROW(ParallelFor(100000, 2,
                           [&](size_t i, int) {
                             ++calls;
                             if (i == 10) throw std::runtime_error("item 10");
                           }),
               std::runtime_error);
  EXPECT_LT(calls.load(), 100000) << "the workers stop after a failure";
}

TEST(ParallelTest, ZeroThreadsMeansAllCores) { EXPECT_GE(ThreadCount(0), 1); }

}  // namespace
}  // namespace nphand
