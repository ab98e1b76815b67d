#pragma once
// The filter's bias states as they were before a fault (docs/fdi.md, "Bias states repaired at isolation").
// During a fault episode the parity and reference updates can push the faulty gyro's error into the healthy
// gyros' bias states; at the isolation those states go back to a copy taken before the fault's onset,
// propagated to now. Copies are taken at most once a second while no episode is open, in a ring that reaches
// further back than any onset estimate; the one before the onset is held when an episode opens.

#include <cstdint>
#include <vector>

#include "mekf.hpp"

namespace tetra::fdi::detail {

class BiasSnapshots {
 public:
  explicit BiasSnapshots(const Mekf& filter);

  //! A copy of the filter's bias states at `now_ns`, when the last one is at least kSpacing old.
  void take(std::int64_t now_ns, const Mekf& filter);
  //! An episode began at `onset_ns`: holds the newest copy taken at or before it (none: the prior will do).
  //! A copy already held is kept (a second detection within the episode).
  void hold(std::int64_t onset_ns);
  //! The held copy (or, with none held, the newest at or before `onset_ns`) restores the unfrozen gyros of
  //! `gyros` at `now_ns`; without such a copy they go back to their prior. Releases the hold.
  void restore(Mekf& filter, GyroMask gyros, std::int64_t onset_ns, std::int64_t now_ns);
  //! The episode ended without an isolation: copies are taken again.
  void release() {
    held_ = -1;
    holding_ = false;
  }
  bool holding() const { return holding_; }
  void reset();

 private:
  static constexpr int kCopies = 64;                          //!< ring size
  static constexpr std::int64_t kSpacing_ns = 1'000'000'000;  //!< [ns] at most one copy a second
  //! Index of the newest copy at or before `t_ns`, else −1.
  int newest_before(std::int64_t t_ns) const;
  double* copy(int k) { return &data_[static_cast<std::size_t>(k % kCopies) * size_]; }

  std::size_t size_;
  std::vector<double> data_;  //!< kCopies × size_
  std::vector<std::int64_t> stamp_ns_;
  int count_ = 0;         //!< copies taken (ring index = count % kCopies)
  int held_ = -1;         //!< the held copy's index, −1: none (then the prior)
  bool holding_ = false;  //!< an episode is open: no new copies
};

}  // namespace tetra::fdi::detail
