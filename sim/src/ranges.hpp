#pragma once
// Range checks of the simulator's inputs (private to tetra::sim): one wording for every key.

#include <cmath>
#include <string>

#include "tetra/core/result.hpp"
#include "text.hpp"

namespace tetra::sim {

//! Ok when `value` is in [min, max] (in (min, max] with `above_min`); otherwise "KEY must be from MIN to
//! MAX UNIT, got VALUE" (NaN and infinities fail).
inline Status check_range(const std::string& key, double value, double min, double max, const char* unit,
                          bool above_min = false) {
  const bool low_ok = above_min ? value > min : value >= min;
  if (std::isfinite(value) && low_ok && value <= max) return ok_status();
  const std::string u = *unit ? std::string(" ") + unit : std::string();
  return bad_input(key + " must be " + (above_min ? "above " : "from ") + number_text(min) +
                   (above_min ? " and at most " : " to ") + number_text(max) + u + ", got " +
                   number_text(value));
}

}  // namespace tetra::sim
