#include "tetra/sim/turntable.hpp"

#include <cmath>
#include <string>

#include "tetra/core/csv.hpp"
#include "tetra/core/frames.hpp"
#include "tetra/core/units.hpp"
#include "text.hpp"

namespace tetra::sim {

namespace {

constexpr std::size_t kMaxRows = 50'000'000;  // a guard against absurd plans (memory)

}  // namespace

TurntableSequence turntable_sequence(int number) {
  // Pairs (2k−1, 2k): same fixed angle, opposite directions.
  static constexpr struct {
    bool inner_rotates;
    double fixed_deg;
  } kPairs[8] = {{true, 0.0},   {true, 180.0},  {false, 0.0},  {false, 180.0},
                 {false, 90.0}, {false, -90.0}, {false, 30.0}, {false, -30.0}};
  const int pair = (number - 1) / 2;
  TurntableSequence s;
  s.inner_rotates = kPairs[pair].inner_rotates;
  s.fixed_deg = kPairs[pair].fixed_deg;
  s.direction = (number % 2 == 1) ? 1.0 : -1.0;
  return s;
}

double wrap_deg(double angle_deg) {
  double a = std::fmod(angle_deg, 360.0);  // (−360, 360)
  if (a > 180.0) a -= 360.0;
  if (a <= -180.0) a += 360.0;
  return a;
}

Result<TurntableLog> simulate_turntable(const Calibration& unit, const TurntablePlan& plan,
                                        std::uint64_t seed) {
  return simulate_turntable(unit, plan, seed, GyroModelOptions{});
}

namespace {

Status check_plan(const TurntablePlan& plan, const GyroModelOptions& model) {
  if (!std::isfinite(plan.table_rate_dps) || plan.table_rate_dps <= 0.0) {
    return bad_input("turntable plan: table_rate_dps must be positive, got " +
                     number_text(plan.table_rate_dps));
  }
  if (!std::isfinite(plan.revolutions) || plan.revolutions <= 0.0) {
    return bad_input("turntable plan: revolutions must be positive, got " + number_text(plan.revolutions));
  }
  if (!std::isfinite(plan.rate_hz) || plan.rate_hz <= 0.0) {
    return bad_input("turntable plan: rate_hz must be positive, got " + number_text(plan.rate_hz));
  }
  if (!std::isfinite(plan.latitude_deg) || std::abs(plan.latitude_deg) > 90.0) {
    return bad_input("turntable plan: latitude_deg must be in [-90, 90], got " +
                     number_text(plan.latitude_deg));
  }
  if (!(model.bias_instability_correlation_s > 0.0)) {
    return bad_input("gyro model: bias_instability_correlation_s must be positive");
  }
  return ok_status();
}

// The plan's sequence numbers (1..16 when it names none), each at most once.
Result<std::vector<int>> sequence_order(const TurntablePlan& plan) {
  std::vector<int> order = plan.order;
  if (order.empty()) {
    for (int i = 1; i <= 16; ++i) order.push_back(i);
  }
  bool seen[17] = {};
  for (int number : order) {
    if (number < 1 || number > 16) {
      return bad_input("turntable plan: order: sequence " + std::to_string(number) + " is not in 1..16");
    }
    if (seen[number]) {
      return bad_input("turntable plan: order: sequence " + std::to_string(number) + " appears twice");
    }
    seen[number] = true;
  }
  return order;
}

Result<std::size_t> samples_per_sequence(const TurntablePlan& plan, std::size_t sequences) {
  const double seconds_per_sequence = plan.revolutions * 360.0 / plan.table_rate_dps;
  const double samples_exact = seconds_per_sequence * plan.rate_hz;
  if (samples_exact < 2.0 || samples_exact * static_cast<double>(sequences) > static_cast<double>(kMaxRows)) {
    return bad_input("turntable plan: " + number_text(samples_exact) +
                     " samples per sequence; need at least 2 and at most " + std::to_string(kMaxRows) +
                     " rows in all");
  }
  return static_cast<std::size_t>(std::llround(samples_exact));
}

// The log's metadata, its columns reserved for `rows` rows.
TurntableLog empty_log(const Calibration& unit, const TurntablePlan& plan, std::uint64_t seed,
                       std::size_t rows) {
  TurntableLog log;
  log.source = "simulated turntable";
  log.gyro_count = unit.gyro_count();
  log.metadata = {{"latitude_deg", number_text(plan.latitude_deg)},
                  {"generator", "tetra sim turntable"},
                  {"unit", metadata_token(unit.unit)},
                  {"seed", std::to_string(seed)},
                  {"table_rate_dps", number_text(plan.table_rate_dps)},
                  {"revolutions", number_text(plan.revolutions)},
                  {"rate_hz", number_text(plan.rate_hz)},
                  {"encoder_angles", plan.wrap_angles ? "wrapped" : "unwrapped"}};
  log.sequence.reserve(rows);
  log.time_s.reserve(rows);
  log.inner_deg.reserve(rows);
  log.outer_deg.reserve(rows);
  log.g_V.reserve(rows * static_cast<std::size_t>(log.gyro_count));
  return log;
}

// Sequence `number`: `samples` rows from row `first_row` on, each gyro sampling the table's and the
// Earth's rate.
void append_sequence(TurntableLog& log, int number, std::size_t samples, std::size_t first_row,
                     const TurntablePlan& plan, std::vector<GyroChannel>& channels) {
  const TurntableSequence seq = turntable_sequence(number);
  const double gimbal_rate_dps = seq.direction * plan.table_rate_dps;
  const double latitude_rad = plan.latitude_deg * kDegToRad;
  for (std::size_t k = 0; k < samples; ++k) {
    const double t_s = static_cast<double>(first_row + k) / plan.rate_hz;
    // "+ 0.0" turns −0 into +0 so the file never shows "-0".
    const double turning_deg = gimbal_rate_dps * static_cast<double>(k) / plan.rate_hz + 0.0;
    const double inner_deg = seq.inner_rotates ? turning_deg : seq.fixed_deg;
    const double outer_deg = seq.inner_rotates ? seq.fixed_deg : turning_deg;
    const double inner_rad = inner_deg * kDegToRad;
    const double outer_rad = outer_deg * kDegToRad;
    const double inner_dot = seq.inner_rotates ? gimbal_rate_dps * kDegToRad : 0.0;
    const double outer_dot = seq.inner_rotates ? 0.0 : gimbal_rate_dps * kDegToRad;
    const Eigen::Vector3d omega_BN_B_rad_s = turntable_rate_B(inner_rad, inner_dot, outer_dot) +
                                             turntable_earth_rate_B(inner_rad, outer_rad, latitude_rad);
    const Eigen::Vector3d omega_B_dps = omega_BN_B_rad_s * kRadToDeg;

    log.sequence.push_back(number);
    log.time_s.push_back(t_s);
    log.inner_deg.push_back(plan.wrap_angles ? wrap_deg(inner_deg) : inner_deg);
    log.outer_deg.push_back(plan.wrap_angles ? wrap_deg(outer_deg) : outer_deg);
    for (auto& channel : channels) log.g_V.push_back(channel.sample_V(omega_B_dps, t_s));
  }
}

}  // namespace

Result<TurntableLog> simulate_turntable(const Calibration& unit, const TurntablePlan& plan,
                                        std::uint64_t seed, const GyroModelOptions& model) {
  if (Status st = validate_calibration(unit, "unit"); !st) return st.error();
  if (Status st = check_plan(plan, model); !st) return st.error();
  const auto order = sequence_order(plan);
  if (!order) return order.error();
  const auto samples = samples_per_sequence(plan, order->size());
  if (!samples) return samples.error();

  const double dt_s = 1.0 / plan.rate_hz;
  std::vector<GyroChannel> channels;
  channels.reserve(static_cast<std::size_t>(unit.gyro_count()));
  for (int i = 0; i < unit.gyro_count(); ++i) {
    channels.emplace_back(unit.gyros[static_cast<std::size_t>(i)], model, dt_s, seed, i);
  }
  TurntableLog log = empty_log(unit, plan, seed, *samples * order->size());
  for (std::size_t s = 0; s < order->size(); ++s) {
    append_sequence(log, (*order)[s], *samples, s * *samples, plan, channels);
  }
  return log;
}

}  // namespace tetra::sim
