// libFuzzer target: the fusion pipeline (fdi::Pipeline) fed arbitrary epochs and operator commands —
// what `tetra fusion` receives from the wire and `tetra replay` from a file. The bytes choose the
// number of gyros (3..6), a few configuration switches, then a stream of operations: an epoch (time
// step; per gyro a plausible sample, an absent one, any double, or NaN/±inf/huge; an optional
// reference quaternion of any four doubles), exclude/reinstate of any gyro id, a reset command or a
// reset(). Properties after every operation:
//   * Health describes N gyros; the counters never decrease (except across reset());
//   * an accepted epoch's attitude is a finite unit quaternion, its rate and σ are not NaN;
//   * an epoch whose time does not increase is rejected;
//   * every event names a gyro in 1..N or none, and its gyro sets stay within the N gyros.
#include <fuzzer/FuzzedDataProvider.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>

#include "fuzz_check.hpp"
#include "tetra/core/calibration_file.hpp"
#include "tetra/fdi/pipeline.hpp"

namespace {

using tetra::fdi::Epoch;
using tetra::fdi::Pipeline;

tetra::Calibration unit_with(int n) {
  tetra::Calibration cal = tetra::seed_as_built_unit();
  cal.gyros.resize(static_cast<std::size_t>(std::min(n, 4)));
  const Eigen::Vector3d extra[] = {Eigen::Vector3d(0.0, 1.0, 1.0).normalized(),
                                   Eigen::Vector3d(0.0, 1.0, -1.0).normalized()};
  for (int i = 4; i < n; ++i) {
    tetra::GyroCalibration g = cal.gyros[0];
    g.id = i + 1;
    g.axis_B = extra[i - 4];
    cal.gyros.push_back(g);
  }
  return cal;
}

double any_double(FuzzedDataProvider& in) {
  switch (in.ConsumeIntegralInRange<int>(0, 5)) {
    case 0:
      return std::numeric_limits<double>::quiet_NaN();
    case 1:
      return std::numeric_limits<double>::infinity();
    case 2:
      return -std::numeric_limits<double>::infinity();
    case 3:
      return in.ConsumeBool() ? 1e300 : -1e-300;
    default:
      return in.ConsumeFloatingPoint<double>();
  }
}

bool counters_not_less(const tetra::fdi::Counters& now, const tetra::fdi::Counters& before) {
  return now.epochs_accepted >= before.epochs_accepted &&
         now.epochs_rejected_time >= before.epochs_rejected_time &&
         now.epochs_time_outlier >= before.epochs_time_outlier &&
         now.samples_accepted >= before.samples_accepted && now.samples_invalid >= before.samples_invalid &&
         now.samples_absent >= before.samples_absent;
}

//! Events of epochs name gyros 1..N; a command's acknowledgement may name the (bad) gyro it was given.
void check_event(const tetra::fdi::FdiEvent& e, int n) {
  if (e.gyro && e.type != tetra::fdi::EventType::kCommand) TETRA_FUZZ_CHECK(*e.gyro >= 1 && *e.gyro <= n);
  TETRA_FUZZ_CHECK((e.gyros >> n) == 0);
  (void)tetra::fdi::to_json(e, n);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  FuzzedDataProvider in(data, size);
  const int n = in.ConsumeIntegralInRange<int>(3, 6);
  const tetra::Calibration cal = unit_with(n);
  tetra::fdi::PipelineConfig config;
  const std::uint8_t switches = in.ConsumeIntegral<std::uint8_t>();
  config.raw_units_dps = (switches & 1) != 0;
  if ((switches & 2) != 0) config.latitude_deg = -23.2;
  config.sample_period_s = (switches & 4) != 0 ? 0.01 : 0.0;
  auto created = Pipeline::create(cal, config);
  TETRA_FUZZ_CHECK(created.ok());  // a valid unit and the default configuration
  Pipeline& pipeline = created.value();
  TETRA_FUZZ_CHECK(pipeline.gyro_count() == n);

  Epoch epoch;
  epoch.raw.assign(static_cast<std::size_t>(n), 0.0);
  epoch.present.assign(static_cast<std::size_t>(n), 1);
  std::int64_t stamp_ns = 0;
  std::int64_t last_accepted_ns = std::numeric_limits<std::int64_t>::min();
  for (int op = 0; op < 4000 && in.remaining_bytes() > 0; ++op) {
    const std::uint8_t kind = in.ConsumeIntegral<std::uint8_t>();
    if (kind < 240) {
      // Time step: mostly the nominal 10 ms, sometimes anything (zero, backwards, huge).
      const std::uint8_t dt_kind = in.ConsumeIntegral<std::uint8_t>();
      std::int64_t dt_ns = 10'000'000;
      if (dt_kind >= 224) dt_ns = in.ConsumeIntegralInRange<std::int64_t>(-2'000'000'000, 2'000'000'000);
      if (dt_kind == 255) dt_ns = in.ConsumeIntegral<std::int64_t>() / 4;
      std::int64_t next_ns = 0;
      if (!__builtin_add_overflow(stamp_ns, dt_ns, &next_ns)) stamp_ns = next_ns;  // else: time stands still
      epoch.stamp_ns = stamp_ns;
      const tetra::fdi::Counters before = pipeline.health().counters;
      for (int i = 0; i < n; ++i) {
        const auto& g = cal.gyros[static_cast<std::size_t>(i)];
        const std::uint8_t s = in.ConsumeIntegral<std::uint8_t>();
        auto& raw = epoch.raw[static_cast<std::size_t>(i)];
        epoch.present[static_cast<std::size_t>(i)] = 1;
        if (s < 200) {  // plausible: bias plus a small rate (±0.0127 deg/s)
          const double rate_dps = static_cast<double>(in.ConsumeIntegral<std::int8_t>()) * 1e-4;
          raw = config.raw_units_dps ? rate_dps : g.bias_V + g.scale_factor_V_per_dps * rate_dps;
        } else if (s < 220) {
          epoch.present[static_cast<std::size_t>(i)] = 0;
          raw = std::numeric_limits<double>::quiet_NaN();
        } else {
          raw = any_double(in);
        }
      }
      epoch.reference_q_RB.reset();
      if (in.ConsumeIntegralInRange<int>(0, 15) == 0) {
        const double w = any_double(in), x = any_double(in), y = any_double(in), z = any_double(in);
        epoch.reference_q_RB = tetra::Quaternion(w, x, y, z);
      }
      const auto& result = pipeline.step(epoch);
      if (result.accepted) {
        TETRA_FUZZ_CHECK(epoch.stamp_ns > last_accepted_ns);
        last_accepted_ns = epoch.stamp_ns;
        const auto& q = result.attitude.q_RB;
        TETRA_FUZZ_CHECK(std::isfinite(q.w()) && std::isfinite(q.x()) && std::isfinite(q.y()) &&
                         std::isfinite(q.z()));
        TETRA_FUZZ_CHECK(std::abs(q.norm() - 1.0) < 1e-6);
        TETRA_FUZZ_CHECK(!result.attitude.omega_BR_B_rad_s.hasNaN());
        TETRA_FUZZ_CHECK(!result.attitude.sigma_rad.hasNaN());
        TETRA_FUZZ_CHECK((result.attitude.gyros >> n) == 0);
      }
      for (const auto& e : result.events) check_event(e, n);
      TETRA_FUZZ_CHECK(counters_not_less(pipeline.health().counters, before));
    } else {
      const int id = in.ConsumeIntegralInRange<int>(-1, n + 1);
      switch (kind % 4) {
        case 0:
          check_event(pipeline.exclude(id, stamp_ns), n);
          break;
        case 1:
          check_event(pipeline.reinstate(id, stamp_ns), n);
          break;
        case 2:
          check_event(pipeline.reset_command(stamp_ns), n);
          last_accepted_ns = std::numeric_limits<std::int64_t>::min();
          break;
        default:
          pipeline.reset();
          last_accepted_ns = std::numeric_limits<std::int64_t>::min();
          break;
      }
    }
    const auto& health = pipeline.health();
    TETRA_FUZZ_CHECK(health.gyros.size() == static_cast<std::size_t>(n));
    TETRA_FUZZ_CHECK((health.used >> n) == 0);
  }
  return 0;
}
