#pragma once
// The gyros in use: exclusions (latched until an operator reinstates) and the fault kind each was excluded
// for. The one place that says which gyros the solution may use.

#include <vector>

#include "tetra/core/geometry.hpp"
#include "tetra/fdi/types.hpp"

namespace tetra::fdi::detail {

class GyroSet {
 public:
  explicit GyroSet(int n_gyros) : n_(n_gyros), kinds_(static_cast<std::size_t>(n_gyros), FaultKind::kNone) {}

  int size() const { return n_; }
  GyroMask all() const { return all_gyros(n_); }
  GyroMask excluded() const { return excluded_; }
  GyroMask active() const { return all() & ~excluded_; }
  bool is_excluded(int id) const { return has_gyro(excluded_, id); }
  bool contains(int id) const { return id >= 1 && id <= n_; }
  FaultKind kind(int id) const { return kinds_[static_cast<std::size_t>(id - 1)]; }

  void exclude(int id, FaultKind kind) {
    excluded_ |= GyroMask{1} << static_cast<unsigned>(id - 1);
    kinds_[static_cast<std::size_t>(id - 1)] = kind;
  }
  void reinstate(int id) {
    excluded_ = without_gyro(excluded_, id);
    kinds_[static_cast<std::size_t>(id - 1)] = FaultKind::kNone;
  }
  void reset() {
    for (int id = 1; id <= n_; ++id) reinstate(id);
  }

 private:
  int n_;
  GyroMask excluded_ = 0;
  std::vector<FaultKind> kinds_;
};

}  // namespace tetra::fdi::detail
