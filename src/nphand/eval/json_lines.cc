#include "nphand/eval/json_lines.h"

#include <cmath>
#include <fstream>
#include <string>

#include "nphand/util/check.h"

namespace nphand {

std::vector<JsonLine> ReadJsonLines(const std::filesystem::path& path) {
  std::ifstream in(path);
  NPHAND_THROW_CHECK(in.good(), path.string(), ": cannot read");
  std::vector<JsonLine> lines;
  std::string text;
  for (int number = 1; std::getline(in, text); ++number) {
    if (text.find_first_not_of(" \t\r") == std::string::npos) continue;
    nlohmann::json json = nlohmann::json::parse(text, nullptr, false);
    NPHAND_THROW_CHECK(!json.is_discarded() && json.is_object(), path.string(), ": line ", number, " is not a JSON object");
    lines.push_back({number, std::move(json)});
  }
  return lines;
}

nlohmann::json JsonNumber(double value) { return std::isfinite(value) ? nlohmann::json(value) : nlohmann::json(nullptr); }

}  // namespace nphand
