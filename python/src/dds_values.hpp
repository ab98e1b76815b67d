#pragma once
// tetra.dds's values: what the wire carries (services/dds/include/tetra/dds/convert.hpp's views) as dicts in
// SI units, with the names of idl/tetra.idl and their units and frames (q_RB_wxyz, omega_BR_B_rad_s,
// sigma_rad). python/tetra/dds.py makes dataclasses of them.
#include "common.hpp"
#include "tetra/dds/convert.hpp"
#include "tetra/fdi/types.hpp"

namespace tetra::python {

//! One Attitude: stamp_ns, time_s, q_RB_wxyz (4,), omega_BR_B_rad_s (3,), sigma_rad (3,),
//! protection_level_rad (3,), mode, gyros (ids), gyros_mask, fdi_available.
py::dict wire_attitude_dict(const fdi::AttitudeEstimate& attitude, int n_gyros);
//! One Health: the pipeline's health, the service's counters and the reference's state.
py::dict wire_health_dict(const dds::HealthView& health);
//! One FdiEvent: the keys of Pipeline's events (event_dict) and unit, event_seq, command_id and, for an
//! acknowledgement, command, force, refused, operator, origin.
py::dict wire_event_dict(const dds::EventView& event, int n_gyros);

}  // namespace tetra::python
