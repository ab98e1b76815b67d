#pragma once
// How the messages of a report function name its files and arguments. A library names an argument by its
// own name ("attitude_path"); a front-end that calls it gives its own words for them ("ATT.csv",
// "--attitude"), so a message reads as the user typed it ("--attitude: is the same file as LOG").

#include <map>
#include <string>

namespace tetra::report {

//! The library's name of an argument → how messages name it. An argument not in the map is named by
//! the library's name.
using ArgumentNames = std::map<std::string, std::string>;

//! How messages name `argument`.
inline std::string name_of(const ArgumentNames& names, const std::string& argument) {
  const auto it = names.find(argument);
  return it == names.end() ? argument : it->second;
}

}  // namespace tetra::report
