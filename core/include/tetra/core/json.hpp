#pragma once
// The few JSON pieces tetra writes (FDI events, monitor lines): string literals and numbers.

#include <string>
#include <string_view>

namespace tetra {

//! Appends `text` as a JSON string literal: quote and backslash escaped, \n and \t as such, other
//! control characters as \u00XX, and any byte that is not part of valid UTF-8 as \ufffd (so the
//! output is always valid UTF-8 JSON).
void append_json_string(std::string& out, std::string_view text);
//! True when `text` is valid UTF-8 (no stray or overlong bytes, no surrogates, nothing beyond U+10FFFF).
bool is_valid_utf8(std::string_view text);
//! Appends `value` in shortest round-trip form, or `null` when it is not finite.
void append_json_number(std::string& out, double value);

}  // namespace tetra
