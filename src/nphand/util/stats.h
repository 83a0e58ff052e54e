// Summaries of numbers that more than one stage needs.
#pragma once

#include <optional>
#include <vector>

namespace nphand {

// The median as Python's statistics.median: the middle value once sorted, or the mean of
// the two middle values of an even count; none for no values.
std::optional<double> TrueMedian(std::vector<double> values);

}  // namespace nphand
