#include "tetra/service/unit_name.hpp"

#include <algorithm>

#include "tetra/core/json.hpp"

namespace tetra::service {

Status check_unit_name(std::string_view name, const std::string& where) {
  if (name.empty() || name.size() > kMaxUnitNameBytes) {
    return bad_input(where + ": must have 1 to 31 bytes (it has " + std::to_string(name.size()) + ")");
  }
  if (!is_valid_utf8(name)) return bad_input(where + ": is not valid UTF-8");
  const bool control = std::any_of(name.begin(), name.end(), [](char c) {
    const auto byte = static_cast<unsigned char>(c);
    return byte < 0x20 || byte == 0x7f;
  });
  if (control) return bad_input(where + ": contains a control character (newline, tab, ...)");
  return ok_status();
}

}  // namespace tetra::service
