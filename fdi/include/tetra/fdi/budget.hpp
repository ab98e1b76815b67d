#pragma once
// The FDI's error budget (docs/fdi.md, "The budget"). One key, `false_alarm_probability` (p), is the unit
// every test's error probability is allocated in: each test's share of p is one row of kAllocations, with
// the reason for it, and every probability threshold derives from p × share. error_budget() states what
// that allows, per hour of fault-free flight (false alarms) and per fault episode (a healthy gyro named),
// summed into the totals for a unit of N gyros sampled every T seconds. Sources whose thresholds are counts
// or ratios, not probabilities, are listed with no figure: the budget does not cover them.

#include <string>
#include <vector>

#include "tetra/fdi/config.hpp"

namespace tetra::fdi {

//! The tests whose error probability is allocated from `false_alarm_probability`.
enum class BudgetTest : unsigned char {
  kChi2,                 //!< one epoch's parity χ² (per epoch)
  kCusum,                //!< the parity CUSUM and the held-level CUSUM (1 / in-control ARL, per epoch)
  kJump,                 //!< the one-epoch jump of the parity (per epoch)
  kParityBlockMatch,     //!< the parity block match of a slow error (per epoch)
  kGlt,                  //!< N ≥ 5: one form of the GLT rejecting a true single-gyro hypothesis
  kReferenceCheck,       //!< each consistency test of the reference (per sample)
  kReferenceNoiseMatch,  //!< three gyros: the reference noise match (per sample)
  kReferenceGate,        //!< the filter's 3-dof gate leaving out a good reference sample (per sample)
  kReferenceBiasMatch,  //!< a common drift in the reference's innovations, its bias model opened (per sample)
  kMotionFit,    //!< the parity's fit to the body rate rejecting H0 or a single-gyro hypothesis (per block)
  kParitySpread  //!< the parity's differences rejecting the stated white noise (per look)
};
constexpr int kBudgetTestCount = 11;

//! One row of the allocation: a test's share of false_alarm_probability, and why.
struct Allocation {
  BudgetTest test;
  const char* name;
  double share;  //!< [-] the test's probability is share × false_alarm_probability
  const char* why;
};
extern const Allocation kAllocations[kBudgetTestCount];
//! The largest share: false_alarm_probability × it stays below 0.5 (config_keys.cpp's range).
inline constexpr double kLargestShare = 1000.0;

//! share × false_alarm_probability: the probability `test`'s threshold is set at.
double allocated_probability(const PipelineConfig& config, BudgetTest test);
//! [epochs] the CUSUMs' in-control average run length, 1 / allocated_probability(kCusum).
double cusum_arl0_epochs(const PipelineConfig& config);

//! What a row of the budget spends.
enum class BudgetKind : unsigned char {
  kFalseAlarm,      //!< H0 rejected while true: a `detected` event without a fault [per hour]
  kWrongExclusion,  //!< a true single-gyro hypothesis rejected while a wrong one stands [per episode]
  kReference,       //!< a healthy reference rejected [per reference sample]
  kMismatch,        //!< a calibration_mismatch named on a unit its calibration describes [per hour]
  kNoiseModel       //!< the stated noise widened on a unit it describes (a noise_model event) [per hour]
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
