#pragma once
// A unit's name: the key of every topic (docs/dds.md). It goes on the wire as an IDL string<31>, into
// log lines and into JSON, so it must be short, printable text.

#include <string>
#include <string_view>

#include "tetra/core/result.hpp"

namespace tetra::service {

constexpr std::size_t kMaxUnitNameBytes = 31;  //!< IDL string<31>

//! Refuses an empty name, one over 31 bytes, invalid UTF-8 or control characters (newline, tab, …);
//! the error starts with `where` (the option or file:key that gave it).
Status check_unit_name(std::string_view name, const std::string& where);

}  // namespace tetra::service
