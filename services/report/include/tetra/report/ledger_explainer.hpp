#pragma once
// `tetra replay --explain T`: the hypothesis ledger at a time (docs/fdi.md, "The ledger and the arbiter"):
// the decisions up to T with the rows that decided each (source, hypothesis, statistic with its unit,
// threshold, verdict), and the detectors' state at the last epoch at or before T.

#include <cstdint>
#include <deque>
#include <optional>
#include <string>

#include "tetra/fdi/pipeline.hpp"

namespace tetra::report {

class LedgerExplainer {
 public:
  //! [s] the time to explain; `decisions_kept`: how many decisions before it are printed.
  explicit LedgerExplainer(double at_s, std::size_t decisions_kept = 8);
  //! One epoch's step at `time_s` (the log's time): its decision events and, at or before T, the health.
  void observe(double time_s, const fdi::StepResult& step, const fdi::Pipeline& pipeline);
  //! The explanation, one table per decision (docs/fdi.md).
  std::string text(int n_gyros) const;

 private:
  struct Decision {
    double time_s = 0.0;
    fdi::FdiEvent event;
  };
  double at_s_;
  std::size_t kept_;
  std::deque<Decision> decisions_;
  std::optional<fdi::Health> health_;  //!< at the last epoch at or before T
  double health_time_s_ = 0.0;
};

//! True for the events that carry ledger rows: detected, isolated, unisolated, cleared, reference_rejected.
bool is_decision(fdi::EventType type);

}  // namespace tetra::report
