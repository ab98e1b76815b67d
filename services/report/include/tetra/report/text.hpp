#pragma once
// Numbers and strings as the reports print them: fixed decimals without iostream state, JSON numbers in
// shortest round-trip form, JSON string literals.

#include <string>

namespace tetra::report {

//! "%.*f": `value` with `decimals` digits after the point.
std::string fixed(double value, int decimals);
//! JSON number in shortest round-trip form; `null` for NaN and infinities.
std::string json_number(double value);
//! JSON string literal with escapes.
std::string json_string(const std::string& text);

}  // namespace tetra::report
