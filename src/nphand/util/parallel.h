// Data-parallel loops on a fixed number of threads, deterministic in which worker does what.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace nphand {

// `requested` threads, or all cores when it is 0 (at least one).
inline int ThreadCount(int requested) {
  return requested > 0 ? requested : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
}

// Runs body(i, worker) for every i in [0, n) on ThreadCount(threads) workers; item i goes to
// worker i % workers, so a caller may keep per-worker state indexed by `worker`. Items must
// be independent. The first exception a body throws is rethrown once every worker has
// stopped (the others stop at their next item).
template <typename Body>
void ParallelFor(size_t n, int threads, Body body) {
  const int workers = static_cast<int>(std::min<size_t>(ThreadCount(threads), std::max<size_t>(n, 1)));
  std::exception_ptr failure;
  std::mutex mutex;  // guards `failure`
  std::atomic<bool> failed = false;
  const auto run = [&](int worker) {
    try {
      for (size_t i = worker; i < n && !failed.load(std::memory_order_relaxed); i += workers) body(i, worker);
    } catch (...) {
      const std::lock_guard<std::mutex> lock(mutex);
      if (!failure) failure = std::current_exception();
      failed = true;
    }
  };
  if (workers == 1) {
    run(0);
  } else {
    std::vector<std::thread> pool;
    for (int w = 0; w < workers; ++w) pool.emplace_back(run, w);
    for (std::thread& t : pool) t.join();
  }
  if (failure) std::rethrow_exception(failure);
}

}  // namespace nphand
