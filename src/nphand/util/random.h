// Seeded pseudo-random numbers. Every random choice in nphand takes one of these, built
// from an explicit seed, so the same command gives the same bytes. The distributions are
// written here (not std::uniform_*), whose outputs differ between standard libraries.
#pragma once

#include <cstdint>
#include <random>

namespace nphand {

class Random {
 public:
  explicit Random(uint64_t seed) : engine_(seed) {}

  uint64_t Next() { return engine_(); }
  // Uniform in [0, 1) with 53 random bits.
  double Uniform() { return static_cast<double>(engine_() >> 11) * 0x1.0p-53; }
  double Uniform(double low, double high) { return low + (high - low) * Uniform(); }
  // Uniform integer in [0, n); n > 0.
  uint64_t UniformIndex(uint64_t n) { return static_cast<uint64_t>(Uniform() * static_cast<double>(n)) % n; }
  // Standard normal (Box-Muller, one value per call).
  double Normal();

 private:
  std::mt19937_64 engine_;
};

}  // namespace nphand
