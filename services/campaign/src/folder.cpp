// A campaign's folder: the spec's hash and copy, the shard, and the rows of runs.csv.
#include <openssl/evp.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

#include <yaml-cpp/yaml.h>

#include "folder.hpp"
#include "tetra/campaign/runner.hpp"
#include "tetra/core/csv.hpp"
#include "tetra/core/input_files.hpp"
#include "tetra/core/output_files.hpp"

namespace tetra::campaign {

namespace {

std::string hex_sha256(const std::string& bytes) {
  unsigned char digest[EVP_MAX_MD_SIZE];
  unsigned int length = 0;
  if (EVP_Digest(bytes.data(), bytes.size(), digest, &length, EVP_sha256(), nullptr) != 1) return {};
  static constexpr char kHex[] = "0123456789abcdef";
  std::string out;
  for (unsigned int i = 0; i < length; ++i) {
    out += kHex[digest[i] >> 4];
    out += kHex[digest[i] & 0xf];
  }
  return out;
}

//! A whole number 1..max in `text`, or nullopt.
std::optional<std::size_t> whole_number(const std::string& text, std::size_t max) {
  if (text.empty() || text.size() > 7 || text.find_first_not_of("0123456789") != std::string::npos)
    return std::nullopt;
  const std::size_t v = std::stoul(text);
  if (v < 1 || v > max) return std::nullopt;
  return v;
}

}  // namespace

Result<Shard> parse_shard(const std::string& text) {
  const auto slash = text.find('/');
  const std::string what = "--shard " + text + ": ";
  if (slash == std::string::npos) return bad_input(what + "expected K/N, e.g. 1/4");
  const auto n = whole_number(text.substr(slash + 1), sim::kMaxCampaignRuns);
  if (!n)
    return bad_input(what + "N must be a whole number from 1 to " + std::to_string(sim::kMaxCampaignRuns));
  const auto k = whole_number(text.substr(0, slash), *n);
  if (!k) return bad_input(what + "K must be a whole number from 1 to N (" + std::to_string(*n) + ")");
  return Shard{*k, *n};
}

std::string shard_text(const Shard& shard) {
  return std::to_string(shard.k) + "/" + std::to_string(shard.n);
}

double Progress::rate_per_s() const {
  return elapsed_s > 0.0 && done_now > 0 ? static_cast<double>(done_now) / elapsed_s : 0.0;
}

double Progress::eta_s() const {
  const double rate = rate_per_s();
  if (rate <= 0.0) return -1.0;
  return static_cast<double>(total - std::min(total, done_before + done_now)) / rate;
}

Result<std::string> campaign_spec_hash(const sim::CampaignSpec& spec, const std::string& spec_path) {
  auto text = read_input(spec_path, kMaxYamlBytes);
  if (!text) return text.error();
  std::string canonical;
  try {
    YAML::Emitter out;
    out << YAML::Load(*text);
    canonical = out.c_str();
  } catch (const YAML::Exception& e) {
    return bad_input(spec_path + ": " + e.what());
  }
  const auto add_file = [&](const std::string& label, const std::string& path) -> Status {
    canonical += "\n--- " + label + " " + std::filesystem::path(path).filename().string() + "\n";
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec)) return ok_status();  // a built-in scenario: its name
    auto contents = read_input(path, kMaxYamlBytes);
    if (!contents) return contents.error();
    canonical += *contents;
    return ok_status();
  };
  for (std::size_t i = 0; i < spec.scenario_paths.size(); ++i) {
    if (Status s = add_file("scenario", spec.scenario_paths[i]); !s) return s.error();
    // The files the scenario names (its unit): a unit file changed is another campaign.
    if (i < spec.scenarios.size()) {
      for (const std::string& named : spec.scenarios[i].named_files) {
        if (Status s = add_file("file", named); !s) return s.error();
      }
    }
  }
  return hex_sha256(canonical);
}

