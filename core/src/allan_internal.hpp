#pragma once
// Pieces of the Allan analysis shared by the whole-log path (allan.cpp) and the streaming path
// (allan_stream.cpp), so that both compute the same numbers by the same operations.

#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "tetra/core/allan.hpp"

namespace tetra::allan {

//! uniform_grid with the file line of a row given by `line_of` (nullopt: name the row instead).
Result<SamplingGrid> uniform_grid_lines(
    std::span<const double> time_s, double tolerance, const std::string& source,
    const std::function<std::optional<std::size_t>(std::size_t)>& line_of);

//! Overlapping Allan variance from the angle x[0..n] (in units of τ0) and, when some samples are
//! missing, the cumulative count of present samples cum[0..n] (nullptr when all are present).
//! `interrupt` as overlapping_avar's.
std::vector<AvarPoint> avar_from_angle(const double* x, const std::uint32_t* cum, std::size_t n,
                                       double tau0_s, std::span<const std::int64_t> m_values,
                                       Interrupt* interrupt = nullptr);

//! `options` without its interrupt: the log analyses run their gyros in parallel threads, and an
//! Interrupt is one caller's, polled from one thread.
inline AllanOptions without_interrupt(AllanOptions options) {
  options.interrupt = nullptr;
  return options;
}

//! The checks analyze_series makes before it computes anything.
Status check_series_options(double tau0_s, const AllanOptions& options);
Status check_present_samples(std::size_t present_samples);

//! The rest of analyze_series once the variances are known: intervals, noise fit, noise types.
//! `runs` are the lengths of the runs of consecutive present samples.
Result<AllanResult> finish_series(std::size_t samples, std::size_t present_samples,
                                  const std::vector<AvarPoint>& all, const std::vector<std::size_t>& runs,
                                  double tau0_s, const AllanOptions& options);

//! The ids analyze_gyro_log analyses (options.gyros sorted without repeats, or all), or the error
//! for one not in the log.
Result<std::vector<int>> gyro_ids(const LogAllanOptions& options, int gyro_count);

//! The error of gyro `id` of the log `source` (one of `analysed` gyros) from the analysis of its
//! series: the series' subject kept, else the other gyros named as a way round when there are some.
Error gyro_error(const Error& series_error, const std::string& source, int id, std::size_t analysed);

//! Runs `analyse(i)` for i = 0..count−1 on up to two threads; appends the results to `out` in order,
//! or returns the first error in that order.
Status analyse_gyros(std::size_t count, const std::function<Result<GyroAllan>(std::size_t)>& analyse,
                     std::vector<GyroAllan>& out);

}  // namespace tetra::allan
