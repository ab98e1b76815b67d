// The demo's simulation, files and monitor (tetra/dds_tools/demo.hpp).
#include "tetra/dds_tools/demo.hpp"

#include <cstdlib>
#include <filesystem>
#include <sstream>

#include "tetra/core/calibration_file.hpp"
#include "tetra/core/csv.hpp"
#include "tetra/core/input_files.hpp"
#include "tetra/core/json.hpp"
#include "tetra/core/units.hpp"
#include "tetra/dds/topics.hpp"
#include "tetra/report/text.hpp"
#include "tetra/sim/scenario.hpp"

namespace tetra::dds_tools {

using report::fixed;

Result<sim::Simulator> demo_simulator(const DemoSimulation& o, const sim::FaultSpec& fault,
                                      sim::SimEpoch& first) {
  auto scenario = std::filesystem::exists(o.scenario) ? sim::read_scenario(o.scenario)
                                                      : sim::builtin_scenario(o.scenario);
  if (!scenario) return scenario.error();
  scenario->duration_s = o.seconds;
  scenario->rate_hz = o.rate_hz;
  if (fault.at_s >= o.seconds)
    return bad_input(ErrorSubject(kSubjectFault), "at=" + report::fixed(fault.at_s, 1) + " is after the end");
  sim::SimOptions options;
  options.seed = o.seed;
  options.faults.push_back(fault);
  auto simulator = sim::Simulator::create(*scenario, options);
  if (!simulator) return simulator.error();
  if (!simulator->next(first)) return bad_input("the scenario has no epochs");
  simulator->reset();
  return simulator;
}

Status write_demo_service_files(const std::string& dir, const sim::Simulator& simulator,
                                const sim::SimEpoch& first, double rate_hz) {
  const std::string& unit = simulator.scenario().unit.unit;
  if (auto s = write_calibration(dir + "/calibration.yaml", simulator.scenario().unit); !s) return s;
  const auto q = to_wxyz(first.truth_q_RB);
  std::string unit_text;
  append_json_string(unit_text, unit);  // a JSON string is a YAML double-quoted scalar: any name reads back
  std::ostringstream config;
  config << "# tetra demo: fusion service configuration\n"
         << "unit: " << unit_text << "\ncalibration: calibration.yaml\n"
         << "sample_rate_hz: " << rate_hz << "\n"
         << "max_latency_s: 0.05\nhealth_period_s: 0.5\n"
         << "pipeline:\n  initial_q_wxyz: [" << report::json_number(q[0]) << ", " << report::json_number(q[1])
         << ", " << report::json_number(q[2]) << ", " << report::json_number(q[3]) << "]\n"
         << "  sample_period_s: " << report::json_number(1.0 / rate_hz) << '\n';
  return write_text_file(dir + "/fusion.yaml", config.str());
}

Result<std::string> demo_folder(const std::string& keep_dir) {
  std::string dir = keep_dir;
  if (dir.empty()) {
    char tmpl[] = "/tmp/tetra-demo-XXXXXX";
    if (mkdtemp(tmpl) == nullptr) return failure("cannot create a temporary folder");
    dir = tmpl;
  }
  std::filesystem::create_directories(dir);
  return dir;
}

void DemoWatch::take() {
  (void)health_reader_.take(
      [&](const tetra_Health& msg, const dds_sample_info_t&) { health_ = dds::from_wire(msg); });
  (void)event_reader_.take(
      [&](const tetra_FdiEvent2& msg, const dds_sample_info_t&) { on_event(dds::from_wire(msg).event); });
}

void DemoWatch::on_event(const fdi::FdiEvent& e) {
  const double t = ns_to_seconds(e.stamp_ns);
  out_ << "  event  " << fdi::to_json(e, n_) << '\n';
  if (e.type == fdi::EventType::kDetected && !timeline_.detected_s) timeline_.detected_s = t;
  if (e.type == fdi::EventType::kIsolated && !timeline_.isolated_s) {
    timeline_.isolated_s = t;
    timeline_.isolated_gyro = e.gyro;
    timeline_.isolated_kind = fdi::to_string(e.kind);
  }
  if (e.type == fdi::EventType::kReconfigured && !timeline_.reconfigured_s) {
    timeline_.reconfigured_s = t;
    timeline_.reconfigured_gyros = mask_to_string(e.gyros, n_);
  }
}

void DemoWatch::print_progress(double time_s, std::optional<double> error_deg) {
  take();
  out_ << "  t=" << fixed(time_s, 1) << " s";
  if (health_) {
    const auto& h = health_->health;
    out_ << "  mode " << fdi::to_string(h.mode) << "  gyros " << mask_to_string(h.used, n_) << "  [";
    for (std::size_t i = 0; i < h.gyros.size(); ++i) {
      out_ << (i ? " " : "") << i + 1 << ":" << fdi::to_string(h.gyros[i].state);
    }
    out_ << "]  parity " << fixed(h.parity_residual, 2) << " σ  cusum " << fixed(h.cusum, 1) << "/"
         << fixed(h.cusum_threshold, 1);
  }
  if (error_deg) out_ << "  attitude error " << fixed(*error_deg * 3600.0, 1) << " arcsec";
  out_ << '\n' << std::flush;
}

}  // namespace tetra::dds_tools
