// Epoch assembler (services/fusion): alignment of asynchronous gyro streams, sequence checks,
// absence and restarts. Plain C++, no DDS. All times are exact integers: comparisons are exact.

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "tetra/core/units.hpp"
#include "tetra/service/epoch_assembler.hpp"

namespace tetra::service {
namespace {

constexpr std::int64_t kPeriod = 10'000'000;    // [ns] 100 Hz
constexpr std::int64_t kTolerance = 1'000'000;  // [ns]
constexpr std::int64_t kLatency = 20'000'000;   // [ns]
constexpr std::int64_t kWindow = 100'000'000;   // [ns] the default clock window

EpochAssembler make(int n = 4) {
  AssemblerConfig config;
  config.gyro_count = n;
  config.nominal_period_ns = kPeriod;
  config.tolerance_ns = kTolerance;
  config.max_latency_ns = kLatency;
  auto assembler = EpochAssembler::create(config);
  EXPECT_TRUE(assembler.ok());
  return std::move(assembler).value();
}

// Feeds all four gyros of epoch k (stamp k·period + jitter_i), sequence k+1, raw = gyro id + k/1000.
void feed_epoch(EpochAssembler& a, int k, std::int64_t now,
                std::array<std::int64_t, 4> jitter = {0, 0, 0, 0}) {
  for (int g = 1; g <= 4; ++g) {
    EXPECT_EQ(a.add_sample(g, static_cast<std::uint64_t>(k + 1),
                           k * kPeriod + jitter[static_cast<std::size_t>(g - 1)], g + k / 1000.0, now),
              Verdict::kAccepted);
  }
}

TEST(EpochAssembler, CompleteEpochIsEmittedAtOnceWithTheOpenersStamp) {
  auto a = make();
  // Jitter within the tolerance: one epoch, stamped with the first sample's stamp (gyro 1's, +300 ns).
  feed_epoch(a, 5, 0, {300, -200, 900, 0});
  std::vector<fdi::Epoch> out;
  a.poll(0, out);  // no time has passed: emitted because complete, not because of the latency limit
  ASSERT_EQ(out.size(), 1U);
  EXPECT_EQ(out[0].stamp_ns, 5 * kPeriod + 300);
  for (int g = 0; g < 4; ++g) {
    EXPECT_EQ(out[0].present[static_cast<std::size_t>(g)], 1);
    EXPECT_EQ(out[0].raw[static_cast<std::size_t>(g)], g + 1 + 0.005);  // bit-exact pass-through
  }
  EXPECT_FALSE(out[0].reference_q_RB.has_value());
  EXPECT_FALSE(a.next_due_ns().has_value());
}

// Lockstep play says how many samples an epoch has (promised): the epoch waits for all of them past the
// latency limit (a loaded machine delays one by 0.5 s: it was fused without that gyro, and every later
// attitude differed), and goes without a promised sample only once a gyro missing from it moved past it.
TEST(EpochAssembler, APromisedSampleIsWaitedForPastTheLatencyLimit) {
  auto a = make();
  constexpr std::int64_t kLate = 1000 + 25 * kLatency;  // [ns] local time: half a second later
  for (int g : {1, 2, 4}) EXPECT_EQ(a.add_sample(g, 1, 0, 1.0, 1000, false, 4), Verdict::kAccepted);
  std::vector<fdi::Epoch> out;
  a.poll(kLate, out);
  EXPECT_TRUE(out.empty()) << "fused without gyro 3, which was promised";
  EXPECT_FALSE(a.next_due_ns().has_value()) << "no timed wake-up: the sample's arrival decides";
  EXPECT_EQ(a.add_sample(3, 1, 0, 3.0, kLate, false, 4), Verdict::kAccepted);
  a.poll(kLate, out);
  ASSERT_EQ(out.size(), 1U);
  EXPECT_EQ(out[0].present, (std::vector<std::uint8_t>{1, 1, 1, 1}));
  // Three promised of gyros 1, 2, 4 (gyro 3 not in the log's epoch): complete with three, at once.
  for (int g : {1, 2, 4}) EXPECT_EQ(a.add_sample(g, 2, kPeriod, 1.0, kLate, false, 3), Verdict::kAccepted);
  a.poll(kLate, out);
  ASSERT_EQ(out.size(), 2U);
  // Four promised, gyro 3's lost: the next epoch's sample of gyro 3 releases it.
  for (int g : {1, 2, 4})
    EXPECT_EQ(a.add_sample(g, 3, 2 * kPeriod, 1.0, kLate, false, 4), Verdict::kAccepted);
  a.poll(kLate + 25 * kLatency, out);
  EXPECT_EQ(out.size(), 2U);
  EXPECT_EQ(a.add_sample(3, 3, 3 * kPeriod, 3.0, kLate + 25 * kLatency, false, 4), Verdict::kAccepted);
  a.poll(kLate + 25 * kLatency, out);
  ASSERT_EQ(out.size(), 3U);
  EXPECT_EQ(out[2].present, (std::vector<std::uint8_t>{1, 1, 0, 1}));
  EXPECT_EQ(a.counters().samples_promised_lost, 1U);
}

// Lockstep's reference: written before the samples that say so and promise the epoch's count, never
// acknowledged (an acknowledgement costs a heartbeat, 100 ms). The epoch waits for it past the latency limit
// (fused without it, the attitude would differ from replay's), and goes without it only once a gyro moves on.
TEST(EpochAssembler, APromisedEpochsReferenceIsWaitedForPastTheLatencyLimit) {
  auto a = make();
  const Quaternion q(0.5, 0.5, 0.5, 0.5);
  constexpr std::int64_t kLate = 1000 + 25 * kLatency;
  for (int g = 1; g <= 4; ++g) EXPECT_EQ(a.add_sample(g, 1, 0, 1.0, 1000, true, 4), Verdict::kAccepted);
  std::vector<fdi::Epoch> out;
  a.poll(kLate, out);
  EXPECT_TRUE(out.empty()) << "fused without the reference its samples said was written";
  a.add_reference(0, q);
  a.poll(kLate, out);
  ASSERT_EQ(out.size(), 1U);
  ASSERT_TRUE(out[0].reference_q_RB.has_value());
  // Its reference lost: the next epoch's first sample releases it, without one.
  for (int g = 1; g <= 4; ++g)
    EXPECT_EQ(a.add_sample(g, 2, kPeriod, 1.0, kLate, true, 4), Verdict::kAccepted);
  a.poll(kLate + 25 * kLatency, out);
  EXPECT_EQ(out.size(), 1U);
  EXPECT_EQ(a.add_sample(1, 3, 2 * kPeriod, 1.0, kLate + 25 * kLatency, false, 4), Verdict::kAccepted);
  a.poll(kLate + 25 * kLatency, out);
  ASSERT_EQ(out.size(), 2U);
  EXPECT_FALSE(out[1].reference_q_RB.has_value());
}

TEST(EpochAssembler, MissingSampleWaitsForTheLatencyLimitOnly) {
  auto a = make();
  for (int g : {1, 2, 4}) a.add_sample(g, 1, 0, 1.0, 1000);
  std::vector<fdi::Epoch> out;
  a.poll(1000 + kLatency - 1, out);  // 1 ns before the limit: still waiting for gyro 3
  EXPECT_TRUE(out.empty());
  ASSERT_TRUE(a.next_due_ns().has_value());
  EXPECT_EQ(*a.next_due_ns(), 1000 + kLatency);
  a.poll(1000 + kLatency, out);
  ASSERT_EQ(out.size(), 1U);
  EXPECT_EQ(out[0].present, (std::vector<std::uint8_t>{1, 1, 0, 1}));
  EXPECT_TRUE(std::isnan(out[0].raw[2]));
}

TEST(EpochAssembler, GyroThatMovedPastAnEpochDoesNotHoldItBack) {
  auto a = make();
  feed_epoch(a, 0, 0);
  for (int g : {1, 2, 4}) a.add_sample(g, 2, kPeriod, 1.0, 0);
  a.add_sample(3, 3, 2 * kPeriod, 1.0, 0);  // gyro 3 lost its sample of epoch 1 and delivered epoch 2
  std::vector<fdi::Epoch> out;
  a.poll(0, out);
  ASSERT_EQ(out.size(), 2U);  // epochs 0 and 1 out at once (gyro 3 absent in 1); epoch 2 still open
  EXPECT_EQ(out[1].stamp_ns, kPeriod);
  EXPECT_EQ(out[1].present, (std::vector<std::uint8_t>{1, 1, 0, 1}));
  EXPECT_EQ(a.counters().samples_gap, 1U);  // gyro 3 skipped sequence number 2
}

TEST(EpochAssembler, SequenceAndStampChecksAreCountedAndDropped) {
  auto a = make();
  feed_epoch(a, 0, 0);
  feed_epoch(a, 1, 0);
  EXPECT_EQ(a.add_sample(1, 2, 2 * kPeriod, 0.0, 0), Verdict::kDuplicate);   // seq 2 again
  EXPECT_EQ(a.add_sample(2, 1, 2 * kPeriod, 0.0, 0), Verdict::kOutOfOrder);  // seq backwards
  EXPECT_EQ(a.add_sample(3, 3, kPeriod, 0.0, 0), Verdict::kOutOfOrder);      // stamp not increasing
  EXPECT_EQ(a.add_sample(4, 5, 2 * kPeriod, 0.0, 0), Verdict::kAccepted);    // seq 3, 4 skipped
  EXPECT_EQ(a.add_sample(0, 1, 2 * kPeriod, 0.0, 0), Verdict::kUnknownGyro);
  EXPECT_EQ(a.add_sample(5, 1, 2 * kPeriod, 0.0, 0), Verdict::kUnknownGyro);
  const auto& c = a.counters();
  EXPECT_EQ(c.samples_duplicate, 1U);
  EXPECT_EQ(c.samples_out_of_order, 2U);
  EXPECT_EQ(c.samples_gap, 2U);
  EXPECT_EQ(c.samples_unknown_gyro, 2U);
}

TEST(EpochAssembler, SampleForAnEmittedEpochIsLate) {
  auto a = make();
  for (int g : {1, 2, 3}) a.add_sample(g, 1, 0, 1.0, 0);
  std::vector<fdi::Epoch> out;
  a.poll(kLatency, out);
  ASSERT_EQ(out.size(), 1U);
  EXPECT_EQ(a.add_sample(4, 1, 0, 1.0, kLatency + 1), Verdict::kLate);
  EXPECT_EQ(a.counters().samples_late, 1U);
  // Its next sample is on time again.
  EXPECT_EQ(a.add_sample(4, 2, kPeriod, 1.0, kLatency + 2), Verdict::kAccepted);
}

TEST(EpochAssembler, EpochsComeOutInStampOrderEvenWhenCompletedOutOfOrder) {
  auto a = make();
  // Epoch 0 misses gyro 2 until epoch 1 is complete for the others.
  for (int g : {1, 3, 4}) a.add_sample(g, 1, 0, 0.0, 0);
  for (int g : {1, 3, 4}) a.add_sample(g, 2, kPeriod, 0.0, 0);
  std::vector<fdi::Epoch> out;
  a.poll(1, out);
  EXPECT_TRUE(out.empty());             // gyro 2 has not moved past epoch 0
  a.add_sample(2, 2, kPeriod, 0.0, 2);  // gyro 2's epoch-0 sample is lost
  a.poll(2, out);
  ASSERT_EQ(out.size(), 2U);
  EXPECT_EQ(out[0].stamp_ns, 0);
  EXPECT_EQ(out[0].present[1], 0);
  EXPECT_EQ(out[1].stamp_ns, kPeriod);
  EXPECT_EQ(out[1].present, (std::vector<std::uint8_t>{1, 1, 1, 1}));
}

TEST(EpochAssembler, AbsentGyroIsNotWaitedForAndReturnsWhenItDelivers) {
  auto a = make();
  a.mark_absent(3, AbsentReason::kDeadline);
  EXPECT_TRUE(a.absent(3));
  for (int g : {1, 2, 4}) a.add_sample(g, 1, 0, 0.0, 0);
  std::vector<fdi::Epoch> out;
  a.poll(0, out);
  ASSERT_EQ(out.size(), 1U);
  EXPECT_EQ(out[0].present[2], 0);
  a.add_sample(3, 7, kPeriod, 0.0, 1);
  EXPECT_FALSE(a.absent(3));
  EXPECT_EQ(a.counters().deadlines_missed, 1U);
}

TEST(EpochAssembler, AbsenceIsCountedOncePerEpisodeAndByReason) {
  auto a = make();
  feed_epoch(a, 0, 0);
  for (int g = 1; g <= 4; ++g) a.mark_absent(g, AbsentReason::kLiveliness);
  a.mark_absent(2, AbsentReason::kDeadline);  // already absent: not counted again
  std::vector<fdi::Epoch> out;
  a.poll(0, out);
  EXPECT_EQ(out.size(), 1U);  // only the real epoch: silence creates no epochs
  EXPECT_EQ(a.counters().liveliness_lost, 4U);
  EXPECT_EQ(a.counters().deadlines_missed, 0U);
}

TEST(EpochAssembler, RestartAfterSilenceStartsAFreshTimeBase) {
  auto a = make();
  for (int k = 0; k < 3; ++k) feed_epoch(a, k, 0);
  std::vector<fdi::Epoch> out;
  a.poll(0, out);
  ASSERT_EQ(out.size(), 3U);
  for (int g = 1; g <= 4; ++g) a.mark_absent(g, AbsentReason::kLiveliness);
  // A new simulator: sequence numbers and stamps from the start again.
  feed_epoch(a, 0, 100);
  a.poll(100, out);
  ASSERT_EQ(out.size(), 4U);
  EXPECT_EQ(out[3].stamp_ns, 0);
  EXPECT_EQ(out[3].present, (std::vector<std::uint8_t>{1, 1, 1, 1}));
  EXPECT_EQ(a.counters().sensor_restarts, 1U);
  EXPECT_EQ(a.counters().samples_out_of_order, 0U);
}

TEST(EpochAssembler, ResumingAfterSilenceIsNotARestart) {
  auto a = make();
  for (int k = 0; k < 3; ++k) feed_epoch(a, k, 0);
  std::vector<fdi::Epoch> out;
  a.poll(0, out);
  for (int g = 1; g <= 4; ++g) a.mark_absent(g, AbsentReason::kDeadline);
  feed_epoch(a, 5, 1);  // the same sensor after a pause: sequence and time go on
  a.poll(1, out);
  ASSERT_EQ(out.size(), 4U);
  EXPECT_EQ(out[3].stamp_ns, 5 * kPeriod);
  EXPECT_EQ(a.counters().sensor_restarts, 0U);
  EXPECT_EQ(a.counters().samples_gap, 8U);  // 2 numbers skipped on each of 4 gyros
}

TEST(EpochAssembler, AUnitResumingIsWaitedForAsAWhole) {
  auto a = make();
  feed_epoch(a, 0, 0);
  std::vector<fdi::Epoch> out;
  a.poll(0, out);
  for (int g = 1; g <= 4; ++g) a.mark_absent(g, AbsentReason::kDeadline);  // the whole stream paused
  a.add_sample(1, 2, kPeriod, 0.0, 100);
  a.poll(100, out);
  EXPECT_EQ(out.size(), 1U);  // epoch 1 waits for gyros 2..4 again instead of going out with gyro 1 alone
  for (int g = 2; g <= 4; ++g) EXPECT_EQ(a.add_sample(g, 2, kPeriod, 0.0, 101), Verdict::kAccepted);
  a.poll(101, out);
  ASSERT_EQ(out.size(), 2U);
  EXPECT_EQ(out[1].present, (std::vector<std::uint8_t>{1, 1, 1, 1}));
  EXPECT_EQ(a.counters().samples_late, 0U);
}

TEST(EpochAssembler, WithoutSilenceABackwardStreamIsNotARestart) {
  auto a = make();
  for (int k = 0; k < 3; ++k) feed_epoch(a, k, 0);
  std::vector<fdi::Epoch> out;
  a.poll(0, out);
  EXPECT_EQ(a.add_sample(1, 1, 0, 0.0, 1), Verdict::kOutOfOrder);
  EXPECT_EQ(a.counters().sensor_restarts, 0U);
}

TEST(EpochAssembler, ReferenceIsAttachedToTheEpochWithinTolerance) {
  auto a = make();
  const Quaternion q = from_wxyz(0.5, 0.5, 0.5, 0.5);
  a.add_reference(kPeriod + 500, q);  // within tolerance of epoch 1, not of epoch 0
  feed_epoch(a, 0, 0);
  feed_epoch(a, 1, 0);
  std::vector<fdi::Epoch> out;
  a.poll(0, out);
  ASSERT_EQ(out.size(), 2U);
  EXPECT_FALSE(out[0].reference_q_RB.has_value());
  ASSERT_TRUE(out[1].reference_q_RB.has_value());
  EXPECT_EQ(out[1].reference_q_RB->w(), 0.5);
  EXPECT_FALSE(out[1].reference_stamp_ns.has_value());  // its own epoch's: no stamp of its own
}

// A star tracker delivering after the epoch of its stamp was emitted: the reference goes with the next epoch,
// stamped with its own time, for the pipeline's fusion horizon (docs/dds.md, "Epoch assembly"); several
// waiting go one an epoch, oldest first, and an epoch's own reference goes before them. Without the change
// each late reference was dropped (references_late 3, no reference on epochs 3 and 4).
TEST(EpochAssembler, AReferenceForAnEmittedEpochGoesWithTheNextAtItsOwnStamp) {
  auto a = make();
  const Quaternion q = from_wxyz(0.5, 0.5, 0.5, 0.5);
  const Quaternion q_other = from_wxyz(0.0, 1.0, 0.0, 0.0);
  std::vector<fdi::Epoch> out;
  for (int k = 0; k < 3; ++k) feed_epoch(a, k, 0);
  a.poll(0, out);
  ASSERT_EQ(out.size(), 3U);
  a.add_reference(kPeriod, q_other);  // epoch 1's, 2 periods late
  a.add_reference(0, q);              // epoch 0's, later still: it goes first (oldest stamp)
  a.add_reference(4 * kPeriod, q);    // epoch 4's own, in time
  out.clear();
  for (int k = 3; k < 6; ++k) feed_epoch(a, k, 0);
  a.poll(0, out);
  ASSERT_EQ(out.size(), 3U);
  ASSERT_TRUE(out[0].reference_q_RB.has_value());  // epoch 3: the oldest late one
  EXPECT_EQ(out[0].reference_q_RB->w(), 0.5);
  ASSERT_TRUE(out[0].reference_stamp_ns.has_value());
  EXPECT_EQ(*out[0].reference_stamp_ns, 0);
  ASSERT_TRUE(out[1].reference_q_RB.has_value());  // epoch 4: its own
  EXPECT_FALSE(out[1].reference_stamp_ns.has_value());
  ASSERT_TRUE(out[2].reference_q_RB.has_value());  // epoch 5: the next late one
  EXPECT_EQ(out[2].reference_q_RB->x(), 1.0);
  EXPECT_EQ(out[2].reference_stamp_ns.value_or(-1), kPeriod);
  EXPECT_EQ(a.counters().references_late, 0U);
}

// More than kMaxLateReferences late references waiting for an epoch: the oldest gives way, counted as crowded
// out (on the wire within Health.references_too_late, not samples_late), and the first of a run is returned
// for the service to report; the run ends once every waiting reference has gone on with an epoch. Before, the
// one crowded out was only counted in references_late (Health's samples_late) and nothing said it.
TEST(EpochAssembler, ALateReferenceCrowdedOutIsCountedAndTheFirstOfARunReturned) {
  auto a = make();
  const Quaternion q = from_wxyz(0.5, 0.5, 0.5, 0.5);
  std::vector<fdi::Epoch> out;
  for (int k = 0; k < 3; ++k) feed_epoch(a, k, 0);
  a.poll(0, out);
  ASSERT_EQ(out.size(), 3U);
  constexpr std::size_t kMax = EpochAssembler::kMaxLateReferences;
  for (std::size_t i = 0; i < kMax; ++i)
    EXPECT_FALSE(a.add_reference(static_cast<std::int64_t>(i) * 1000, q).has_value());
  const auto crowded = a.add_reference(static_cast<std::int64_t>(kMax) * 1000, q);
  ASSERT_TRUE(crowded.has_value());
  EXPECT_EQ(crowded->stamp_ns, 0);                                // the oldest
  EXPECT_DOUBLE_EQ(crowded->late_s, ns_to_seconds(2 * kPeriod));  // against the last epoch emitted
  EXPECT_FALSE(a.add_reference(static_cast<std::int64_t>(kMax + 1) * 1000, q).has_value());  // same run
  EXPECT_EQ(a.counters().references_crowded_out, 2U);
  EXPECT_EQ(a.counters().references_late, 0U);
  // One epoch takes one: the queue is not empty yet, so the run goes on.
  out.clear();
  feed_epoch(a, 3, 0);
  a.poll(0, out);
  EXPECT_FALSE(a.add_reference(100, q).has_value());
  EXPECT_FALSE(a.add_reference(200, q).has_value());
  EXPECT_EQ(a.counters().references_crowded_out, 3U);
  // Every waiting one gone on (one an epoch): the next crowded out starts a new run.
  for (int k = 4; k < 4 + static_cast<int>(kMax); ++k) feed_epoch(a, k, 0);
  out.clear();
  a.poll(0, out);
  ASSERT_EQ(out.size(), kMax);
  for (const auto& epoch : out) EXPECT_TRUE(epoch.reference_stamp_ns.has_value());
  for (std::size_t i = 0; i < kMax; ++i)
    EXPECT_FALSE(a.add_reference(static_cast<std::int64_t>(i) * 1000, q).has_value());
  EXPECT_TRUE(a.add_reference(static_cast<std::int64_t>(kMax) * 1000, q).has_value());
  EXPECT_EQ(a.counters().references_crowded_out, 4U);
}

// A sample that says its reference was written holds the epoch until the reference is in, whichever of the
// two streams arrives first (they have no common delivery order); without it, up to the latency limit only.
TEST(EpochAssembler, AnEpochWhoseReferenceWasWrittenWaitsForIt) {
  auto a = make();
  const Quaternion q = from_wxyz(0.5, 0.5, 0.5, 0.5);
  for (int g = 1; g <= 4; ++g) EXPECT_EQ(a.add_sample(g, 1, 0, g, 0, true), Verdict::kAccepted);
  std::vector<fdi::Epoch> out;
  a.poll(kLatency - 1, out);
  EXPECT_TRUE(out.empty());  // every gyro in, the reference not yet
  a.add_reference(500, q);   // within the tolerance of the epoch's stamp
  a.poll(kLatency - 1, out);
  ASSERT_EQ(out.size(), 1U);
  ASSERT_TRUE(out[0].reference_q_RB.has_value());
  EXPECT_EQ(out[0].reference_q_RB->w(), 0.5);
  // A reference that never comes: the epoch goes at the latency limit, without one, and that is counted
  // (references_late, on the wire within samples_late); should it still come, it is late and counted.
  for (int g = 1; g <= 4; ++g) EXPECT_EQ(a.add_sample(g, 2, kPeriod, g, kLatency, true), Verdict::kAccepted);
  out.clear();
  a.poll(2 * kLatency - 1, out);
  EXPECT_TRUE(out.empty());
  a.poll(2 * kLatency, out);
  ASSERT_EQ(out.size(), 1U);
  EXPECT_FALSE(out[0].reference_q_RB.has_value());
  EXPECT_EQ(a.counters().references_late, 1U);
  a.add_reference(kPeriod, q);  // after all: it goes with the next epoch, at its own stamp
  EXPECT_EQ(a.counters().references_late, 1U);
}

// --- The unit's clock (docs/dds.md, "Epoch assembly"): one bad stamp or sequence number never blinds it.

// Feeds epochs [from, to) of all four gyros at local time k·period, stamped k·period + stamp_offset
// (speed 1); the sequence number is the stamp's period count + 1.
void feed_flowing(EpochAssembler& a, int from, int to, std::vector<fdi::Epoch>& out,
                  std::int64_t stamp_offset = 0) {
  for (int k = from; k < to; ++k) {
    const std::int64_t t = k * kPeriod;
    const auto seq = static_cast<std::uint64_t>((t + stamp_offset) / kPeriod + 1);
    for (int g = 1; g <= 4; ++g) {
      EXPECT_EQ(a.add_sample(g, seq, t + stamp_offset, 0.0, t), Verdict::kAccepted)
          << "epoch " << k << " gyro " << g;
    }
    a.poll(t, out);
  }
}

TEST(EpochAssembler, AStampAtInt64MaxIsAnOutlierAndNeverMovesTheClock) {
  auto a = make();
  std::vector<fdi::Epoch> out;
  feed_flowing(a, 0, 10, out);
  EXPECT_EQ(a.add_sample(2, 11, std::numeric_limits<std::int64_t>::max(), 0.0, 10 * kPeriod),
            Verdict::kTimeOutlier);
  EXPECT_EQ(a.add_sample(3, 11, std::numeric_limits<std::int64_t>::min(), 0.0, 10 * kPeriod),
            Verdict::kTimeOutlier);
  feed_flowing(a, 11, 20,
               out);  // every later good epoch is accepted (sequence 11 skipped: gap 1 on gyros 2, 3)
  ASSERT_EQ(out.size(), 19U);
  EXPECT_EQ(out.back().stamp_ns, 19 * kPeriod);
  EXPECT_EQ(a.counters().time_outlier, 2U);
  EXPECT_EQ(a.counters().sensor_restarts, 0U);
  EXPECT_EQ(a.counters().samples_late + a.counters().samples_out_of_order, 0U);
}

TEST(EpochAssembler, AnEpochAMillionSecondsAheadIsDroppedWhole) {
  auto a = make();
  std::vector<fdi::Epoch> out;
  feed_flowing(a, 0, 10, out);
  const std::int64_t ahead = 1'000'000 * kNanosPerSecond;
  for (int g = 1; g <= 4; ++g)
    EXPECT_EQ(a.add_sample(g, 11, ahead, 0.0, 10 * kPeriod), Verdict::kTimeOutlier);
  feed_flowing(a, 11, 20, out);
  EXPECT_EQ(out.size(), 19U);
  EXPECT_EQ(a.counters().time_outlier, 4U);
  EXPECT_EQ(a.counters().sensor_restarts, 0U);  // one epoch on a new time base is no restart
}

TEST(EpochAssembler, TheWindowIsJudgedAgainstTheReceiveClock) {
  auto a = make();
  std::vector<fdi::Epoch> out;
  feed_flowing(a, 0, 10, out);
  // A stamp 0.1 s + 1 ns ahead of where the receive clock puts the unit: outlier; exactly 0.1 s: kept.
  const std::int64_t now = 10 * kPeriod;
  EXPECT_EQ(a.add_sample(1, 11, now + kWindow + 1, 0.0, now), Verdict::kTimeOutlier);
  EXPECT_EQ(a.add_sample(1, 11, now + kWindow, 0.0, now), Verdict::kAccepted);
  // After 5 s of silence the sensor is 5 s further on: accepted without any re-anchoring.
  auto b = make();
  feed_flowing(b, 0, 10, out);
  for (int g = 1; g <= 4; ++g) b.mark_absent(g, AbsentReason::kDeadline);
  const std::int64_t later = 10 * kPeriod + 5 * kNanosPerSecond;
  for (int g = 1; g <= 4; ++g) EXPECT_EQ(b.add_sample(g, 511, later, 0.0, later), Verdict::kAccepted);
  EXPECT_EQ(b.counters().time_outlier, 0U);
  EXPECT_EQ(b.counters().samples_gap, 4U * 500U);  // 500 numbers per gyro, credible over 5 s
  EXPECT_EQ(b.counters().sensor_restarts, 0U);
}

TEST(EpochAssembler, DelayedDeliveryNeverMakesAnOutlier) {
  auto a = make();
  std::vector<fdi::Epoch> out;
  // A full reader history (64 samples per gyro) held up 2 s and taken at once, gyro by gyro (gyro 2's
  // first sample lags gyro 1's newest by 63 periods), then on time again.
  const std::int64_t batch_now = 2 * kNanosPerSecond;
  for (int g = 1; g <= 4; ++g) {
    for (int k = 0; k < 64; ++k) {
      EXPECT_EQ(a.add_sample(g, static_cast<std::uint64_t>(k + 1), k * kPeriod, 0.0, batch_now),
                Verdict::kAccepted);
    }
  }
  a.poll(batch_now, out);
  feed_flowing(a, 200, 210, out, -136 * kPeriod);  // stamps 64.. periods at local 2 s..: taken at once
  EXPECT_EQ(out.size(), 74U);
  EXPECT_EQ(a.counters().time_outlier, 0U);
}

TEST(EpochAssembler, SequenceNumberUint64MaxIsADiscontinuityNotAGap) {
  auto a = make();
  std::vector<fdi::Epoch> out;
  feed_flowing(a, 0, 100, out);
  // Seen from 100, 2^64-1 is 101 numbers back and 2^63 as far as can be: neither is credible.
  const std::int64_t now = 100 * kPeriod;
  EXPECT_EQ(a.add_sample(1, std::numeric_limits<std::uint64_t>::max(), now, 0.0, now),
            Verdict::kSeqDiscontinuity);
  EXPECT_EQ(a.add_sample(2, std::uint64_t{1} << 63, now, 0.0, now), Verdict::kSeqDiscontinuity);
  EXPECT_EQ(a.add_sample(3, 100'000, now, 0.0, now), Verdict::kSeqDiscontinuity);  // forward, 1 period later
  feed_flowing(a, 100, 120, out);  // the gyros' own numbering goes on: nothing is out of order
  EXPECT_EQ(out.size(), 120U);
  EXPECT_EQ(a.counters().samples_gap, 0U);
  EXPECT_EQ(a.counters().samples_out_of_order, 0U);
  EXPECT_EQ(a.counters().seq_discontinuity, 3U);
}

TEST(EpochAssembler, SequenceNumbersWrapAround) {
  auto a = make();
  std::vector<fdi::Epoch> out;
  const std::uint64_t start =
      std::numeric_limits<std::uint64_t>::max() - 1;  // ..., 2^64-2, 2^64-1, 0, 1, ...
  for (int k = 0; k < 6; ++k) {
    for (int g = 1; g <= 4; ++g) {
      EXPECT_EQ(a.add_sample(g, start + static_cast<std::uint64_t>(k), k * kPeriod, 0.0, k * kPeriod),
                Verdict::kAccepted);
    }
  }
  EXPECT_EQ(a.add_sample(1, start + 3, 6 * kPeriod, 0.0, 6 * kPeriod), Verdict::kOutOfOrder);  // 1 after 3
  EXPECT_EQ(a.counters().samples_gap, 0U);
  EXPECT_EQ(a.counters().seq_discontinuity, 0U);
}

TEST(EpochAssembler, AGyroWhoseNumberingRestartsIsReanchoredOnItsSecondSample) {
  auto a = make();
  std::vector<fdi::Epoch> out;
  feed_flowing(a, 0, 100, out);
  // Gyro 3's writer restarts: numbers from 1 again while time goes on.
  for (int g = 1; g <= 4; ++g) {
    a.add_sample(g, g == 3 ? 1 : 101, 100 * kPeriod, 0.0, 100 * kPeriod);
  }
  EXPECT_EQ(a.counters().seq_discontinuity, 1U);
  for (int g = 1; g <= 4; ++g) {
    EXPECT_EQ(a.add_sample(g, g == 3 ? 2 : 102, 101 * kPeriod, 0.0, 101 * kPeriod), Verdict::kAccepted);
  }
  EXPECT_EQ(a.counters().samples_gap, 0U);
}

TEST(EpochAssembler, ASensorClockThatJumpsForGoodIsReanchoredAfterThreeSamplesPerGyro) {
  auto a = make();
  std::vector<fdi::Epoch> out;
  feed_flowing(a, 0, 100, out);  // 1 s of time
  // The sensor's clock restarts at 0 (sequence numbers too) without the stream pausing.
  const std::int64_t local0 = 100 * kPeriod;
  for (int k = 0; k < kRestartSamples; ++k) {
    for (int g = 1; g <= 4; ++g) {
      const Verdict v =
          a.add_sample(g, static_cast<std::uint64_t>(k + 1), k * kPeriod, 0.0, local0 + k * kPeriod);
      const bool last = k == kRestartSamples - 1 && g == 4;  // the sample that confirms the new base
      EXPECT_EQ(v, last ? Verdict::kAccepted : Verdict::kTimeOutlier) << k << " " << g;
    }
  }
  EXPECT_EQ(a.counters().sensor_restarts, 1U);
  EXPECT_EQ(a.counters().time_outlier, 4U * kRestartSamples - 1U);
  out.clear();
  for (int k = kRestartSamples; k < 10; ++k) {
    for (int g = 1; g <= 4; ++g) {
      EXPECT_EQ(a.add_sample(g, static_cast<std::uint64_t>(k + 1), k * kPeriod, 0.0, local0 + k * kPeriod),
                Verdict::kAccepted);
    }
    a.poll(local0 + k * kPeriod, out);
  }
  ASSERT_FALSE(out.empty());
  EXPECT_EQ(out.back().stamp_ns, 9 * kPeriod);
  EXPECT_EQ(a.counters().samples_out_of_order + a.counters().samples_late, 0U);
}

TEST(EpochAssembler, OutliersInterleavedWithGoodSamplesNeverReanchor) {
  auto a = make();
  std::vector<fdi::Epoch> out;
  // A hostile peer repeats a whole epoch 1e6 s ahead between every good epoch: it never takes over.
  const std::int64_t ahead = 1'000'000 * kNanosPerSecond;
  for (int k = 0; k < 20; ++k) {
    feed_flowing(a, k, k + 1, out);
    for (int g = 1; g <= 4; ++g) a.add_sample(g, 1000, ahead + k * kPeriod, 0.0, k * kPeriod);
  }
  EXPECT_EQ(out.size(), 20U);
  EXPECT_EQ(a.counters().sensor_restarts, 0U);
  EXPECT_EQ(a.counters().time_outlier, 80U);
}

TEST(EpochAssembler, AnOutlierFirstOfAllIsOutvotedByTheRealStream) {
  auto a = make();
  // The first sample ever is a glitch (stamp 1e6 s): the real stream re-anchors after 3 samples per gyro.
  EXPECT_EQ(a.add_sample(1, 1, 1'000'000 * kNanosPerSecond, 0.0, 0), Verdict::kAccepted);
  std::vector<fdi::Epoch> out;
  for (int k = 0; k < 10; ++k) {
    for (int g = 1; g <= 4; ++g)
      a.add_sample(g, static_cast<std::uint64_t>(k + 2), k * kPeriod, 0.0, k * kPeriod);
    a.poll(k * kPeriod, out);
  }
  EXPECT_EQ(a.counters().sensor_restarts, 1U);
  ASSERT_FALSE(out.empty());
  EXPECT_EQ(out.back().stamp_ns, 9 * kPeriod);
  EXPECT_EQ(out.back().present, (std::vector<std::uint8_t>{1, 1, 1, 1}));
}

TEST(EpochAssembler, InvalidSettingsAreRejectedByName) {
  AssemblerConfig config;
  config.tolerance_ns = config.nominal_period_ns / 2;  // would merge neighbouring epochs
  auto a = EpochAssembler::create(config);
  ASSERT_FALSE(a.ok());
  EXPECT_NE(a.error().message.find("tolerance_s"), std::string::npos);
  config = AssemblerConfig{};
  config.gyro_count = 0;
  EXPECT_FALSE(EpochAssembler::create(config).ok());
  config = AssemblerConfig{};
  config.max_latency_ns = 0;
  EXPECT_FALSE(EpochAssembler::create(config).ok());
  config = AssemblerConfig{};
  config.clock_window_ns = config.nominal_period_ns;  // under 2 periods
  a = EpochAssembler::create(config);
  ASSERT_FALSE(a.ok());
  EXPECT_NE(a.error().message.find("clock_window_s"), std::string::npos);
}

}  // namespace
}  // namespace tetra::service
