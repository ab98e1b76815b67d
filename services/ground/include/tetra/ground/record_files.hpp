#pragma once
// History from `tetra record` files (docs/ground.md): the attitude CSV (docs/interfaces.md §2.4) and the
// events or commands JSON lines in one folder, served as the stream's JSON objects. The files hold
// sensor time only (no UTC), so rows are selected by `sensor_time_s`.

#include <cstddef>
#include <string>

#include <nlohmann/json.hpp>

#include "tetra/core/result.hpp"

namespace tetra::ground {

//! The record files of `dir`: [{"name", "kind": "attitude" | "events"}] (.csv with an attitude
//! header, .jsonl), sorted by name.
Result<nlohmann::json> list_records(const std::string& dir);

//! Rows of record file `name` (a plain file name inside `dir`) with sensor time in
//! [start_s, end_s], evenly thinned to at most `max_points` (0: all). Errors name the file and line.
Result<nlohmann::json> read_record(const std::string& dir, const std::string& name, double start_s,
                                   double end_s, std::size_t max_points);

}  // namespace tetra::ground
