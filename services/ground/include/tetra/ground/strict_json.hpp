#pragma once
// JSON as the ground station accepts it from clients and record files: one value, and no object with
// the same key twice (a parser keeping the last would let `"action":"reset","action":"exclude"` say
// two things to two readers).

#include <string>

#include <nlohmann/json.hpp>

#include "tetra/core/result.hpp"

namespace tetra::ground {

//! The value of `text`; an error names a repeated key or says the text is not JSON.
Result<nlohmann::json> parse_strict_json(const std::string& text);

}  // namespace tetra::ground
