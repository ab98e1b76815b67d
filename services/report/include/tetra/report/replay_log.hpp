#pragma once
// The whole fusion pipeline offline, as `tetra replay` runs it: a gyro log in; attitude rows
// (docs/interfaces.md §2.4) and FDI events (docs/interfaces.md §2.5) out, block by block (memory does not
// grow with the log's length); a summary on `err`. The same Pipeline object serves the DDS service.

#include <cstddef>
#include <cstdio>
#include <map>
#include <optional>
#include <ostream>
#include <string>

#include "tetra/core/result.hpp"
#include "tetra/fdi/types.hpp"
#include "tetra/report/argument_names.hpp"
#include "tetra/report/ledger_explainer.hpp"

namespace tetra::report {

struct ReplayLogOptions {
  std::string log_path;                    //!< gyro log (CSV, or HDF5 when named .h5)
  std::string calibration_path;            //!< calibration YAML (docs/interfaces.md §2.3)
  std::string config_path;                 //!< YAML with a 'pipeline:' map (docs/fdi.md); empty: defaults
  std::string attitude_path;               //!< attitude rows to write (CSV)
  std::string events_path;                 //!< FDI events to write (JSON lines)
  std::string commands_path;               //!< operator commands to re-apply (tetra record's); empty: none
  std::optional<double> latitude_deg;      //!< [deg] ground-test mode: remove the Earth rate at this latitude
  std::optional<std::string> initial_q;    //!< initial attitude "w,x,y,z"; none: the configuration's
  bool verbose = false;                    //!< the configuration and the derived thresholds on `err`
  std::FILE* progress_terminal = nullptr;  //!< a terminal to draw the progress line on; nullptr: none
  std::optional<double> explain_s;         //!< [s] explain the ledger at this time (ReplayedLog::explanation)
  //! How messages name the arguments (log_path, attitude_path, ...) and the command ("command").
  ArgumentNames names;
};

//! Error::subject of an initial_q that is not a unit quaternion "w,x,y,z".
inline constexpr const char* kSubjectInitialQ = "initial_q";

struct ReplayedLog {
  std::size_t epochs = 0;                    //!< epochs read
  std::map<std::string, int> event_counts;   //!< per event type (fdi::to_string)
  fdi::Health health;                        //!< the pipeline's health after the last epoch
  std::optional<LedgerExplainer> explainer;  //!< with explain_s: what it saw
  std::string explanation;                   //!< with explain_s: the ledger at that time
};

//! Replays the log; the outputs are written all or none (through the output layer). The summary (and
//! its warnings) goes to `err`.
Result<ReplayedLog> replay_log(const ReplayLogOptions& options, std::ostream& err);

}  // namespace tetra::report
