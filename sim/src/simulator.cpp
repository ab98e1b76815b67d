#include "tetra/sim/simulator.hpp"

#include <cmath>
#include <cstdio>

#include "tetra/core/csv.hpp"
#include "tetra/core/units.hpp"
#include "text.hpp"

namespace tetra::sim {

Simulator::Simulator(Scenario scenario, SimOptions options, TruthMotion motion)
    : scenario_(std::move(scenario)),
      options_(std::move(options)),
      motion_(std::move(motion)),
      package_(scenario_, all_faults(scenario_, options_), options_.seed) {
  epochs_ = static_cast<std::size_t>(std::llround(scenario_.duration_s * scenario_.rate_hz));
  reset();
}

std::vector<FaultSpec> all_faults(const Scenario& scenario, const SimOptions& options) {
  std::vector<FaultSpec> faults = scenario.faults;
  faults.insert(faults.end(), options.faults.begin(), options.faults.end());
  return faults;
}

Result<Simulator> Simulator::create(const Scenario& scenario, const SimOptions& options) {
  // Validate the scenario with the run's extra faults, so they get the same checks.
  Scenario all = scenario;
  all.faults = all_faults(scenario, options);
  if (Status st = validate_scenario(all); !st) return st.error();
  auto motion = TruthMotion::create(scenario.motion, options.seed);
  if (!motion) return motion.error();
  return Simulator(scenario, options, std::move(motion.value()));
}

void Simulator::reset() {
  package_.reset();
  jitter_rng_ = Rng(stream_seed(options_.seed, Stream::kJitter, -1));
  k_ = 0;
}

bool Simulator::next(SimEpoch& out) {
  if (k_ >= epochs_) return false;
  const auto nominal_ns = static_cast<std::int64_t>(
      std::llround(static_cast<double>(k_) * static_cast<double>(kNanosPerSecond) / scenario_.rate_hz));
  std::int64_t stamp_ns = nominal_ns;
  if (scenario_.jitter_s > 0.0) {
    stamp_ns += seconds_to_ns(scenario_.jitter_s * (2.0 * jitter_rng_.uniform() - 1.0));
  }
  const double t_s = static_cast<double>(stamp_ns) / static_cast<double>(kNanosPerSecond);
  const MotionState truth = motion_.at(t_s);
  out.stamp_ns = stamp_ns;
  out.time_s = t_s;
  out.truth_q_RB = truth.q_RB;
  out.truth_omega_BR_B_rad_s = truth.omega_BR_B_rad_s;
  out.omega_BN_B_rad_s = truth.omega_BN_B_rad_s;
  package_.sample(truth.omega_BN_B_rad_s * kRadToDeg, t_s, out.raw_V, out.present);
  out.reference_q_RB = package_.reference(k_, truth.q_RB);
  ++k_;
  return true;
}

std::vector<std::pair<std::string, std::string>> Simulator::metadata() const {
  std::vector<std::pair<std::string, std::string>> meta;
  const MotionSpec& m = scenario_.motion;
  meta.emplace_back("generator", "tetra sim");
  meta.emplace_back("scenario", metadata_token(scenario_.name));
  meta.emplace_back("motion", std::string(motion_kind_name(m.kind)));
  meta.emplace_back("seed", std::to_string(options_.seed));
  meta.emplace_back("unit", metadata_token(scenario_.unit.unit));
  meta.emplace_back("rate_hz", number_text(scenario_.rate_hz));
  meta.emplace_back("duration_s", number_text(scenario_.duration_s));
  meta.emplace_back("reference_frame", motion_.reference_frame());
  if (m.kind == MotionKind::kStatic || m.kind == MotionKind::kLabOrbit) {
    meta.emplace_back("latitude_deg", number_text(m.latitude_deg));
  }
  if (m.kind == MotionKind::kLabOrbit) {
    meta.emplace_back("pitch_axis_B", "+Y");
    meta.emplace_back("pitch_rate_dps", number_text(m.pitch_rate_dps));
  }
  if (m.kind == MotionKind::kOrbit || m.kind == MotionKind::kSlews) {
    meta.emplace_back("pitch_axis_B", "-Y");
    meta.emplace_back("orbit_period_s", number_text(m.orbit_period_s));
    meta.emplace_back("acs_amplitude_deg", number_text(m.acs.amplitude_deg));
    meta.emplace_back("acs_peak_accel_dps2", number_text(motion_.acs_peak_accel_dps2()));
    for (const Slew& s : motion_.spec().slews) {
      if (m.kind != MotionKind::kSlews) break;
      // Metadata values may not contain spaces or commas (they separate key=value tokens).
      std::string text = "axis=";
      append_double(text, s.axis_B.x());
      text += '/';
      append_double(text, s.axis_B.y());
      text += '/';
      append_double(text, s.axis_B.z());
      text += ";angle_deg=" + number_text(s.angle_deg) + ";start_s=" + number_text(s.start_s) +
              ";duration_s=" + number_text(s.duration_s);
      meta.emplace_back("slew", text);
    }
  }
  if (scenario_.reference.rate_hz > 0.0) {
    meta.emplace_back("reference_hz", number_text(scenario_.reference.rate_hz));
    meta.emplace_back("reference_noise_arcsec", number_text(scenario_.reference.noise_arcsec));
    const ReferenceOptions& r = scenario_.reference;  // its failure modes, only when set
    if (r.latency_s > 0.0) meta.emplace_back("reference_latency_s", number_text(r.latency_s));
    if (r.bias_arcsec != 0.0)
      meta.emplace_back("reference_bias", number_text(r.bias_arcsec) + " arcsec from " +
                                              number_text(r.bias_at_s) + " s over " +
                                              number_text(r.bias_ramp_s) + " s");
    if (r.misid_duration_s > 0.0)
      meta.emplace_back("reference_misid", number_text(r.misid_deg) + " deg from " +
                                               number_text(r.misid_at_s) + " s for " +
                                               number_text(r.misid_duration_s) + " s");
    if (r.drop_probability > 0.0)
      meta.emplace_back("reference_drop_probability", number_text(r.drop_probability));
  }
  if (const ThermalOptions& t = scenario_.thermal; t.active()) {
    std::string text = number_text(t.start_C) + " to " + number_text(t.end_C) + " degC, tau " +
                       number_text(t.time_constant_s) + " s, deg/s/K";
    for (const double c : t.bias_dps_per_K) text += " " + number_text(c);
    meta.emplace_back("thermal", text);
  }
  if (scenario_.jitter_s > 0.0) meta.emplace_back("jitter_s", number_text(scenario_.jitter_s));
  if (scenario_.drop_probability > 0.0) {
    meta.emplace_back("drop_probability", number_text(scenario_.drop_probability));
  }
  for (const FaultSpec& f : package_.faults()) {
    std::string text = format_fault_spec(f);
    for (char& c : text) c = c == ',' ? ';' : c;  // commas separate metadata tokens
    meta.emplace_back("fault", text);
  }
  return meta;
}

Result<GyroLog> simulate_log(const Scenario& scenario, const SimOptions& options, Truth* truth,
                             Interrupt* interrupt) {
  auto created = Simulator::create(scenario, options);
  if (!created) return created.error();
  Simulator& sim = created.value();
  const int n = sim.gyro_count();
  GyroLog log;
  log.source = "simulated " + scenario.name;
  log.metadata = sim.metadata();
  log.gyro_count = n;
  log.has_reference = scenario.reference.rate_hz > 0.0;
  const std::size_t e = sim.epoch_count();
  log.time_s.reserve(e);
  log.values.reserve(e * static_cast<std::size_t>(n));
  log.present.reserve(e * static_cast<std::size_t>(n));
  log.lines.reserve(e);
  if (log.has_reference) {
    log.reference_present.reserve(e);
    log.reference_wxyz.reserve(e);
  }
  if (truth) {
    // Reserved like the log: no reallocation (a copy of all so far) between two polls of `interrupt`.
    *truth = Truth{};
    truth->time_s.reserve(e);
    truth->q_RB.reserve(e);
    truth->omega_BR_B_rad_s.reserve(e);
    truth->omega_BN_B_rad_s.reserve(e);
  }
  SimEpoch epoch;
  while (sim.next(epoch)) {
    if (sim.epochs_done() % 64 == 0 && interrupt_requested(interrupt, sim.epochs_done(), e)) {
      if (truth) *truth = Truth{};  // no partial truth behind
      return interrupted();
    }
    log.time_s.push_back(epoch.time_s);
    log.values.insert(log.values.end(), epoch.raw_V.begin(), epoch.raw_V.end());
    log.present.insert(log.present.end(), epoch.present.begin(), epoch.present.end());
    log.lines.push_back(log.lines.size() + 1);
    if (log.has_reference) {
      log.reference_present.push_back(epoch.reference_q_RB ? 1 : 0);
      log.reference_wxyz.push_back(epoch.reference_q_RB ? to_wxyz(*epoch.reference_q_RB)
                                                        : std::array<double, 4>{0.0, 0.0, 0.0, 0.0});
    }
    if (truth) {
      truth->time_s.push_back(epoch.time_s);
      truth->q_RB.push_back(epoch.truth_q_RB);
      truth->omega_BR_B_rad_s.push_back(epoch.truth_omega_BR_B_rad_s);
      truth->omega_BN_B_rad_s.push_back(epoch.omega_BN_B_rad_s);
    }
  }
  return log;
}

namespace {

//! Buffered writer of the truth file into an output of the run.
class TruthWriter {
 public:
  void open(OutputFile& out, const std::vector<std::pair<std::string, std::string>>& comments) {
    out_ = &out;
    for (const auto& [key, value] : comments) append_metadata(buffer_, key, value);
    buffer_ += "time_s,qw,qx,qy,qz,wx_dps,wy_dps,wz_dps\n";
  }
  Status write(const SimEpoch& e) {
    append_double(buffer_, e.time_s);
    const Quaternion q = canonical(e.truth_q_RB);
    for (double c : to_wxyz(q)) {
      buffer_ += ',';
      append_double(buffer_, c + 0.0);  // + 0.0: never write "-0"
    }
    for (int a = 0; a < 3; ++a) {
      buffer_ += ',';
      append_double(buffer_, e.truth_omega_BR_B_rad_s[a] * kRadToDeg + 0.0);
    }
    buffer_ += '\n';
    if (buffer_.size() > (1u << 20)) return flush();
    return ok_status();
  }
  Status flush() {
    if (Status st = out_->write(buffer_); !st) return st;
    buffer_.clear();
    return ok_status();
  }

