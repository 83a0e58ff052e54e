// Google Benchmark of the index stage: one K = 500 query at a time on one core, as the
// estimator asks, on the database named by NPHAND_BENCH_DB (default out/nphand.db, which
// `nphand db build` writes); queries are stored descriptors of entries spread over it.
// BM_IndexFileSearch searches the index file NPHAND_BENCH_INDEX (any backend, built from
// that database by `nphand index build`).
#include <cstdlib>

#include <benchmark/benchmark.h>

#include "nphand/index/backends.h"

namespace nphand {
namespace {

const Database& BenchDatabase() {
  static const Database db = Database::Open(std::getenv("NPHAND_BENCH_DB") != nullptr ? std::getenv("NPHAND_BENCH_DB")
                                                                                      : "out/nphand.db");
  return db;
}

// One query at a time, K = state.range(0), entries spread over the database.
void SearchLoop(benchmark::State& state, const KnnIndex& index) {
  const Database& db = BenchDatabase();
  size_t entry = 0;
  for (auto _ : state) {
    entry = (entry + 7919) % db.size();
    const Descriptor query{db.descriptor(), std::vector<float>(db.Hog(entry).begin(), db.Hog(entry).end()), 0.0};
    benchmark::DoNotOptimize(index.Search(query, static_cast<int>(state.range(0))));
  }
  state.counters["entries"] = static_cast<double>(index.size());
}

// Built once: Google Benchmark calls a benchmark several times.
void BM_ExactSearch(benchmark::State& state) {
  static const std::unique_ptr<KnnIndex> index = BuildIndex(BenchDatabase(), IndexOptions::Exact());
  SearchLoop(state, *index);
}
BENCHMARK(BM_ExactSearch)->Arg(500)->Unit(benchmark::kMillisecond);

// The paper's LSH (L = 10, T = 50) with the M and W its tuner chose for R = 0.95 on the
// default database (`nphand index build --backend lsh` prints them).
void BM_LshSearch(benchmark::State& state) {
  static const std::unique_ptr<KnnIndex> index = [] {
    IndexOptions options;
    options.backend = "lsh";
    options.lsh.hashes = 12;
    options.lsh.bucket_width = 1.96117;
    return BuildIndex(BenchDatabase(), options);
  }();
  SearchLoop(state, *index);
}
BENCHMARK(BM_LshSearch)->Arg(500)->Unit(benchmark::kMillisecond);

void BM_IndexFileSearch(benchmark::State& state) {
  const char* path = std::getenv("NPHAND_BENCH_INDEX");
  if (path == nullptr) {
    state.SkipWithError("set NPHAND_BENCH_INDEX to an index file of the database");
    return;
  }
  static const std::unique_ptr<KnnIndex> index = LoadIndex(path, BenchDatabase());
  state.SetLabel(index->Backend());
  SearchLoop(state, *index);
}
BENCHMARK(BM_IndexFileSearch)->Arg(500)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace nphand

BENCHMARK_MAIN();
