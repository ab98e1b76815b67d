// Report text helpers (tetra/report/text.hpp).
#include "tetra/report/text.hpp"

#include <cstdio>

#include "tetra/core/json.hpp"

namespace tetra::report {

std::string fixed(double value, int decimals) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.*f", decimals, value);
  return buffer;
}

std::string json_number(double value) {
  std::string out;
  append_json_number(out, value);
  return out;
}

std::string json_string(const std::string& text) {
  std::string out;
  append_json_string(out, text);
  return out;
}

}  // namespace tetra::report
