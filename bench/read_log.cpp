// Reading alone: a gyro log (CSV or HDF5) read block by block (GyroLogReader, what replay, allan and
// convert use) or whole (read_gyro_log); prints epochs, wall seconds and epochs per second.
// usage: read_log FILE [blocks|whole]
#include <chrono>
#include <cstdio>
#include <cstring>
#include <string>

#include "tetra/core/gyro_log.hpp"

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: read_log FILE [blocks|whole]\n");
    return 2;
  }
  const bool whole = argc > 2 && std::strcmp(argv[2], "whole") == 0;
  const auto t0 = std::chrono::steady_clock::now();
  std::size_t epochs = 0;
  double checksum = 0.0;  // keeps the reading from being optimized away
  if (whole) {
    auto log = tetra::read_gyro_log(argv[1]);
    if (!log) {
      std::fprintf(stderr, "%s\n", log.error().message.c_str());
      return 1;
    }
    epochs = log->epochs();
    checksum = log->time_s.empty() ? 0.0 : log->time_s.back();
  } else {
    auto reader = tetra::GyroLogReader::open(argv[1]);
    if (!reader) {
      std::fprintf(stderr, "%s\n", reader.error().message.c_str());
      return 1;
    }
    tetra::GyroLog block;
    while (true) {
      auto more = (*reader)->next(block);
      if (!more) {
        std::fprintf(stderr, "%s\n", more.error().message.c_str());
        return 1;
      }
      if (!*more) break;
      epochs += block.epochs();
      checksum += block.time_s.back();
    }
  }
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("%s (%s): %zu epochs in %.3f s: %.2f M epochs/s (checksum %g)\n", argv[1],
              whole ? "whole" : "blocks", epochs, s, static_cast<double>(epochs) / s * 1e-6, checksum);
  return 0;
}
