// Temporary exploration driver (not part of the suite).
#include <cstdio>
#include "synth.hpp"
#include "tetra/fdi/pipeline.hpp"
using namespace tetra;
int main(int argc, char** argv) {
  const int kind = argc > 1 ? std::atoi(argv[1]) : 0;
  const int gyro = argc > 2 ? std::atoi(argv[2]) : 1;
  const double size = argc > 3 ? std::atof(argv[3]) : 0.0;
  const double dur = argc > 4 ? std::atof(argv[4]) : 200.0;
  const double refp = argc > 5 ? std::atof(argv[5]) : 0.0;
  const int zero = argc > 6 ? std::atoi(argv[6]) : 0;
  auto cal = seed_as_built_unit();
  fdi::PipelineConfig cfg;
  cfg.max_angular_acceleration_dps2 = 2e-4;
  auto p = fdi::Pipeline::create(cal, cfg);
  if (!p) {
    std::puts(p.error().message.c_str());
    return 1;
  }
  test::SynthOptions o;
  o.reference_period_s = refp;
  o.seed = 7;
  test::SynthFault f;
  f.gyro = kind ? gyro : 0;
  f.kind = static_cast<fdi::FaultKind>(kind);
  f.at_s = 100.0;
  f.size = size;
  f.zero = zero;
  test::Synth s(cal, o, f);
  const int n = static_cast<int>(dur / 0.1);
  double max_err = 0;
  for (int k = 0; k < n; ++k) {
    const auto& r = p->step(s.next());
    for (const auto& e : r.events) std::printf("%s\n", fdi::to_json(e, 4).c_str());
    max_err = std::max(max_err, angle_between(r.attitude.q_RB, s.truth_q()));
    if (k == n - 1)
      std::printf(
          "final mode %s gyros %s err %.3g deg sigma %.3g deg maxerr %.3g chi2 %.3g cusum %.3g h %.3g\n",
          fdi::to_string(r.attitude.mode), mask_to_string(r.attitude.gyros, 4).c_str(),
          angle_between(r.attitude.q_RB, s.truth_q()) * kRadToDeg, r.attitude.sigma_rad.norm() * kRadToDeg,
          max_err * kRadToDeg, p->health().chi2, p->health().cusum, p->health().cusum_threshold);
  }
  std::printf("%s", p->describe_thresholds().c_str());
  const auto& c = p->health().counters;
  std::printf("outliers %llu spikes %llu\n", (unsigned long long)c.samples_outlier,
              (unsigned long long)c.spikes);
}
