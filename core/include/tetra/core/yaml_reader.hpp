#pragma once
// Reading hand-written YAML (calibration, scenario and pipeline files) with errors that name the place:
// every message starts "FILE:LINE: " (the line of the offending node, 1-based) and then names the field
// by its path, e.g. "cal.yaml:7: gyros[0].sigma: unknown key 'scale' (allowed: ...)".
// Every function returns a Result; none throws. Include this header only from a library that links
// yaml-cpp itself (tetra::core keeps yaml-cpp private).

#include <optional>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>
#include <Eigen/Core>

#include "tetra/core/result.hpp"

namespace tetra {

//! The reading context of one YAML document: `source` names it (usually the file path) in messages.
//! `what` arguments are the dotted path of the node being read ("gyros[1].noise"); "" at the root.
class YamlReader {
 public:
  explicit YamlReader(std::string source) : source_(std::move(source)) {}

  const std::string& source() const { return source_; }

  //! "FILE:LINE: " for a node that came from the text, "FILE: " for one that did not (e.g. a missing key).
  std::string at(const YAML::Node& node) const;

  //! "FILE:LINE: what: message" (or "FILE:LINE: message" when `what` is empty), as a bad-input Error.
  Error error(const YAML::Node& node, const std::string& what, const std::string& message) const;

  //! Parses a whole document; a syntax error becomes "FILE:LINE: message".
  Result<YAML::Node> load(const std::string& text) const;

  //! A yaml-cpp exception (syntax error, bad conversion) as "FILE:LINE: what: message".
  Error error(const YAML::Exception& e, const std::string& what) const;

  //! `map` must be a mapping whose keys are all in `allowed`; otherwise an Error naming the line of the
  //! first unknown key and listing `allowed` in the order given.
  Status check_keys(const YAML::Node& map, const std::vector<std::string>& allowed,
                    const std::string& what) const;

  //! A finite number: "'abc' is not a number" / "must be finite" otherwise.
  Result<double> number(const YAML::Node& node, const std::string& what) const;
  //! parent[key] as a finite number; "what: missing key 'key'" when absent.
  Result<double> required_number(const YAML::Node& parent, const std::string& key,
                                 const std::string& what) const;
  //! parent[key] as a finite number, or nullopt when the key is absent or null.
  Result<std::optional<double>> optional_number(const YAML::Node& parent, const std::string& key,
                                                const std::string& what) const;

  //! A sequence of exactly three finite numbers, "[x, y, z]".
  Result<Eigen::Vector3d> vector3(const YAML::Node& node, const std::string& what) const;
  //! parent[key] as a 3-vector; "what: missing key 'key'" when absent.
  Result<Eigen::Vector3d> required_vector3(const YAML::Node& parent, const std::string& key,
                                           const std::string& what) const;

  //! "what.key", or "key" at the root.
  static std::string child(const std::string& what, const std::string& key);

 private:
  std::string source_;
};

}  // namespace tetra
