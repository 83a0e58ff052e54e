// Crafting database files as a hostile or careless user might: a header rewritten with a
// valid checksum, records edited and sealed with a valid checksum.
#pragma once

#include <cstdint>
#include <vector>

#include <nlohmann/json.hpp>

namespace nphand::testing {

// Where the records of a database file's bytes begin.
size_t RecordsOffset(const std::vector<uint8_t>& file);
// The file's header, parsed.
nlohmann::json HeaderOf(const std::vector<uint8_t>& file);
// The file with its header replaced by `header` (checksum and padding redone).
std::vector<uint8_t> WithHeader(const std::vector<uint8_t>& file, const nlohmann::json& header);
// Recomputes the records' checksum in the footer after the records were edited.
void SealRecords(std::vector<uint8_t>* file);

}  // namespace nphand::testing
