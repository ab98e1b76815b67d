#pragma once
// A gyro log from CSV to HDF5 or back (`tetra convert`; the format follows each name's extension, see
// docs/formats.md), block by block: memory does not grow with the log's length.

#include <cstddef>
#include <string>

#include "tetra/core/result.hpp"
#include "tetra/report/argument_names.hpp"

namespace tetra::report {

struct ConvertLogOptions {
  std::string in_path;    //!< gyro log to read (CSV, or HDF5 when named .h5/.hdf5)
  std::string out_path;   //!< gyro log to write, format by its name; refused when it is the input
  bool compress = false;  //!< HDF5 output: shuffle + deflate every dataset
  ArgumentNames names;    //!< how messages name in_path and out_path
};

struct ConvertedLog {
  std::size_t epochs = 0;  //!< epochs written
};

//! Converts the log. The output goes through the output layer: written into its temporary file as it
//! goes, renamed into place when the whole log is converted. Comment lines go over as they are
//! (provenance included), so a round trip gives the same file.
Result<ConvertedLog> convert_gyro_log(const ConvertLogOptions& options);

}  // namespace tetra::report
