#pragma once
// JSON of what the ground shows: Health, Attitude, FdiEvent, command acknowledgements and the link
// state of a unit, as sent to browsers (docs/ground.md has every field). Times: `utc_ms` is the DDS
// source timestamp in milliseconds since 1970 (UTC), `sensor_time_s` the unit's own clock.

#include <cstdint>
#include <string>

#include <nlohmann/json.hpp>

#include "tetra/dds/convert.hpp"
#include "tetra/fdi/types.hpp"

namespace tetra::ground {

//! The JSON text of `value`, whatever bytes its strings hold: a DDS string (unit, operator id, event
//! detail) need not be UTF-8, and any byte that is not part of valid UTF-8 is written as U+FFFD (the
//! replacement character), so the text is always valid UTF-8 JSON and never an exception.
std::string json_text(const nlohmann::json& value);

//! [ms] UTC milliseconds of a DDS source timestamp (ns since 1970).
double utc_ms(std::int64_t utc_ns);

//! [deg] roll, pitch, yaw: the body's Z-Y-X (3-2-1) Euler angles relative to the reference frame.
struct EulerDeg {
  double roll_deg = 0.0;
  double pitch_deg = 0.0;
  double yaw_deg = 0.0;
};
EulerDeg euler_zyx_deg(const Quaternion& q_RB);

//! True when the parity space exists: at least four gyros in the solution (χ², CUSUM meaningful).
bool parity_available(const fdi::Health& health);

nlohmann::json health_json(const dds::HealthView& health, std::int64_t utc_ns);
nlohmann::json attitude_json(const std::string& unit, const fdi::AttitudeEstimate& attitude,
                             std::int64_t utc_ns);
//! An event (docs/interfaces.md §2.5 fields) with its unit, sequence number, UTC and, for acknowledgements,
//! the command's audit fields.
nlohmann::json event_json(const dds::EventView& event, int n_gyros, std::int64_t utc_ns);
//! The acknowledgement of a command as `tetra command` prints it and the ground's POST answers it.
nlohmann::json ack_json(const dds::EventView& ack, int n_gyros);

}  // namespace tetra::ground
