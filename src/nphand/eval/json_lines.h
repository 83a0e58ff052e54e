// JSON as the studies read and write it: JSON-lines files (one object per line), and
// figures that may have nothing to measure.
#pragma once

#include <filesystem>
#include <vector>

#include <nlohmann/json.hpp>

namespace nphand {

struct JsonLine {
  int number = 0;  // 1-based line number in the file
  nlohmann::json json;
};

// The objects of a JSON-lines file, blank lines skipped (an empty file gives none). Throws
// nphand::Error "<path>: line N is not a JSON object" for any other line, or naming a file
// that cannot be read.
std::vector<JsonLine> ReadJsonLines(const std::filesystem::path& path);

// A figure, or null when it is not a number (nothing was measured).
nlohmann::json JsonNumber(double value);

}  // namespace nphand
