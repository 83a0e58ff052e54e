#include "nphand/util/stats.h"

#include <algorithm>

namespace nphand {

std::optional<double> TrueMedian(std::vector<double> values) {
  if (values.empty()) return std::nullopt;
  std::sort(values.begin(), values.end());
  const size_t n = values.size();
  return n % 2 == 1 ? values[n / 2] : (values[n / 2 - 1] + values[n / 2]) / 2.0;
}

}  // namespace nphand
