#pragma once
// The query parameters of a request, validated: an unknown or repeated parameter, a number that is not
// finite or out of its range is an error naming the parameter (the HTTP answer is a 400 with it).

#include <cstddef>
#include <initializer_list>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "tetra/core/result.hpp"

namespace tetra::ground {

class QueryParams {
 public:
  //! The parameters, each at most once and each one of `allowed`.
  static Result<QueryParams> of(const std::vector<std::pair<std::string, std::string>>& params,
                                std::initializer_list<const char*> allowed);
  bool has(const std::string& name) const;
  //! The parameter's text ("" when absent).
  std::string text(const std::string& name) const;
  //! The parameter's text; nullopt when absent.
  std::optional<std::string> given(const std::string& name) const;
  //! A finite number; `fallback` when absent.
  Result<double> number(const std::string& name, double fallback) const;
  //! An integer in [min, max]; `fallback` when absent.
  Result<std::size_t> count(const std::string& name, std::size_t fallback, std::size_t min,
                            std::size_t max) const;

 private:
  std::vector<std::pair<std::string, std::string>> params_;
};

}  // namespace tetra::ground
