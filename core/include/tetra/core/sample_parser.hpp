#pragma once
// Live gyro samples from a byte stream (`tetra ingest`, docs/dds.md "Ingesting live samples"): a parser turns
// whatever bytes a source delivers (standard input, UDP datagrams, a serial port) into raw gyro samples.
// Malformed input is counted and described, never fatal: a live source keeps going.
//
// The line protocol (LineProtocolParser): one sample or one epoch per line, CSV,
//   TIME_S,GYRO,RAW          one gyro's output (GYRO 1..N)
//   TIME_S,all,RAW1,...,RAWN every gyro's output of one epoch
// TIME_S the sensor's time [s] (finite, within ±9e9 s), RAW the gyro's raw output [V] (`nan`: an invalid
// sample). Blank lines and lines starting with '#' are ignored; a CR before the newline is dropped.
//
// A vendor's binary frame format plugs in by implementing SampleParser::feed: consume the bytes (a frame
// may span calls), append the complete samples, call refuse() for each malformed frame.

#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace tetra {

//! One gyro output as the unit delivered it.
struct RawGyroSample {
  double time_s = 0.0;  //!< [s] sensor time
  int gyro = 0;         //!< 1-based gyro index
  double raw = 0.0;     //!< [V] raw output (NaN: invalid)
};

class SampleParser {
 public:
  virtual ~SampleParser() = default;
  //! Consumes `bytes` (any split of the stream) and appends the samples completed by them to `out`.
  virtual void feed(std::span<const std::uint8_t> bytes, std::vector<RawGyroSample>& out) = 0;
  //! Everything still buffered is a complete unit (end of stream, or the end of a datagram).
  virtual void flush(std::vector<RawGyroSample>& out) = 0;
  std::uint64_t accepted() const { return accepted_; }               //!< lines or frames that gave samples
  std::uint64_t malformed() const { return malformed_; }             //!< lines or frames refused
  const std::string& last_problem() const { return last_problem_; }  //!< why the last one was refused

 protected:
  void accept() { ++accepted_; }
  void refuse(std::string why) {
    ++malformed_;
    last_problem_ = std::move(why);
  }

 private:
  std::uint64_t accepted_ = 0;
  std::uint64_t malformed_ = 0;
  std::string last_problem_;
};

//! The line protocol above, for a unit of `gyro_count` gyros.
class LineProtocolParser final : public SampleParser {
 public:
  //! [bytes] longest line; a longer one is refused whole (up to its newline).
  static constexpr std::size_t kMaxLineBytes = 4096;
  explicit LineProtocolParser(int gyro_count) : gyro_count_(gyro_count) {}
  void feed(std::span<const std::uint8_t> bytes, std::vector<RawGyroSample>& out) override;
  void flush(std::vector<RawGyroSample>& out) override;
  //! One line (without its newline); the line number names it in last_problem().
  void parse_line(std::string_view line, std::vector<RawGyroSample>& out);

 private:
  int gyro_count_;
  std::string pending_;
  bool overlong_ = false;  // discarding the rest of a line that was too long
  std::uint64_t line_no_ = 0;
};

}  // namespace tetra
