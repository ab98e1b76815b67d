#pragma once
// The files of a campaign's folder (private to the runner and the merge).

#include <cstddef>
#include <string>
#include <vector>

#include "tetra/campaign/runner.hpp"
#include "tetra/core/result.hpp"

namespace tetra::campaign::folder {

inline constexpr const char* kRunsFile = "runs.csv";
inline constexpr const char* kHashFile = "spec.sha256";  //!< campaign_spec_hash, one line
inline constexpr const char* kSpecCopy = "spec.yaml";    //!< the spec as given
inline constexpr const char* kShardFile = "shard.txt";   //!< "shard K/N" and "runs T" (the matrix's)

std::string path_in(const std::string& dir, const char* name);

struct Manifest {
  Shard shard;
  std::size_t matrix_runs = 0;  //!< runs of the whole campaign
  std::string spec_sha256;
};
std::string manifest_text(const Shard& shard, std::size_t matrix_runs);
//! shard.txt and spec.sha256 of `dir`; errors name the file.
Result<Manifest> read_manifest(const std::string& dir);

//! A row of runs.csv: its run and its text.
struct Row {
  std::size_t run = 0;
  bool error = false;
  std::string line;
};
//! The rows of `runs_csv` by run (none when the file does not exist); a torn line is dropped, and with
//! `drop_errors` the error rows too. A header other than `header`, or a run twice, is an error.
Result<std::vector<Row>> read_rows(const std::string& runs_csv, const std::string& header, bool drop_errors);
//! Writes `header` and `rows` in their order (atomically).
Status write_rows(const std::string& runs_csv, const std::string& header, const std::vector<Row>& rows);
//! The header line of `runs_csv`: this version's columns, then the spec's dispersion columns if any.
Result<std::string> read_header(const std::string& runs_csv);

}  // namespace tetra::campaign::folder
