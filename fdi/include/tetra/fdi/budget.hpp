#pragma once
// The FDI's error budget (docs/fdi.md, "The budget"): what each evidence source's configured probability
// allows, per hour of fault-free flight (false alarms) and per fault episode (a healthy gyro named), summed
// into the totals the configuration implies for a unit of N gyros sampled every T seconds. Sources whose
// thresholds are counts or ratios, not probabilities, are listed with no figure: the budget does not cover
// them.

#include <string>
#include <vector>

#include "tetra/fdi/config.hpp"

namespace tetra::fdi {

//! What a row of the budget spends.
enum class BudgetKind : unsigned char {
  kFalseAlarm,      //!< H0 rejected while true: a `detected` event without a fault [per hour]
  kWrongExclusion,  //!< a true single-gyro hypothesis rejected while a wrong one stands [per episode]
  kReference        //!< a healthy reference rejected [per reference sample]
};

struct BudgetRow {
  const char* source;  //!< the ledger's source name (kEvidenceSources)
  BudgetKind kind;
  const char* key;        //!< the configuration key that sets it ("" when none)
  double per_evaluation;  //!< [-] probability per evaluation (NaN: not a probability)
  double evaluations;     //!< evaluations per hour (false alarms) or per episode (wrong exclusions)
  double total() const { return per_evaluation * evaluations; }  //!< [1/h] or [1/episode]
  const char* note;
};

struct Budget {
  int gyros = 0;
  double sample_period_s = 0.0;
  std::vector<BudgetRow> rows;
  double false_alarms_per_hour = 0.0;        //!< Σ of the false-alarm rows
  double wrong_exclusion_per_episode = 0.0;  //!< Σ of the wrong-exclusion rows that apply to N
};

//! The budget of `config` for `gyros` gyros sampled every `sample_period_s` [s] (> 0).
Budget error_budget(const PipelineConfig& config, int gyros, double sample_period_s);
//! A table for a terminal: one line per row, then the totals.
std::string to_text(const Budget& budget);

}  // namespace tetra::fdi
