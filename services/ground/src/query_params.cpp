#include "tetra/ground/query_params.hpp"

#include <cmath>
#include <cstdlib>

namespace tetra::ground {

Result<QueryParams> QueryParams::of(const std::vector<std::pair<std::string, std::string>>& params,
                                    std::initializer_list<const char*> allowed) {
  QueryParams q;
  for (const auto& [name, value] : params) {
    bool known = false;
    for (const char* a : allowed) known = known || name == a;
    if (!known) return bad_input("parameter '" + name + "' unknown here");
    if (q.has(name)) return bad_input("parameter '" + name + "' given twice");
    q.params_.emplace_back(name, value);
  }
  return q;
}

bool QueryParams::has(const std::string& name) const {
  for (const auto& p : params_) {
    if (p.first == name) return true;
  }
  return false;
}

std::string QueryParams::text(const std::string& name) const {
  return given(name).value_or("");
}

std::optional<std::string> QueryParams::given(const std::string& name) const {
  for (const auto& p : params_) {
    if (p.first == name) return p.second;
  }
  return std::nullopt;
}

Result<double> QueryParams::number(const std::string& name, double fallback) const {
  if (!has(name)) return fallback;
  const std::string t = text(name);
  char* end = nullptr;
  const double v = std::strtod(t.c_str(), &end);
  if (t.empty() || end != t.c_str() + t.size() || !std::isfinite(v))
    return bad_input("parameter '" + name + "': a finite number");
  return v;
}

Result<std::size_t> QueryParams::count(const std::string& name, std::size_t fallback, std::size_t min,
                                       std::size_t max) const {
  const std::string range = std::to_string(min) + ".." + std::to_string(max);
  if (!has(name)) return fallback;
  const std::string t = text(name);
  if (t.empty() || t.size() > 12 || t.find_first_not_of("0123456789") != std::string::npos)
    return bad_input("parameter '" + name + "': an integer " + range);
  const auto v = static_cast<std::size_t>(std::stoull(t));
  if (v < min || v > max) return bad_input("parameter '" + name + "': an integer " + range);
  return v;
}

}  // namespace tetra::ground
