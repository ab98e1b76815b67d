#include "tetra/ground/unit_id.hpp"

#include "tetra/ground/operators.hpp"

namespace tetra::ground {

namespace {

int digit_value(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  return -1;
}

}  // namespace

std::string unit_id(std::string_view name) {
  return hex_of(name);
}

std::optional<std::string> unit_of_id(std::string_view id) {
  if (id.empty() || id.size() % 2 != 0) return std::nullopt;
  std::string name;
  name.reserve(id.size() / 2);
  for (std::size_t i = 0; i < id.size(); i += 2) {
    const int hi = digit_value(id[i]);
    const int lo = digit_value(id[i + 1]);
    if (hi < 0 || lo < 0) return std::nullopt;
    name += static_cast<char>(hi * 16 + lo);
  }
  return name;
}

Result<std::string> requested_unit(const std::optional<std::string>& name,
                                   const std::optional<std::string>& id, const std::string& what) {
  if (name && id) return bad_input(what + " 'unit' or 'unit_id', not both");
  if (name) {
    if (name->empty()) return bad_input(what + " 'unit' is empty");
    return *name;
  }
  if (!id) return bad_input(what + " 'unit' (or 'unit_id') missing");
  auto named = unit_of_id(*id);
  if (!named)
    return bad_input(what +
                     " 'unit_id': the lowercase hexadecimal of the unit's name, as /api/units gives it");
  return *named;
}

}  // namespace tetra::ground
