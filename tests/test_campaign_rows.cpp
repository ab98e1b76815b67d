// A campaign's rows checked against its spec's matrix (sim::check_campaign_row), as `campaign merge` and a
// resumed campaign read them: the case columns must be the run's case, and a finished run's results must
// be consistent with it (gyros of its unit, the outcome its detections and isolations imply, times within
// the run, the columns of its kind and loop). Each refusal names the field and why.

#include <gtest/gtest.h>

#include <limits>
#include <string>

#include "tetra/sim/campaign.hpp"

namespace tetra::sim {
namespace {

// Open loop, the built-in orbit (4 gyros), 30 s: a fault-free run (run 0), then bias 0.5 deg/s on gyro 1
// and 2 at 10 s (runs 1 and 2).
CampaignSpec small_spec() {
  auto spec = parse_campaign_spec(
      "loop: open\nscenarios: [orbit]\nduration_s: 30\nkinds: [bias]\nsizes: {bias: [0.5]}\n"
      "gyros: [1, 2]\nonsets_s: [10]\nseeds: [1]\nfault_free: true\n",
      "c.yaml", ".");
  EXPECT_TRUE(spec) << spec.error().message;
  return *spec;
}

// A consistent result for run 1 (bias on gyro 1 at 10 s): detected after 1 s, gyro 1 isolated after 2 s.
CampaignRow right_row(const CampaignSpec& spec) {
  CampaignRow row = campaign_error_row(spec, 1, "-");
  row.error.clear();
  row.fdi.outcome = Outcome::kRight;
  row.fdi.detection_delay_s = 1.0;
  row.fdi.isolation_delay_s = 2.0;
  row.fdi.isolated_gyro = 1;
  row.fdi.fault_free_s = 10.0;
  row.theory_delay_s = 0.5;
  row.final_knowledge_error_deg = 0.01;
  row.final_sigma_deg = 0.02;
  for (double* v : {&row.pointing_max_before_deg, &row.pointing_rms_after_deg, &row.pointing_max_after_deg,
                    &row.bound_deg, &row.max_wheel_momentum_fraction})
    *v = std::numeric_limits<double>::quiet_NaN();
  return row;
}

std::string refusal(const CampaignSpec& spec, const CampaignRow& row) {
  const Status st = check_campaign_row(spec, row);
  return st ? std::string("accepted") : st.error().message;
}

TEST(CampaignRows, ARealRowAndItsWrittenFormAreAccepted) {
  const CampaignSpec spec = small_spec();
  for (std::size_t run = 0; run < 3; ++run) {
    const CampaignRow row = campaign_run_row(spec, run, in_process_estimators(spec));
    ASSERT_TRUE(row.error.empty()) << row.error;
    EXPECT_EQ(refusal(spec, row), "accepted") << run;
    auto back = parse_campaign_row(campaign_csv_row(row), campaign_csv_header(spec));
    ASSERT_TRUE(back) << back.error().message;
    EXPECT_EQ(refusal(spec, *back), "accepted") << campaign_csv_row(row);
  }
  EXPECT_EQ(refusal(spec, right_row(spec)), "accepted");
  EXPECT_EQ(refusal(spec, campaign_error_row(spec, 2, "worker killed")), "accepted");
}

TEST(CampaignRows, CaseColumnsMustBeTheRunsCase) {
  const CampaignSpec spec = small_spec();
  CampaignRow row = right_row(spec);
  row.run = 3;
  EXPECT_EQ(refusal(spec, row), "campaign row: run '3' (the campaign has runs 0 to 2)");
  row = right_row(spec);
  row.kind = "stuck";
  EXPECT_EQ(refusal(spec, row), "campaign row: kind 'stuck' (run 1 of the spec's matrix has bias)");
  row = right_row(spec);
  row.gyro = 2;
  EXPECT_EQ(refusal(spec, row), "campaign row: gyro '2' (run 1 of the spec's matrix has gyro 1)");
  row = right_row(spec);
  row.size = 0.7;
  EXPECT_EQ(refusal(spec, row), "campaign row: size '0.7' (run 1 of the spec's matrix has size 0.5)");
  row = right_row(spec);
  row.onset_s = 11;
  EXPECT_EQ(refusal(spec, row), "campaign row: onset_s '11' (run 1 of the spec's matrix has onset 10)");
  row = right_row(spec);
  row.seed = 9;
  EXPECT_EQ(refusal(spec, row), "campaign row: seed '9' (run 1 of the spec's matrix has seed 1)");
  row = right_row(spec);
  row.scenario = "other";
  EXPECT_EQ(refusal(spec, row), "campaign row: scenario 'other' (run 1 of the spec's matrix has orbit)");
  CampaignRow error = campaign_error_row(spec, 2, "worker killed");
  error.gyro = 1;  // an error row's case too
  EXPECT_EQ(refusal(spec, error), "campaign row: gyro '1' (run 2 of the spec's matrix has gyro 2)");
}

TEST(CampaignRows, ResultsMustBeConsistentWithTheCase) {
  const CampaignSpec spec = small_spec();
  const auto with = [&](auto change) {
    CampaignRow row = right_row(spec);
    change(row);
    return refusal(spec, row);
  };
  EXPECT_EQ(with([](CampaignRow& r) { r.fdi.isolated_gyro = 5; }),
            "campaign row: isolated_gyro '5' (a gyro 1..4 of the scenario's unit)");
  EXPECT_EQ(with([](CampaignRow& r) { r.fdi.isolated_gyro = 2; }),
            "campaign row: outcome 'right' with isolated_gyro '2' (the faulty gyro is 1)");
  EXPECT_EQ(with([](CampaignRow& r) { r.fdi.isolation_delay_s.reset(); }),
            "campaign row: isolation_delay_s (given with isolated_gyro, and only with it)");
  EXPECT_EQ(with([](CampaignRow& r) {
              r.fdi.wrong_gyro = 1;
              r.fdi.wrong_at_s = 12;
            }),
            "campaign row: wrong_gyro '1' (the faulty gyro)");
  EXPECT_EQ(with([](CampaignRow& r) { r.fdi.outcome = Outcome::kWrong; }),
            "campaign row: outcome 'wrong' with wrong_gyro ''");
  EXPECT_EQ(with([](CampaignRow& r) { r.fdi.outcome = Outcome::kNone; }),
            "campaign row: outcome 'none' (a run with a fault is right, wrong, unisolated or missed)");
  EXPECT_EQ(with([](CampaignRow& r) { r.fdi.outcome = Outcome::kMissed; }),
            "campaign row: outcome 'missed' (neither detected nor isolated: no detection_delay_s and no "
            "isolated_gyro)");
  EXPECT_EQ(
      with([](CampaignRow& r) { r.fdi.detection_delay_s = 1e9; }),
      "campaign row: detection_delay_s '1e+09' (after the onset at 10 s: beyond the run's end at 30 s)");
  EXPECT_EQ(with([](CampaignRow& r) { r.fdi.fault_free_s = 1e6; }),
            "campaign row: fault_free_s '1e+06' (beyond the run's end at 30 s)");
  EXPECT_EQ(with([](CampaignRow& r) { r.pointing_max_after_deg = 0.1; }),
            "campaign row: pointing_max_after_deg '0.1' (an open-loop run has no pointing)");
  CampaignRow fault_free = campaign_error_row(spec, 0, "-");
  fault_free.error.clear();
  fault_free.fdi.outcome = Outcome::kMissed;
  fault_free.fdi.fault_free_s = 30;
  EXPECT_EQ(refusal(spec, fault_free),
            "campaign row: outcome 'missed' (a run without a fault is none or wrong)");
  fault_free.fdi.outcome = Outcome::kNone;
  fault_free.theory_delay_s = 3;
  EXPECT_EQ(refusal(spec, fault_free), "campaign row: theory_delay_s '3' (for bias faults only)");
}

}  // namespace
}  // namespace tetra::sim
