#include "nphand/util/progress.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace nphand {

std::string FormatClock(double seconds) {
  const long s = std::lround(std::max(0.0, seconds));
  char text[32];
  std::snprintf(text, sizeof(text), "%ld:%02ld", s / 60, s % 60);
  return text;
}

ProgressLine::ProgressLine(std::ostream* out, std::string label, uint64_t total, std::string unit, uint64_t already,
                           Clock now)
    : out_(out), label_(std::move(label)), unit_(std::move(unit)), total_(total), already_(already), now_(now),
      start_(now()) {}

void ProgressLine::Update(uint64_t done) {
  if (out_ == nullptr) return;
  const double seconds = std::chrono::duration<double>(now_() - start_).count();
  if (seconds < last_ + 1.0 && done < total_) return;
  last_ = seconds;
  printed_ = true;
  const double rate = static_cast<double>(done - std::min(done, already_)) / std::max(seconds, 1e-9);
  *out_ << "\r" << label_ << ": " << done << "/" << total_ << " " << unit_ << " ("
        << (total_ == 0 ? 100 : static_cast<int>(100.0 * done / total_)) << "%), " << static_cast<long>(rate)
        << "/s, ETA " << FormatClock((total_ - std::min(done, total_)) / std::max(rate, 1e-9)) << "   " << std::flush;
}

void ProgressLine::Finish() {
  if (out_ != nullptr && printed_) *out_ << "\n";
  printed_ = false;
}

}  // namespace nphand