namespace folder {

std::string path_in(const std::string& dir, const char* name) {
  return (std::filesystem::path(dir) / name).string();
}

std::vector<std::string> output_names(const sim::CampaignSpec& spec) {
  std::vector<std::string> names{kShardFile, kHashFile, kSpecCopy, kRunsFile};
  for (const std::string& report : sim::campaign_report_files()) names.push_back(report);
  if (spec.target == sim::CampaignTarget::kDds) names.emplace_back("dds/");
  return names;
}

namespace {

//! Whether `path` lies in the folder `root` (both resolved).
bool inside(const std::filesystem::path& root, const std::filesystem::path& path) {
  const auto [end, _] = std::mismatch(root.begin(), root.end(), path.begin(), path.end());
  return end == root.end();
}

//! One output of a campaign folder whose real path is `root`: see check_outputs.
Status check_output(const std::filesystem::path& root, const std::string& path, bool folder) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::file_status link = fs::symlink_status(path, ec);
  if (!fs::exists(link)) return ok_status();
  if (fs::is_symlink(link)) {
    const fs::path target = fs::weakly_canonical(path, ec);
    if (ec || !inside(root, target))
      return bad_input(path + ": a symbolic link out of the output folder (to " +
                       (ec ? std::string("an unreadable path") : target.string()) +
                       "): a campaign writes only its folder's own files");
  }
  if (!folder) return check_output_path(path, "campaign output");
  if (!fs::is_directory(path, ec))
    return bad_input(path + ": is not a folder (a campaign over DDS keeps its services' files there)");
  return ok_status();
}

}  // namespace

Status check_outputs(const std::string& dir, const std::vector<std::string>& names) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::exists(dir, ec)) return ok_status();
  const fs::path root = fs::canonical(dir, ec);
  if (ec) return bad_input(dir + ": cannot resolve the folder: " + ec.message());
  for (const std::string& name : names) {
    const bool folder = !name.empty() && name.back() == '/';
    const std::string path = path_in(dir, name.substr(0, name.size() - (folder ? 1 : 0)).c_str());
    if (Status s = check_output(root, path, folder); !s) return s;
  }
  if (read_manifest(dir)) return ok_status();
  for (const std::string& name : names) {
    const std::string path = path_in(dir, name.substr(0, name.find('/')).c_str());
    if (fs::exists(fs::symlink_status(path, ec)))
      return bad_input(path + ": the output folder holds files of no campaign (no " +
                       std::string(kShardFile) + " and " + kHashFile + " of one): use another folder");
  }
  return ok_status();
}

std::string manifest_text(const Shard& shard, std::size_t matrix_runs) {
  return "shard " + shard_text(shard) + "\nruns " + std::to_string(matrix_runs) + "\n";
}

Result<Manifest> read_manifest(const std::string& dir) {
  const std::string path = path_in(dir, kShardFile);
  auto text = read_input(path, 4096);
  if (!text) return text.error();
  std::istringstream in(*text);
  std::string shard_word, shard, runs_word, runs;
  in >> shard_word >> shard >> runs_word >> runs;
  auto parsed = parse_shard(shard);
  const auto total = whole_number(runs, sim::kMaxCampaignRuns);
  if (shard_word != "shard" || runs_word != "runs" || !parsed || !total)
    return bad_input(path + ": not a campaign's shard file (expected 'shard K/N' and 'runs T')");
  auto hash = read_input(path_in(dir, kHashFile), 4096);
  if (!hash) return hash.error();
  Manifest m;
  m.shard = *parsed;
  m.matrix_runs = *total;
  m.spec_sha256 = hash->substr(0, hash->find('\n'));
  return m;
}

Result<std::string> read_header(const std::string& runs_csv) {
  std::ifstream in(runs_csv);
  std::string line;
  if (!in || !std::getline(in, line)) return bad_input(runs_csv + ": cannot read its header");
  const std::string base = sim::campaign_csv_header();
  if (line.compare(0, base.size(), base) != 0 || (line.size() > base.size() && line[base.size()] != ','))
    return bad_input(runs_csv + ":1: not the header of a campaign of this version");
  return line;
}

Result<std::vector<Row>> read_rows(const std::string& runs_csv, const std::string& header, bool drop_errors,
                                   const RowCheck& check) {
  std::vector<Row> rows;
  std::ifstream in(runs_csv);
  if (!in) return rows;
  std::string line;
  if (!std::getline(in, line)) return rows;
  if (line != header)
    return bad_input(runs_csv +
                     ":1: not the header of this campaign (another version, or other dispersions)");
  for (std::size_t number = 2; std::getline(in, line); ++number) {
    auto row = sim::parse_campaign_row(line, header);
    // A torn line (an interrupted write) can only be the last one, and lacks its newline: the run is
    // done again. Any other row that does not read is refused, never dropped or counted.
    if (!row && in.eof()) continue;
    if (!row) return bad_input(runs_csv + ":" + std::to_string(number) + ": " + row.error().message);
    if (Status st = check ? check(*row) : ok_status(); !st)
      return bad_input(runs_csv + ":" + std::to_string(number) + ": " + st.error().message);
    if (drop_errors && !row->error.empty()) continue;
    rows.push_back(Row{row->run, !row->error.empty(), line});
  }
  std::stable_sort(rows.begin(), rows.end(), [](const Row& a, const Row& b) { return a.run < b.run; });
  for (std::size_t i = 1; i < rows.size(); ++i) {
    if (rows[i].run == rows[i - 1].run)
      return bad_input(runs_csv + ": run " + std::to_string(rows[i].run) + " twice");
  }
  return rows;
}

