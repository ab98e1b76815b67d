#pragma once
// The epoch time check (docs/fdi.md, "Per epoch", step 1): each epoch's stamp judged against the stream's own
// last accepted time. A stamp more than design::stamp_window_periods sample periods away from it is a time
// outlier: counted, dropped, and it never moves the time. A forward jump is followed once
// design::stamp_confirm_count stamps in a row agree with it (each increasing, within the window of the one
// before): the last of them is accepted and the jump is a gap. A stream's time never goes back: a stamp far
// behind is always an outlier.

#include <cstdint>
#include <optional>

namespace tetra::fdi::detail {

enum class StampVerdict : std::uint8_t {
  kAccepted,       //!< increasing, within the window (or the first stamp, or a confirmed jump)
  kNotIncreasing,  //!< a duplicate, or behind the last accepted stamp by no more than the window
  kOutlier,        //!< far outside the window; not (yet) confirmed by agreeing stamps
};

class StampJudge {
 public:
  //! Judges `stamp_ns`; an accepted stamp becomes the last accepted time.
  StampVerdict judge(std::int64_t stamp_ns);
  //! [ns] the sample period that sets the window (> 0); until it is set (the pipeline sets it from the
  //! configuration or from the first time step) every increasing stamp is accepted.
  void set_period(std::int64_t period_ns) { period_ns_ = period_ns; }
  bool has_period() const { return period_ns_ > 0; }
  std::optional<std::int64_t> last_ns() const { return last_ns_; }
  void reset();

 private:
  std::int64_t window_ns() const;

  std::int64_t period_ns_ = 0;                //!< [ns]
  std::optional<std::int64_t> last_ns_;       //!< [ns] the last accepted stamp
  std::optional<std::int64_t> candidate_ns_;  //!< [ns] the newest stamp of a run of forward outliers
  int candidate_count_ = 0;                   //!< stamps in that run
};

}  // namespace tetra::fdi::detail
