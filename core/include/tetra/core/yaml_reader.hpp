#pragma once
// Reading hand-written YAML (calibration, scenario and pipeline files) with errors that name the place:
// every message starts "FILE:LINE: " (the line of the offending node, 1-based) and then names the field
// by its path, e.g. "cal.yaml:7: gyros[0].sigma: unknown key 'scale' (allowed: ...)".
// Every function returns a Result; none throws. Include this header only from a library that links
// yaml-cpp itself (tetra::core keeps yaml-cpp private).

#include <cstdint>
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

  //! Parses a file's one document; a syntax error becomes "FILE:LINE: message". A second document
  //! and a key given twice in any mapping, at any depth, are errors naming the line and key path.
  Result<YAML::Node> load(const std::string& text) const;
  //! Every mapping below `node` has distinct keys; at most kMaxYamlNodes nodes are walked.
  Status check_unique_keys(const YAML::Node& node, const std::string& what) const;
  //! [nodes] largest YAML tree read (aliases included).
  static constexpr std::size_t kMaxYamlNodes = 1'000'000;

  //! A scalar as text ("expected a text value" for a list or a mapping).
  Result<std::string> text(const YAML::Node& node, const std::string& what) const;
  //! parent[key] as text, or "" when absent or null.
  Result<std::string> optional_text(const YAML::Node& parent, const std::string& key,
                                    const std::string& what) const;

  //! A yaml-cpp exception (syntax error, bad conversion) as "FILE:LINE: what: message" (a bad
  //! conversion worded as "a value of the wrong type"; the typed readers above name the type expected).
  Error error(const YAML::Exception& e, const std::string& what) const;

  //! `map` must be a mapping whose keys are all in `allowed`; otherwise an Error naming the line of the
  //! first unknown key and listing `allowed` in the order given.
  Status check_keys(const YAML::Node& map, const std::vector<std::string>& allowed,
                    const std::string& what) const;

  //! A finite plain decimal number: "'abc' is not a number" (hexadecimal, a decimal comma, YAML's
  //! .inf and the like included) / "must be finite" otherwise.
  Result<double> number(const YAML::Node& node, const std::string& what) const;
  //! parent[key] as a finite number; "what: missing key 'key'" when absent.
  Result<double> required_number(const YAML::Node& parent, const std::string& key,
                                 const std::string& what) const;
  //! parent[key] as a finite number, or nullopt when the key is absent or null.
  Result<std::optional<double>> optional_number(const YAML::Node& parent, const std::string& key,
                                                const std::string& what) const;

  //! A whole number (plain decimal digits, an optional '-') in [min, max]; otherwise "expected a whole
  //! number from MIN to MAX, got 'TEXT'".
  Result<std::int64_t> integer(const YAML::Node& node, const std::string& what, std::int64_t min,
                               std::int64_t max) const;
  //! A whole number from 0 to 2^64 - 1 (a seed); otherwise "expected a whole number from 0 to ..., got".
  Result<std::uint64_t> unsigned_integer(const YAML::Node& node, const std::string& what) const;
  //! true or false; otherwise "expected true or false, got 'TEXT'".
  Result<bool> boolean(const YAML::Node& node, const std::string& what) const;

  //! A sequence of exactly three finite numbers, "[x, y, z]".
  Result<Eigen::Vector3d> vector3(const YAML::Node& node, const std::string& what) const;
  //! parent[key] as a 3-vector; "what: missing key 'key'" when absent.
  Result<Eigen::Vector3d> required_vector3(const YAML::Node& parent, const std::string& key,
                                           const std::string& what) const;

  //! "what.key", or "key" at the root.
  static std::string child(const std::string& what, const std::string& key);

 private:
  Status check_unique_keys(const YAML::Node& node, const std::string& what, std::size_t& budget) const;
  std::string source_;
};

}  // namespace tetra