Status write_rows(const std::string& runs_csv, const std::string& header, const std::vector<Row>& rows) {
  std::string text = header + "\n";
  for (const Row& r : rows) text += r.line + "\n";
  return write_text_file(runs_csv, text);
}

}  // namespace folder

namespace {

//! A new campaign's manifest in `dir`: the spec's copy, the shard, then the hash (the folder is a
//! campaign's once it is there).
Status write_manifest(const std::string& dir, const RunOptions& options, std::size_t matrix_runs,
                      const std::string& hash) {
  auto text = read_input(options.spec_path, kMaxYamlBytes);
  if (!text) return text.error();
  if (Status st = write_text_file(folder::path_in(dir, folder::kSpecCopy), *text); !st) return st;
  if (Status st = write_text_file(folder::path_in(dir, folder::kShardFile),
                                  folder::manifest_text(options.shard, matrix_runs));
      !st)
    return st;
  return write_text_file(folder::path_in(dir, folder::kHashFile), hash + "\n");
}

//! The folder's manifest against this campaign's spec and shard.
Status check_manifest(const std::string& dir, const RunOptions& options, const std::string& hash) {
  auto manifest = folder::read_manifest(dir);
  if (!manifest) return manifest.error();
  if (manifest->spec_sha256 != hash)
    return bad_input(folder::path_in(dir, folder::kHashFile) +
                     ": this folder holds a campaign of another spec (its SHA-256 " +
                     manifest->spec_sha256.substr(0, 12) + "… differs from " + options.spec_path + "'s " +
                     hash.substr(0, 12) + "…): use another --out, or remove the folder to start over");
  if (manifest->shard.k != options.shard.k || manifest->shard.n != options.shard.n)
    return bad_input(folder::path_in(dir, folder::kShardFile) + ": this folder holds shard " +
                     shard_text(manifest->shard) + ", not " + shard_text(options.shard) +
                     ": use another --out");
  return ok_status();
}

}  // namespace

Result<std::vector<std::size_t>> prepare_folder(const sim::CampaignSpec& spec, const RunOptions& options,
                                                RunSummary& summary) {
  const std::string& dir = options.out_dir;
  auto matrix_runs = sim::campaign_run_count(spec);
  if (!matrix_runs) return matrix_runs.error();
  auto hash = campaign_spec_hash(spec, options.spec_path);
  if (!hash) return hash.error();
  // Every file the campaign writes, before any is: runs.csv is appended to in place (an interrupted
  // campaign resumes), the report replaced; a folder of no campaign's is never written into.
  if (Status st = folder::check_outputs(dir, folder::output_names(spec)); !st) return st.error();
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) return failure(dir + ": cannot create the folder");
  summary.runs_csv = folder::path_in(dir, folder::kRunsFile);
  const bool has_hash = std::filesystem::exists(folder::path_in(dir, folder::kHashFile), ec);
  if (Status st =
          has_hash ? check_manifest(dir, options, *hash) : write_manifest(dir, options, *matrix_runs, *hash);
      !st)
    return st.error();
  const std::string header = sim::campaign_csv_header(spec);
  auto rows = folder::read_rows(summary.runs_csv, header, true, [&](const sim::CampaignRow& row) {
    return sim::check_campaign_row(spec, row);
  });
  if (!rows) return rows.error();
  for (const folder::Row& r : *rows) {
    if (!in_shard(options.shard, r.run))
      return bad_input(summary.runs_csv + ": run " + std::to_string(r.run) + " is not a run of shard " +
                       shard_text(options.shard) + " of this campaign");
  }
  // Without the torn line and the error rows (those runs are done again).
  if (Status st = folder::write_rows(summary.runs_csv, header, *rows); !st) return st.error();
  std::vector<std::size_t> pending;
  std::size_t next_done = 0;
  summary.total = 0;
  for (std::size_t index = options.shard.k - 1; index < *matrix_runs; index += options.shard.n) {
    ++summary.total;
    while (next_done < rows->size() && (*rows)[next_done].run < index) ++next_done;
    if (next_done < rows->size() && (*rows)[next_done].run == index) continue;
    pending.push_back(index);
  }
  summary.done_before = summary.total - pending.size();
  return pending;
}

}  // namespace tetra::campaign
