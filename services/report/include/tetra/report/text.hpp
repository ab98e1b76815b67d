#pragma once
// Numbers and strings as the reports print them: fixed decimals without iostream state, JSON numbers in
// shortest round-trip form, JSON string literals.

#include <cstdio>
#include <string>

namespace tetra::report {

//! "%.*f": `value` with `decimals` digits after the point.
std::string fixed(double value, int decimals);
//! JSON number in shortest round-trip form; `null` for NaN and infinities.
std::string json_number(double value);
//! JSON string literal with escapes.
std::string json_string(const std::string& text);

//! printf's text as a string.
template <class... Args>
std::string printf_text(const char* format, Args... args) {
  const int n = std::snprintf(nullptr, 0, format, args...);
  std::string text(static_cast<std::size_t>(n > 0 ? n : 0), '\0');
  if (n > 0) std::snprintf(text.data(), text.size() + 1, format, args...);
  return text;
}

}  // namespace tetra::report
