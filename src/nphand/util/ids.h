// Typed ids with an invalid sentinel.
#pragma once

#include <cstdint>
#include <limits>

namespace nphand {

// An entry of the database: its record number in the file.
using entry_id_t = uint32_t;
inline constexpr entry_id_t kInvalidEntryId = std::numeric_limits<entry_id_t>::max();

}  // namespace nphand
