#pragma once
// FDI events and gyro masks as Python values.
#include "common.hpp"
#include "tetra/core/geometry.hpp"
#include "tetra/fdi/types.hpp"

namespace tetra::python {

//! The ids (1..N) in `mask`.
py::list gyro_ids(GyroMask mask, int n_gyros);
//! One event as a dict: stamp_ns, time_s, type, gyro, test, statistic, kind, evidence, gyros, command,
//! outcome, why, detail, and json (the line `tetra replay --events` writes).
py::dict event_dict(const fdi::FdiEvent& event, int n_gyros);
//! A health's state as a dict (Pipeline.health and tetra.dds's Health): mode, used, gyros (state, kind,
//! bias_rad_s, bias_sigma_rad_s each), chi2, cusum, their thresholds, fdi_available, reference_state.
py::dict health_state_dict(const fdi::Health& health, int n_gyros);

}  // namespace tetra::python
