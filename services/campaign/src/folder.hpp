#pragma once
// The files of a campaign's folder (private to the runner and the merge).

#include <cstddef>
#include <functional>
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

//! Every name a campaign of `spec` writes in its folder: the manifest and spec's copy, runs.csv, the
//! report's files and, over DDS, the services' folder "dds/" (a trailing '/': a folder).
std::vector<std::string> output_names(const sim::CampaignSpec& spec);
//! The outputs `names` in `dir`, before anything is written there: each that exists must be a regular file
//! the caller may write (or a folder, for a name ending in '/'), not a symbolic link out of `dir`, a FIFO,
//! a device or write-protected; and when `dir` holds no campaign's manifest (shard.txt and spec.sha256),
//! none may exist at all (another program's file, never replaced). Bad input naming the file.
Status check_outputs(const std::string& dir, const std::vector<std::string>& names);

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
//! Checks one row read back (sim::check_campaign_row against the spec's matrix).
using RowCheck = std::function<Status(const sim::CampaignRow&)>;
//! The rows of `runs_csv` by run (none when the file does not exist); a torn line is dropped, and with
//! `drop_errors` the error rows too. A header other than `header`, a row `check` refuses or a run twice is
//! an error naming the file (and the line).
Result<std::vector<Row>> read_rows(const std::string& runs_csv, const std::string& header, bool drop_errors,
                                   const RowCheck& check = {});
//! Writes `header` and `rows` in their order (atomically).
Status write_rows(const std::string& runs_csv, const std::string& header, const std::vector<Row>& rows);
//! The header line of `runs_csv`: this version's columns, then the spec's dispersion columns if any.
Result<std::string> read_header(const std::string& runs_csv);

}  // namespace tetra::campaign::folder
