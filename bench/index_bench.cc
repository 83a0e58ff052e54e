// Google Benchmark of the index stage: one K = 500 query at a time on one core, as the
// estimator asks, on the database named by NPHAND_BENCH_DB (default out/nphand.db, which
// `nphand db build` writes); queries are stored descriptors of entries spread over it.
#include <cstdlib>

#include <benchmark/benchmark.h>

#include "nphand/index/knn_index.h"

namespace nphand {
namespace {

const Database& BenchDatabase() {
  static const Database db = Database::Open(std::getenv("NPHAND_BENCH_DB") != nullptr ? std::getenv("NPHAND_BENCH_DB")
                                                                                      : "out/nphand.db");
  return db;
}

void BM_ExactSearch(benchmark::State& state) {
  const Database& db = BenchDatabase();
  const std::unique_ptr<KnnIndex> index = BuildIndex(db, {});
  size_t entry = 0;
  for (auto _ : state) {
    entry = (entry + 7919) % db.size();
    const Descriptor query{db.descriptor(), std::vector<float>(db.Hog(entry).begin(), db.Hog(entry).end()), 0.0};
    benchmark::DoNotOptimize(index->Search(query, static_cast<int>(state.range(0))));
  }
  state.counters["entries"] = static_cast<double>(index->size());
}
BENCHMARK(BM_ExactSearch)->Arg(500)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace nphand

BENCHMARK_MAIN();
