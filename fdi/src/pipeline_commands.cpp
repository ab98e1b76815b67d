// Operator commands (exclude, reinstate, reset), the start-up echo and the public API of the pipeline: part
// of Pipeline::Impl (pipeline_impl.hpp).

#include "pipeline_impl.hpp"
#include "tetra/fdi/budget.hpp"

namespace tetra::fdi {

// ---------------------------------------------------------------------------------------------
// operator commands

void Pipeline::Impl::reinstate(int id) {
  publish_filter_health();  // the health keeps the last step's filter
  if (gyro_set_.is_excluded(id)) attitude_.thaw(id);
  noise_match_.forget(id);
  own_noise_.forget(id);
  bias_match_.forget(id);
  gyro_set_.reinstate(id);
  series_.forget_evidence(id);
  reference_.restart_windows();  // the reinstated gyro's angle has a gap: the reference windows start again
}

FdiEvent Pipeline::Impl::acknowledge(CommandVerb verb, int id, CommandOutcome outcome, bool changed,
                                     std::int64_t stamp_ns) {
  if (changed) {
    restart_detectors();
    update_mode(stamp_ns);
  }
  FdiEvent ack;
  ack.stamp_ns = stamp_ns;
  ack.type = EventType::kCommand;
  ack.gyro = id;
  ack.command = verb;
  ack.outcome = outcome;
  ack.detail = std::string(to_string(verb)) + " " + std::to_string(id) + ": " + to_string(outcome);
  ack.gyros = gyro_set_.active();
  if (changed) {
    FdiEvent rc;
    rc.stamp_ns = stamp_ns;
    rc.type = persistent_mode_ == Mode::kLost ? EventType::kLost : EventType::kReconfigured;
    rc.gyros = gyro_set_.active();
    pending_.push_back(rc);
  }
  return ack;
}

FdiEvent Pipeline::Impl::command_exclude(int id, std::int64_t stamp_ns, bool force) {
  const auto verb = CommandVerb::kExclude;
  if (!gyro_set_.contains(id)) return acknowledge(verb, id, CommandOutcome::kNoSuchGyro, false, stamp_ns);
  if (gyro_set_.is_excluded(id))
    return acknowledge(verb, id, CommandOutcome::kAlreadyExcluded, false, stamp_ns);
  if (!force && !subsets_.observable(without_gyro(gyro_set_.active(), id)))
    return acknowledge(verb, id, CommandOutcome::kRefusedUnobservable, false, stamp_ns);
  publish_filter_health();  // the health keeps the last step's filter
  gyro_set_.exclude(id, FaultKind::kUnknown);
  attitude_.freeze(id);
  series_.restart_evidence();
  reference_.restart_windows();
  return acknowledge(verb, id, CommandOutcome::kDone, true, stamp_ns);
}

FdiEvent Pipeline::Impl::command_reinstate(int id, std::int64_t stamp_ns) {
  const auto verb = CommandVerb::kReinstate;
  if (!gyro_set_.contains(id)) return acknowledge(verb, id, CommandOutcome::kNoSuchGyro, false, stamp_ns);
  if (!gyro_set_.is_excluded(id)) return acknowledge(verb, id, CommandOutcome::kNotExcluded, false, stamp_ns);
  reinstate(id);
  return acknowledge(verb, id, CommandOutcome::kDone, true, stamp_ns);
}

FdiEvent Pipeline::Impl::command_reset(std::int64_t stamp_ns) {
  // FDI reset: every gyro reinstated, detectors and episode cleared, the reference judged afresh; the
  // attitude and time go on.
  for (int id = 1; id <= n_; ++id) reinstate(id);
  consistency_.reset();
  reference_rejected_ns_.reset();
  trend_.stop();
  noise_match_.reset();
  bias_match_.release(attitude_.filter());  // every bias model the calibration's again
  drift_match_.reset();
  calibration_fit_.reset();  // a standing mismatch judged afresh too
  for (int id = 1; id <= n_; ++id) attitude_.filter().set_added_noise(id, 0.0);
  restart_detectors();
  update_mode(stamp_ns);
  FdiEvent ack;
  ack.stamp_ns = stamp_ns;
  ack.type = EventType::kCommand;
  ack.command = CommandVerb::kReset;
  ack.gyros = gyro_set_.active();
  ack.detail = "reset: done, all gyros reinstated";
  FdiEvent c;
  c.stamp_ns = stamp_ns;
  c.type = EventType::kCleared;
  c.gyros = gyro_set_.active();
  pending_.push_back(c);
  return ack;
}

std::string Pipeline::Impl::describe_thresholds() const {
  std::string out = "gyros: " + std::to_string(n_) + "\n";
  for (int id = 1; id <= n_; ++id) {
    char text[64];
    std::snprintf(text, sizeof text, "gyro %d: N = %.6g deg/sqrt(s)\n", id,
                  series_.constants(id).arw_rad_rts * kRadToDeg);
    out += text;
  }
  if (!subsets_.ready()) return out;
  const Subset* s = subsets_.find(gyro_set_.all());
  if (s == nullptr || s->dof < 1) return out;
  out += "sample period: ";
  append_double(out, subsets_.period_s());
  out += " s\nparity dimension: " + std::to_string(s->dof) + "\nchi2 threshold: ";
  append_double(out, s->chi2_threshold);
  out += "\ncusum k (sigma): ";
  append_double(out, s->cusum_k);
  out += "\nbias wander in the parity (sigma): ";
  append_double(out, s->bias_wander_sigma);
  out +=
      s->wander_averaged ? " (averaged in h)" : " (beyond the average's reach: a tolerance in the bound D)";
  out += "\nconstant bound D0 (sigma: calibrated biases, stated ramps, absorbed wander): ";
  append_double(out, s->calibration_bias_bound);
  out += "\ncusum h (sigma): ";
  append_double(out, s->cusum_h);
  out += "\nlevel test k (sigma, during an episode): ";
  append_double(out, s->level_k);
  out += "\nlevel test h (sigma): ";
  append_double(out, s->level_h);
  out += "\n" + to_text(error_budget(config_, n_, subsets_.period_s()));
  return out;
}

// ---------------------------------------------------------------------------------------------
// public API

Pipeline::Pipeline(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Pipeline::Pipeline(Pipeline&&) noexcept = default;
Pipeline& Pipeline::operator=(Pipeline&&) noexcept = default;
Pipeline::~Pipeline() = default;

Result<Pipeline> Pipeline::create(const Calibration& stated, const PipelineConfig& config) {
  if (auto st = validate_calibration(stated, "calibration"); !st) return st.error();
  // A gyro whose noise is not stated runs on the conservative defaults (default_noise_warning says which).
  const Calibration calibration = with_default_noise(stated, config);
  if (auto st = validate(config); !st) return st.error();
  auto constants = gyro_constants(calibration, config);
  if (!constants) return constants.error();
  Eigen::VectorXd arw(calibration.gyro_count());
  for (Eigen::Index i = 0; i < arw.size(); ++i)
    arw[i] = (*constants)[static_cast<std::size_t>(i)].arw_rad_rts;
  auto geometry = GyroGeometry::create(calibration.axes_B(), arw);
  if (!geometry) return geometry.error();
  return Pipeline(std::make_unique<Impl>(config, calibration, std::move(*geometry), std::move(*constants)));
}

void Pipeline::reset() {
  // Created again from its inputs: every stage's state, and any a later change adds, is the initial one.
  impl_ = std::make_unique<Impl>(impl_->inputs());
}
const StepResult& Pipeline::step(const Epoch& epoch) {
  return impl_->step(epoch);
}
FdiEvent Pipeline::exclude(int gyro_id, std::int64_t stamp_ns, bool force) {
  return impl_->command_exclude(gyro_id, stamp_ns, force);
}
FdiEvent Pipeline::reinstate(int gyro_id, std::int64_t stamp_ns) {
  return impl_->command_reinstate(gyro_id, stamp_ns);
}
FdiEvent Pipeline::reset_command(std::int64_t stamp_ns) {
  return impl_->command_reset(stamp_ns);
}
bool Pipeline::observable(GyroMask gyros) const {
  return impl_->observable(gyros);
}
const Health& Pipeline::health() const {
  return impl_->health();
}
int Pipeline::gyro_count() const {
  return impl_->gyro_count();
}
const PipelineConfig& Pipeline::config() const {
  return impl_->config();
}
std::string Pipeline::describe_thresholds() const {
  return impl_->describe_thresholds();
}
std::uint64_t Pipeline::arbiter_refusals() const {
  return impl_->arbiter_refusals();
}

}  // namespace tetra::fdi
