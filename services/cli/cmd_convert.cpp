// tetra convert — a gyro log from CSV to HDF5 or back (the format follows each name's extension),
// block by block: memory does not grow with the log's length. The output goes through the output layer
// (RunFiles): written into its temporary file as it goes, renamed into place when the whole log is
// converted.
#include <string>

#include "cli_common.hpp"
#include "commands.hpp"
#include "tetra/core/gyro_log.hpp"
#include "tetra/core/output_files.hpp"

namespace tetra::cli {

namespace {

Status convert(const std::string& in_path, const std::string& out_path, bool compress) {
  RunFiles files;
  files.add_input(in_path, "IN");
  auto out = files.add(out_path, "OUT");
  if (!out) return out.error();
  auto reader = GyroLogReader::open(in_path);
  if (!reader) return reader.error();
  const GyroLog& head = (*reader)->header();
  GyroLogWriter writer;
  writer.set_hdf5_compression(compress);
  // The comment lines go over as they are (provenance included), so a round trip gives the same file.
  if (Status s = writer.open_like(**out, head); !s) return s;
  const auto ng = static_cast<std::size_t>(head.gyro_count);
  GyroLog block;
  while (true) {
    auto more = (*reader)->next(block);
    if (!more) return more.error();
    if (!*more) break;
    for (std::size_t k = 0; k < block.epochs(); ++k) {
      const std::span<const double> values(block.values.data() + k * ng, ng);
      const std::span<const std::uint8_t> present(block.present.data() + k * ng, ng);
      std::optional<std::array<double, 4>> ref;
      if (block.has_reference && block.reference_present[k] != 0) ref = block.reference_wxyz[k];
      if (Status s = writer.write(block.time_s[k], values, present, ref); !s) return s;
    }
  }
  if (Status s = writer.close(); !s) return s;
  return files.commit();
}

}  // namespace

int cmd_convert(int argc, char** argv) {
  CLI::App app{
      "Convert a gyro log between CSV and HDF5, or from TDMS (docs/formats.md); each file's format follows its "
      "name: .h5 or .hdf5 is HDF5, .tdms TDMS (read only), anything else CSV. CSV -> HDF5 -> CSV gives back a "
      "file written by tetra byte for byte.",
      "convert"};
  std::string in_path;
  std::string out_path;
  app.add_option("IN", in_path, "gyro log to read (CSV, HDF5 or TDMS)")->required();
  app.add_option("OUT", out_path, "gyro log to write (CSV or HDF5)")->required();
  bool compress = false;
  app.add_flag("--compress", compress,
               "HDF5 output: shuffle + deflate every dataset (2-4x smaller, read about 5x slower; default: "
               "chunked, uncompressed)");
  if (auto status = parse(app, argc, argv)) return *status;
  if (Status s = convert(in_path, out_path, compress); !s) return report("convert", s.error());
  return kExitOk;
}

}  // namespace tetra::cli
