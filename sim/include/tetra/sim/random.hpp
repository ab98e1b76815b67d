#pragma once
// Seeded random streams of the simulator.
//
// Every stage of every gyro (white noise, bias instability, rate random walk, faults, dropped
// samples, ...) draws from its own std::mt19937_64, seeded from the user's seed and a stream id by
// splitmix64. Adding a stage or a gyro therefore never shifts the numbers another stage sees, and a
// fault-free run and a faulty run with the same seed share every noise sample.
//
// Normal deviates come from our own Marsaglia polar sampler on top of the engine's raw 64-bit
// words, not from std::normal_distribution: the C++ standard fixes std::mt19937_64's output but not
// the algorithm of its distributions, so results would otherwise depend on the standard library.
// (libstdc++'s normal_distribution happens to be deterministic on this platform; we do not rely on it.)

#include <cstdint>
#include <random>

namespace tetra::sim {

//! splitmix64 finalizer: a well-mixed 64-bit function of `x`.
inline std::uint64_t splitmix64(std::uint64_t x) {
  x += 0x9E3779B97F4A7C15ULL;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ULL;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBULL;
  return x ^ (x >> 31);
}

//! Stream ids: one per stage kind; combined with the gyro index.
enum class Stream : std::uint64_t {
  kWhiteNoise = 1,
  kBiasInstability = 2,
  kRateRandomWalk = 3,
  kFault = 4,
  kDropped = 5,
  kJitter = 6,
  kReference = 7,
  kMotion = 8,
  kReferenceDrop = 9,
};

//! Seed of the stream `stream` of gyro `gyro_index0` (use -1 for streams that belong to no gyro).
inline std::uint64_t stream_seed(std::uint64_t seed, Stream stream, int gyro_index0) {
  const auto g = static_cast<std::uint64_t>(static_cast<std::int64_t>(gyro_index0) + 1);
  return splitmix64(splitmix64(splitmix64(seed) ^ static_cast<std::uint64_t>(stream)) ^ (g << 32));
}

//! One seeded random stream: uniform and standard normal deviates, reproducible bit for bit.
class Rng {
 public:
  explicit Rng(std::uint64_t seed = 0) : engine_(seed) {}

  //! Uniform in [0, 1) with 53 random bits.
  double uniform() { return static_cast<double>(engine_() >> 11) * 0x1.0p-53; }

  //! Standard normal N(0, 1) (Marsaglia polar method; pairs, the second value is cached).
  double normal();

 private:
  std::mt19937_64 engine_;
  double cached_ = 0.0;
  bool has_cached_ = false;
};

}  // namespace tetra::sim
