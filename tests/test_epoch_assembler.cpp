// Epoch assembler (services/fusion): alignment of asynchronous gyro streams, sequence checks,
// absence and restarts. Plain C++, no DDS. All times are exact integers: comparisons are exact.

#include <gtest/gtest.h>

#include <cmath>

#include "tetra/service/epoch_assembler.hpp"

namespace tetra::service {
namespace {

constexpr std::int64_t kPeriod = 10'000'000;    // [ns] 100 Hz
constexpr std::int64_t kTolerance = 1'000'000;  // [ns]
constexpr std::int64_t kLatency = 20'000'000;   // [ns]

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
  a.add_reference(kPeriod, q);  // for an epoch already emitted
  EXPECT_EQ(a.counters().references_late, 1U);
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
}

}  // namespace
}  // namespace tetra::service
