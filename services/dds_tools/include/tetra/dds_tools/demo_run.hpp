#pragma once
// The run of `tetra demo` (docs/dds.md): simulator + fusion service + monitor on a private loopback DDS
// domain, a gyro failure injected mid-run, and a summary. The simulator runs in this process (it scores
// the attitude it receives against its truth); the service is a separate `tetra fusion` process; the
// monitor's view is printed once a second and, at the end, by `tetra monitor --once`. With `web`, a
// `tetra ground` process serves the ground station in the browser (docs/ground.md) and stays up after
// the summary until the shutdown is requested.

#include <cstdint>
#include <ostream>
#include <string>

#include <dds/dds.h>

#include "tetra/core/result.hpp"
#include "tetra/dds/shutdown.hpp"
#include "tetra/sim/fault.hpp"

namespace tetra::dds_tools {

struct DemoOptions {
  std::string scenario_name = "orbit";                 //!< static, lab-orbit, orbit, slews or FILE.yaml
  std::string fault_text = "gyro=2,kind=stuck,at=15";  //!< the injected failure, as given (printed)
  double seconds = 40.0;                               //!< [s] simulated duration
  double rate_hz = 50.0;                               //!< [Hz] gyro rate
  double speed = 8.0;                                  //!< times faster than real time (1: watch it live)
  std::uint64_t seed = 1;                              //!< simulation seed
  std::string keep_dir;                                //!< keep the service's files here (empty: removed)
  bool web = false;                                    //!< also run the ground station
  std::string listen = "127.0.0.1:8080";               //!< HOST:PORT of the ground station
  dds_domainid_t domain = DDS_DOMAIN_DEFAULT;          //!< the DDS domain (loopback only)
};

//! Runs the demo with `fault` (parsed from options.fault_text), printing on `out`; sets CYCLONEDDS_URI to
//! the loopback configuration (the children inherit it). True when the fault was isolated and attitudes
//! were scored, or the shutdown was requested. A fault that does not fit the run: subject kSubjectFault.
Result<bool> run_demo(const DemoOptions& options, const sim::FaultSpec& fault, dds::ShutdownSignal& shutdown,
                      std::ostream& out);

}  // namespace tetra::dds_tools
