#pragma once
// A unit's id in the HTTP API (docs/ground.md, "Unit ids"): the lowercase hexadecimal of its name's bytes,
// the DDS key exactly as it came. A name that is not UTF-8 is shown with U+FFFD in `unit` (two such names
// may look alike there); its `unit_id` is still its own, so its history and its commands are reached by
// it. This is the one place a unit enters the API (a request's `unit` or `unit_id`) and leaves it.

#include <optional>
#include <string>
#include <string_view>

#include "tetra/core/result.hpp"

namespace tetra::ground {

//! "756e6974206f6e65" for "unit one": two lowercase hexadecimal digits per byte of the name.
std::string unit_id(std::string_view name);
//! The name whose unit_id() is `id`; nullopt unless `id` is one (non-empty, an even number of 0-9 a-f).
std::optional<std::string> unit_of_id(std::string_view id);

//! The unit a request names, by `name` (its name as text) or by `id` (its unit_id): exactly one of
//! them. `what` says where, in the errors ("parameter", "command: field").
Result<std::string> requested_unit(const std::optional<std::string>& name,
                                   const std::optional<std::string>& id, const std::string& what);

}  // namespace tetra::ground
