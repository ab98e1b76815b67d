#pragma once
// The fusion pipeline: raw epochs in; attitude, health and FDI events out. One object serves
// `tetra replay` (files) and `tetra fusion` (DDS). Lifecycle: create → step(epoch)… → reset().
// A library object: it never exits or throws on bad input; bad epochs are rejected and counted.

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "tetra/core/calibration_file.hpp"
#include "tetra/core/result.hpp"
#include "tetra/fdi/config.hpp"
#include "tetra/fdi/types.hpp"

namespace tetra::fdi {

struct StepResult {
  bool accepted = false;         //!< false: epoch rejected (and counted), attitude not advanced
  AttitudeEstimate attitude;     //!< valid when accepted
  std::vector<FdiEvent> events;  //!< events triggered by this epoch, in order (often empty)
};

class Pipeline {
 public:
  Pipeline(Pipeline&&) noexcept;
  Pipeline& operator=(Pipeline&&) noexcept;
  Pipeline(const Pipeline&) = delete;
  Pipeline& operator=(const Pipeline&) = delete;
  ~Pipeline();

  //! Validates the calibration and configuration once; errors name what is wrong.
  static Result<Pipeline> create(const Calibration& calibration, const PipelineConfig& config);

  //! Back to the initial state: the pipeline create() made, created again from the same calibration and
  //! configuration (every gyro reinstated, the attitude the configured one, nothing learned, the clock
  //! unset). References returned before are invalid.
  void reset();
  //! Processes one epoch. The returned reference is valid until the next call.
  const StepResult& step(const Epoch& epoch);
  //! Operator commands. Each returns its acknowledgement (an event of type kCommand), once: the caller
  //! publishes or records it. What the command changed (reconfigured, lost, cleared) comes with the next
  //! step()'s events. `exclude` refuses to leave a set of gyros that cannot determine the attitude, unless
  //! `force`; a refused command changes nothing and its acknowledgement says why (`refused()`).
  FdiEvent exclude(int gyro_id, std::int64_t stamp_ns, bool force = false);
  FdiEvent reinstate(int gyro_id, std::int64_t stamp_ns);
  FdiEvent reset_command(std::int64_t stamp_ns);

  //! True when these gyros determine the attitude: at least three whose axes span 3-D (the one rule for
  //! LOST, shared by the pipeline and whoever adds what only it knows, e.g. a service's silent streams).
  bool observable(GyroMask gyros) const;
  const Health& health() const;
  int gyro_count() const;
  const PipelineConfig& config() const;
  //! Start-up echo: the thresholds derived from the configuration and the calibration (multi-line).
  std::string describe_thresholds() const;
  //! Findings of the evidence sources that the arbiter's rule did not confirm from their ledger rows since
  //! creation or the last reset(), so excluded nothing (docs/fdi.md, "The ledger and the arbiter"); 0 over
  //! every golden scenario.
  std::uint64_t arbiter_refusals() const;

 private:
  class Impl;
  explicit Pipeline(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;  //!< all state; created again only by reset(), never in step()
};

}  // namespace tetra::fdi
