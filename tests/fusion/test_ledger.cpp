// The hypothesis ledger and the arbiter (docs/fdi.md, "The ledger and the arbiter"): the one helper that
// fills a row, the source table, the single rule over crafted rows (each condition of the rule removed in
// turn must change the ruling), the rows in JSON, and the whole event — detail and rows — through the DDS
// type and back, nothing cut.

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "tetra/dds/convert.hpp"
#include "tetra/fdi/ledger.hpp"
#include "tetra/fdi/types.hpp"

namespace tetra::fdi {
namespace {

std::uint8_t h(int i) {
  return static_cast<std::uint8_t>(i);
}

TEST(Ledger, TheHelperJudgesAStatisticAgainstItsThresholds) {
  EXPECT_EQ(judge(EvidenceSource::kGlt, h(1), 3.0, 2.0, 9.0, 1).verdict, RowVerdict::kNoCall);
  EXPECT_EQ(judge(EvidenceSource::kGlt, h(1), 2.0, 2.0, 9.0, 1).verdict, RowVerdict::kConsistent);
  EXPECT_EQ(judge(EvidenceSource::kGlt, h(1), 9.5, 2.0, 9.0, 1).verdict, RowVerdict::kRejected);
  EXPECT_EQ(judge(EvidenceSource::kGlt, h(1), std::nan(""), 2.0, 9.0, 1).verdict, RowVerdict::kNoCall);
  const LedgerRow r = judge(EvidenceSource::kChi2, kHypothesisNone, 30.0, 16.27, 16.27, 3);
  EXPECT_EQ(r.verdict, RowVerdict::kRejected);
  EXPECT_EQ(r.dof, 3);
}

TEST(Ledger, OneTableNamesEverySourceWithItsUnit) {
  for (int i = 0; i < kEvidenceSourceCount; ++i) {
    const auto& s = kEvidenceSources[i];
    EXPECT_EQ(static_cast<int>(s.source), i) << s.name;  // the table is in the enum's order
    EvidenceSource back{};
    ASSERT_TRUE(evidence_source_from_string(s.name, back)) << s.name;
    EXPECT_EQ(back, s.source);
    EXPECT_NE(std::string(s.tests), "");
  }
  EvidenceSource none{};
  EXPECT_FALSE(evidence_source_from_string("lone_gyro_below_half", none));
  for (std::uint8_t hyp :
       {std::uint8_t{0}, std::uint8_t{1}, std::uint8_t{16}, std::uint8_t{32}, kHypothesisReference}) {
    std::uint8_t back = 99;
    ASSERT_TRUE(hypothesis_from_string(hypothesis_name(hyp), back)) << hypothesis_name(hyp);
    EXPECT_EQ(back, hyp);
  }
  std::uint8_t x = 0;
  EXPECT_FALSE(hypothesis_from_string("H33", x));
  EXPECT_FALSE(hypothesis_from_string("H01", x));
  EXPECT_FALSE(hypothesis_from_string("Hx", x));
}

//! An onset test's rows on four gyros where gyro 2 alone explains the data.
std::vector<LedgerRow> gyro_two_alone() {
  const auto src = EvidenceSource::kOnset;
  return {stated(src, kHypothesisNone, RowVerdict::kRejected, 3.1, 1.0),
          stated(src, kHypothesisReference, RowVerdict::kRejected, 3.1, 1.0),
          stated(src, h(1), RowVerdict::kRejected, 2.9, 1.0),
          stated(src, h(2), RowVerdict::kConsistent, 0.4, 1.0),
          stated(src, h(3), RowVerdict::kRejected, 2.5, 1.0),
          stated(src, h(4), RowVerdict::kRejected, 2.7, 1.0)};
}

int rule(const std::vector<LedgerRow>& rows, std::uint32_t active = 0xF, bool reference = true) {
  return arbitrate(rows.data(), rows.data() + rows.size(), active, reference);
}

TEST(Arbiter, ExcludesOnlyTheHypothesisThatStandsAloneAndSaysNoOtherwise) {
  auto rows = gyro_two_alone();
  EXPECT_EQ(rule(rows), 2);
  // A competing hypothesis the data cannot judge: no exclusion.
  rows[4].verdict = RowVerdict::kNoCall;
  EXPECT_EQ(rule(rows), 0);
  // Two hypotheses consistent: no exclusion.
  rows = gyro_two_alone();
  rows[4].verdict = RowVerdict::kConsistent;
  EXPECT_EQ(rule(rows), 0);
  // The standing hypothesis rejected by another source: no exclusion.
  rows = gyro_two_alone();
  rows.push_back(stated(EvidenceSource::kGlt, h(2), RowVerdict::kRejected, 40.0, 9.0));
  EXPECT_EQ(rule(rows), 0);
  // No fault shown (H0 not rejected): no exclusion.
  rows = gyro_two_alone();
  rows[0].verdict = RowVerdict::kConsistent;
  EXPECT_EQ(rule(rows), 0);
  // A reference exists and nothing rejects it being the wrong one: no exclusion; without one, gyro 2.
  rows = gyro_two_alone();
  rows.erase(rows.begin() + 1);
  EXPECT_EQ(rule(rows, 0xF, true), 0);
  EXPECT_EQ(rule(rows, 0xF, false), 2);
  // Gyros out of the set in use do not compete; one in use without any row does.
  rows = gyro_two_alone();
  EXPECT_EQ(rule(rows, 0x7), 2);
  EXPECT_EQ(rule(rows, 0x1F), 0);
}

//! A reference sample's rows with four gyros vouching (the parity rejects each Hi) and a mean that a common
//! drift may explain: H0 rejected, Href consistent, Hdrift consistent, H1..H4 rejected.
std::vector<LedgerRow> a_mean_the_gyros_vouch_for() {
  const auto src = EvidenceSource::kReferenceTest;
  std::vector<LedgerRow> rows = {
      judge(src, kHypothesisNone, 60.0, 44.9, 44.9, 3),
      stated(src, kHypothesisReference, RowVerdict::kConsistent, 60.0, 44.9, 3),
      stated(EvidenceSource::kDriftWander, kHypothesisDrift, RowVerdict::kConsistent, 120.0, 1e4)};
  for (int i = 1; i <= 4; ++i)
    rows.push_back(stated(EvidenceSource::kCusum, h(i), RowVerdict::kRejected, 2.0, 20.0));
  return rows;
}

ReferenceDecision reference_rule(const std::vector<LedgerRow>& rows, std::uint32_t active = 0xF) {
  return arbitrate_reference(rows.data(), rows.data() + rows.size(), active);
}

TEST(Arbiter, TheReferenceIsRejectedOnlyWhenItsHypothesisStandsAlone) {
  auto rows = a_mean_the_gyros_vouch_for();
  // Hdrift and Href both stand: the drift is matched (the step that keeps the reference).
  EXPECT_EQ(reference_rule(rows), ReferenceDecision::kMatchDrift);
  // Hdrift rejected (a working unit's drift could not be that large): the reference is rejected.
  rows[2].verdict = RowVerdict::kRejected;
  EXPECT_EQ(reference_rule(rows), ReferenceDecision::kReject);
  // ...but not while a gyro's hypothesis is not rejected (an open episode, a parity that cannot vouch).
  rows[4].verdict = RowVerdict::kNoCall;
  EXPECT_EQ(reference_rule(rows), ReferenceDecision::kNoCall);
  // A gyro out of the set in use does not compete; one in use without a row does.
  EXPECT_EQ(reference_rule(rows, 0xD), ReferenceDecision::kReject);
  EXPECT_EQ(reference_rule(rows, 0x1D), ReferenceDecision::kNoCall);
  // Hdrift with no call (the gyros cannot vouch): neither rejected nor matched.
  rows = a_mean_the_gyros_vouch_for();
  rows[2].verdict = RowVerdict::kNoCall;
  EXPECT_EQ(reference_rule(rows), ReferenceDecision::kNoCall);
  // H0 not rejected: the sample is used, whatever else the rows say.
  rows = a_mean_the_gyros_vouch_for();
  rows[0].verdict = RowVerdict::kConsistent;
  EXPECT_EQ(reference_rule(rows), ReferenceDecision::kUse);
  // Href rejected too (nothing explains the failure): no call.
  rows = a_mean_the_gyros_vouch_for();
  rows[2].verdict = RowVerdict::kRejected;
  rows[1].verdict = RowVerdict::kRejected;
  EXPECT_EQ(reference_rule(rows), ReferenceDecision::kNoCall);
  // Hcal standing (a calibration mismatch named): the gyros' own error explains the disagreement, no call;
  // an Hcal row that does not stand changes nothing.
  rows = a_mean_the_gyros_vouch_for();
  rows[2].verdict = RowVerdict::kRejected;
  rows.push_back(
      stated(EvidenceSource::kMotionFit, kHypothesisCalibration, RowVerdict::kConsistent, 90.0, 30.7, 3));
  EXPECT_EQ(reference_rule(rows), ReferenceDecision::kNoCall);
  rows.back().verdict = RowVerdict::kNoCall;
  EXPECT_EQ(reference_rule(rows), ReferenceDecision::kReject);
  EXPECT_STREQ(to_string(ReferenceDecision::kMatchDrift), "match drift");
  std::uint8_t back = 0;
  ASSERT_TRUE(hypothesis_from_string(hypothesis_name(kHypothesisDrift), back));
  EXPECT_EQ(back, kHypothesisDrift);
  EXPECT_EQ(hypothesis_name(kHypothesisDrift), "Hdrift");
}

// Hcal, the calibration that does not describe the unit: a standing Hcal withholds an exclusion the other
// rows make (the parity's evidence is the calibration's error as well), and a block of the motion fit names
// the mismatch only when H0 and every gyro's own error are rejected.
TEST(Arbiter, AStandingCalibrationHypothesisWithholdsTheExclusionAndIsNamedAlone) {
  auto rows = gyro_two_alone();
  ASSERT_EQ(rule(rows), 2);
  rows.push_back(
      stated(EvidenceSource::kMotionFit, kHypothesisCalibration, RowVerdict::kConsistent, 90.0, 30.7, 3));
  EXPECT_EQ(rule(rows), 0);
  rows.back().verdict = RowVerdict::kNoCall;  // Hcal not judged: the other rows decide
  EXPECT_EQ(rule(rows), 2);
  rows.back().verdict = RowVerdict::kRejected;
  EXPECT_EQ(rule(rows), 2);

  std::vector<LedgerRow> block = {judge(EvidenceSource::kMotionFit, kHypothesisNone, 90.0, 30.7, 30.7, 3)};
  for (std::uint8_t i = 1; i <= 4; ++i)
    block.push_back(judge(EvidenceSource::kMotionFit, i, 60.0, 27.6, 27.6, 2));
  block.push_back(
      stated(EvidenceSource::kMotionFit, kHypothesisCalibration, RowVerdict::kConsistent, 90.0, 30.7, 3));
  const auto named = [&block](std::uint32_t active) {
    return arbitrate_calibration(block.data(), block.data() + block.size(), active);
  };
  EXPECT_TRUE(named(0xF));
  EXPECT_FALSE(named(0x1F));  // gyro 5 in use without a row: its hypothesis stands
  block[3] = judge(EvidenceSource::kMotionFit, 3, 10.0, 27.6, 27.6, 2);  // gyro 3 alone explains the fit
  EXPECT_FALSE(named(0xF));
  EXPECT_TRUE(named(0xB));  // ...unless gyro 3 is out of the set
  block[0] = judge(EvidenceSource::kMotionFit, kHypothesisNone, 12.0, 30.7, 30.7, 3);  // no fit beyond noise
  EXPECT_FALSE(named(0xB));
  std::uint8_t back = 0;
  ASSERT_TRUE(hypothesis_from_string("Hcal", back));
  EXPECT_EQ(back, kHypothesisCalibration);
  EXPECT_EQ(hypothesis_name(kHypothesisCalibration), "Hcal");
  EXPECT_TRUE(reads_own_signal(EvidenceSource::kRepeated));
  EXPECT_FALSE(reads_own_signal(EvidenceSource::kGlt));
}

TEST(Ledger, DecisionEventsCarryTheirRowsInJsonAndTheRuleRebuildsTheIsolation) {
  FdiEvent e;
  e.type = EventType::kIsolated;
  e.gyro = 2;
  e.evidence = Evidence::kOnset;
  e.ledger = gyro_two_alone();
  EXPECT_EQ(ruling_of(e), 2);
  const std::string json = to_json(e, 4);
  EXPECT_NE(
      json.find("\"ledger\": [{\"source\": \"onset\", \"hypothesis\": \"H0\", \"statistic\": 3.1, \"unit\": "
                "\"motion bound\", \"threshold\": 1, \"verdict\": \"rejected\"}"),
      std::string::npos)
      << json;
  EXPECT_NE(
      json.find("{\"source\": \"onset\", \"hypothesis\": \"H2\", \"statistic\": 0.4, \"unit\": \"motion "
                "bound\", \"threshold\": 1, \"verdict\": \"consistent\"}"),
      std::string::npos)
      << json;
  const LedgerRow glt = judge(EvidenceSource::kGlt, h(3), 5.0, 2.0, 9.0, 1);
  std::string one;
  append_json(one, glt);
  EXPECT_EQ(one,
            "{\"source\": \"glt\", \"hypothesis\": \"H3\", \"statistic\": 5, \"unit\": \"chi2\", \"dof\": 1, "
            "\"threshold\": 9, \"accept\": 2, \"verdict\": \"no call\"}");
}

TEST(Ledger, AnEventCrossesTheWireWholeItsDetailAndEveryRow) {
  dds::EventView view;
  view.unit = "unit one";
  view.event_seq = 7;
  view.event.type = EventType::kIsolated;
  view.event.gyro = 2;
  view.event.ledger = gyro_two_alone();
  // The pipeline's longest texts are about 320 bytes; 127 used to be the wire's bound.
  view.event.detail = std::string(600, 'd');
  dds::WireEvent wire;
  ASSERT_TRUE(dds::to_wire(view, wire).ok());
  const dds::EventView back = dds::from_wire(wire.msg);
  EXPECT_EQ(back.event.detail, view.event.detail);
  EXPECT_EQ(back.event.ledger, view.event.ledger);
  EXPECT_EQ(wire.msg.ledger_dropped, 0);
  EXPECT_EQ(ruling_of(back.event), 2);
  // Beyond the bound the text says so: never cut silently.
  view.event.detail = std::string(1500, 'x');
  ASSERT_TRUE(dds::to_wire(view, wire).ok());
  const std::string cut = dds::from_wire(wire.msg).event.detail;
  EXPECT_EQ(cut.size(), 1023U);
  EXPECT_NE(cut.find("[cut: "), std::string::npos) << cut.substr(cut.size() - 40);
  EXPECT_EQ(cut.substr(cut.size() - 15), "bytes not sent]");
  // More rows than the wire holds: the count of those not carried travels with them.
  view.event.ledger.assign(45, gyro_two_alone()[0]);
  ASSERT_TRUE(dds::to_wire(view, wire).ok());
  EXPECT_EQ(wire.msg.ledger._length, 40U);
  EXPECT_EQ(wire.msg.ledger_dropped, 5);
}

}  // namespace
}  // namespace tetra::fdi
