// A frame's result as one JSON object: the line `nphand estimate` writes per frame
// (docs/FORMAT.md gives every field, its unit and frame).
#pragma once

#include <nlohmann/json.hpp>

#include "nphand/db/database.h"
#include "nphand/estimate/estimator.h"

namespace nphand {

// `db` names the top hypotheses' entries (grasp, step, object); `with_top` includes them.
nlohmann::json FrameResultJson(const FrameResult& result, const Database& db, bool with_top);

}  // namespace nphand
