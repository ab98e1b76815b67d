#pragma once
// Ground monitoring of every unit on a DDS domain, as `tetra monitor` shows it (docs/dds.md): Health and
// FdiEvent (transient-local: a late monitor still gets the current health and the event history) and
// Attitude, as a dashboard refreshed every period or as JSON lines; or every unit's current health once.
// A unit whose last Health is older than three of the service's Health periods is STALE, one whose Health
// writer lost its liveliness SERVICE LOST (docs/ground.md).

#include <cstddef>
#include <ostream>
#include <string>

#include <dds/dds.h>

#include "tetra/core/result.hpp"
#include "tetra/dds/shutdown.hpp"

namespace tetra::dds_tools {

struct MonitorOptions {
  std::string unit_filter;  //!< only this unit; empty: every unit discovered
  bool jsonl = false;       //!< JSON lines instead of the dashboard
  bool once = false;        //!< each unit's current health (and event history) once all have arrived
  double period_s = 0.4;    //!< [s] refresh period
  double duration_s = 0.0;  //!< [s] stop after this long; 0: until `shutdown`
  double timeout_s = 5.0;   //!< [s] with `once`: a failure when no unit answers within this
  bool terminal = false;    //!< the output is a terminal: each dashboard clears the screen
  dds_domainid_t domain = DDS_DOMAIN_DEFAULT;
};

struct Monitored {
  std::size_t units = 0;  //!< units heard
};

//! Monitors until `shutdown` (SIGINT/SIGTERM), the duration, or (once) every unit's health printed; the
//! dashboard or JSON lines go to `out`.
Result<Monitored> monitor_units(const MonitorOptions& options, dds::ShutdownSignal& shutdown,
                                std::ostream& out);

}  // namespace tetra::dds_tools
