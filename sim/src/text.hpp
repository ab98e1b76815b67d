#pragma once
// Text helpers shared by the simulator's sources (private to tetra::sim).

#include <string>

#include "tetra/core/csv.hpp"

namespace tetra::sim {

//! A number in shortest round-trip form, as the files write it.
inline std::string number_text(double value) {
  std::string out;
  append_double(out, value);
  return out;
}

//! A metadata value: spaces, tabs and commas separate "# key=value" tokens, so they become '_'.
inline std::string metadata_token(std::string text) {
  for (char& c : text) {
    if (c == ' ' || c == '\t' || c == ',') c = '_';
  }
  return text;
}

}  // namespace tetra::sim
