// One line of progress for a long job: "\r<label>: done/total <unit> (p%), rate/s, ETA m:ss",
// at most once a second, ended with a newline by Finish().
#pragma once

#include <chrono>
#include <cstdint>
#include <ostream>
#include <string>

namespace nphand {

// "m:ss" of a number of seconds (negative counts as 0).
std::string FormatClock(double seconds);

class ProgressLine {
 public:
  using Clock = std::chrono::steady_clock::time_point (*)();
  // Reports to `out` (nothing if null). `already` of `total` were done before this run (a
  // resumed job): they count toward the fraction but not the rate. `now` tells the time.
  ProgressLine(std::ostream* out, std::string label, uint64_t total, std::string unit, uint64_t already = 0,
               Clock now = &std::chrono::steady_clock::now);
  // `done` of `total` are done now; prints if a second has passed since the last line or
  // the job is complete.
  void Update(uint64_t done);
  // Ends the line (if anything was printed).
  void Finish();

 private:
  std::ostream* out_;
  std::string label_, unit_;
  uint64_t total_, already_;
  Clock now_;
  std::chrono::steady_clock::time_point start_;
  double last_ = -1.0;
  bool printed_ = false;
};

}  // namespace nphand