 private:
  OutputFile* out_ = nullptr;
  std::string buffer_;
};

}  // namespace

Status write_simulation(Simulator& simulator, const std::string& log_path, const std::string& truth_path,
                        void (*progress)(double fraction)) {
  RunFiles files;
  auto log = files.add(log_path, "log");
  if (!log) return log.error();
  OutputFile* truth = nullptr;
  if (!truth_path.empty()) {
    auto t = files.add(truth_path, "truth");
    if (!t) return t.error();
    truth = *t;
  }
  if (Status st = write_simulation(simulator, **log, truth, {}, progress); !st) return st;
  return files.commit();
}

Status write_simulation(Simulator& simulator, OutputFile& log, OutputFile* truth_out,
                        const std::vector<std::pair<std::string, std::string>>& extra_metadata,
                        void (*progress)(double fraction)) {
  const Scenario& sc = simulator.scenario();
  const bool with_reference = sc.reference.rate_hz > 0.0;
  auto meta = simulator.metadata();
  meta.insert(meta.end(), extra_metadata.begin(), extra_metadata.end());
  GyroLogWriter writer;
  if (Status st = writer.open(log, simulator.gyro_count(), with_reference, false, meta); !st) return st;
  TruthWriter truth;
  if (truth_out != nullptr) {
    auto truth_meta = meta;
    truth_meta.emplace_back("truth", "q_body_to_reference_frame;w_body_relative_to_reference_frame_in_body");
    truth.open(*truth_out, truth_meta);
  }
  SimEpoch epoch;
  const std::size_t total = simulator.epoch_count();
  const std::size_t every = total / 10 + 1;
  while (simulator.next(epoch)) {
    std::optional<std::array<double, 4>> ref;
    if (epoch.reference_q_RB) ref = to_wxyz(*epoch.reference_q_RB);
    if (Status st = writer.write(epoch.time_s, epoch.raw_V, epoch.present, ref); !st) return st;
    if (truth_out != nullptr) {
      if (Status st = truth.write(epoch); !st) return st;
    }
    if (progress && simulator.epochs_done() % every == 0) {
      progress(static_cast<double>(simulator.epochs_done()) / static_cast<double>(total));
    }
  }
  if (Status st = writer.close(); !st) return st;
  if (truth_out != nullptr) return truth.flush();
  return ok_status();
}

}  // namespace tetra::sim
