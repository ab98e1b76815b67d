// tetra convert — a gyro log from CSV to HDF5 or back (the format follows each name's extension),
// block by block (tetra/report/convert_log.hpp).
#include "cli_common.hpp"
#include "commands.hpp"
#include "tetra/report/convert_log.hpp"

namespace tetra::cli {

int cmd_convert(int argc, char** argv) {
  CLI::App app{
      "Convert a gyro log between CSV and HDF5, or from TDMS (docs/formats.md); each file's format follows "
      "its "
      "name: .h5 or .hdf5 is HDF5, .tdms TDMS (read only), anything else CSV. CSV -> HDF5 -> CSV gives back "
      "a "
      "file written by tetra byte for byte.",
      "convert"};
  report::ConvertLogOptions o;
  o.names = {{"in_path", "IN"}, {"out_path", "OUT"}};
  app.add_option("IN", o.in_path, "gyro log to read (CSV, HDF5 or TDMS)")->required();
  app.add_option("OUT", o.out_path, "gyro log to write (CSV or HDF5)")->required();
  app.add_flag("--compress", o.compress,
               "HDF5 output: shuffle + deflate every dataset (2-4x smaller, read about 5x slower; default: "
               "chunked, uncompressed)");
  if (auto status = parse(app, argc, argv)) return *status;
  if (auto converted = report::convert_gyro_log(o); !converted) return report("convert", converted.error());
  return kExitOk;
}

}  // namespace tetra::cli
