#pragma once
// The fault-model check behind the filter's bias states (docs/fdi.md, "Filter bias states"): before the gyro
// whose bias estimate stands out alone is isolated, one single-gyro fault must explain both independent
// records of the episode — the parity mean and every gyro's disagreement with the reference over the same
// span — better than every other gyro's by a margin, and it must still be there in the latest half of the
// span (a spike has gone by then). Neither record contains the body's motion: the parity is blind to it
// (V·H = 0) and the reference measures it.

#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "evidence_rows.hpp"
#include "gyro_series.hpp"
#include "subset_cache.hpp"
#include "tetra/core/geometry.hpp"

namespace tetra::fdi::detail {

//! Each active gyro's disagreement with the reference over a span: its integrated angle less the rotation the
//! reference saw about its axis, and the 1σ of that difference without a fault.
struct SpanDisagreement {
  int start = -1;             //!< the reference monitor's snapshot the span starts at (−1: none)
  std::int64_t start_ns = 0;  //!< [ns] its time
  double span_s = 0.0;        //!< [s] from it to the last snapshot
  GyroMask gyros = 0;         //!< the gyros compared
  std::array<double, kMaxGyros> err_rad{};
  std::array<double, kMaxGyros> sigma_rad{};
};

//! The test's outcome for the best-fitting gyro.
struct BiasFit {
  int gyro = 0;             //!< 0: no single-gyro fault's model fits the records
  double size_rad_s = 0.0;  //!< the fault's mean rate over the span
  double margin = 0.0;      //!< [σ²] of the best hypothesis over the runner-up
};

class BiasHypothesis {
 public:
  //! Per gyro, its calibrated bias's 1σ (a constant offset in the parity mean) and its angle quantization Q
  //! (a rate error that telescopes in a mean).
  explicit BiasHypothesis(const std::vector<GyroConstants>& constants);

  //! The epoch's normalized parity `p` over the full active subset `s` (other epochs are not recorded).
  void record(const Eigen::VectorXd& p, const Subset& s);
  //! A reference sample at `now_ns` closes the parity bin since the previous sample, so that parity bins and
  //! the reference monitor's snapshots share their boundaries.
  void close_bin(std::int64_t now_ns);
  void reset();

  //! The single-gyro fault that explains the parity since `span.start_ns` and the reference disagreements
  //! `span` jointly best, when its model is accepted; else gyro 0. Writes the `bias_fit` row of every gyro of
  //! `s` into `rows` (none without records): Hi's statistic is what the best fault explains beyond gyro i's,
  //! rejected beyond the margin; every row no call when the best fit's residual is beyond what the model
  //! accepts.
  BiasFit best(const Subset& s, const SpanDisagreement& span, double sqrt_period, EvidenceRows& rows) const;
  //! The `bias_persists` row of gyro `id`'s fault in the latest part of the records (`late`): consistent
  //! when significant (χ²₁ at least design::bias_hypothesis_persist_sigma2) and of the sign `sign`, else
  //! rejected; none without records.
  std::optional<LedgerRow> persists(int id, double sign, const Subset& s, const SpanDisagreement& late,
                                    double sqrt_period) const;

 private:
  static constexpr int kBins = 512;  //!< as many as the reference monitor's snapshots
  struct Bin {
    std::int64_t end_ns = 0;
    GyroMask mask = 0;
    int count = 0;
    std::array<double, kMaxGyros> sum{};
  };
  //! Parity mean over the bins ending in (from_ns, last], per axis variance; returns the epoch count.
  int parity_mean(const Subset& s, std::int64_t from_ns, double sqrt_period) const;
  //! Gain G = (aᵀV⁻¹x)²/(aᵀV⁻¹a) of gyro `i`'s fault over both records, and its size.
  double gain(int i, const Subset& s, const SpanDisagreement& span, double sqrt_period, double& size) const;

  std::vector<double> bias_sigma_rad_s_;
  std::vector<double> quantization_rad_;
  std::vector<Bin> bins_;
  int bin_count_ = 0;
  Bin open_;
  mutable std::array<double, kMaxGyros> mean_{};  //!< scratch: parity mean
  mutable std::array<double, kMaxGyros> var_{};   //!< scratch: its variance per axis
};

}  // namespace tetra::fdi::detail
