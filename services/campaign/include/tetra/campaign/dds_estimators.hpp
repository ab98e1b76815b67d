#pragma once
// `tetra campaign` with `target: dds` (docs/campaign.md): every run against a `tetra fusion` service
// over DDS. The campaign starts one service per run (the running program itself, `tetra fusion`, on the
// spec's domain, under a unit key of its own) configured with the scenario's unit as its calibration,
// the spec's `pipeline:` map and the run's true initial attitude; publishes the run's epochs to it in
// lockstep (tetra/dds_tools/sim_dds_estimator.hpp), reads its Attitude, FdiEvent and Health topics, and stops
// it at the end of the run. A fresh service per run is the reset between runs: the `reset` command resets
// only FDI (the attitude and the time go on), and a service restarts its time base only after its
// unit went silent — neither returns it to a run's start.

#include <string>

#include "tetra/sim/campaign.hpp"

namespace tetra::campaign {

//! The estimators of a DDS campaign (made by tetra::dds_tools; in a build without DDS, by tetra::campaign:
//! each run then fails, naming why); `work_dir` holds each run's service configuration and log while
//! it runs (kept when the run fails, for the log).
sim::EstimatorFactory dds_campaign_estimators(const sim::CampaignSpec& spec, const std::string& work_dir);

}  // namespace tetra::campaign
