// `tetra campaign merge`: the shards of one campaign into the folder a one-machine run writes.
#include <algorithm>
#include <filesystem>
#include <map>
#include <optional>

#include "folder.hpp"
#include "tetra/campaign/runner.hpp"
#include "tetra/core/csv.hpp"
#include "tetra/core/input_files.hpp"
#include "tetra/sim/campaign.hpp"
#include "tetra/sim/requirement.hpp"

#include <yaml-cpp/yaml.h>

namespace tetra::campaign {

namespace {

bool same_folder(const std::string& a, const std::string& b) {
  std::error_code ec;
  return std::filesystem::equivalent(a, b, ec);
}

//! The spec the shards ran, from the first shard's copy, with the files it names found from the shard's
//! folder or else from the current one (a spec naming its scenarios relative to its own folder, merged
//! from there), and the campaign their spec.sha256 names. Without it no row could be checked against the
//! spec's matrix: an error, never a merge unchecked.
Result<sim::CampaignSpec> spec_of(const std::string& shard_dir, const std::string& sha256) {
  const std::string copy = folder::path_in(shard_dir, folder::kSpecCopy);
  auto text = read_input(copy, kMaxYamlBytes);
  if (!text) return text.error();
  std::string why;
  for (const std::string& base : {shard_dir, std::string(".")}) {
    auto spec = sim::parse_campaign_spec(*text, copy, base);
    if (!spec) {
      if (why.empty()) why = spec.error().message;
      continue;
    }
    auto hash = campaign_spec_hash(*spec, copy);
    if (hash && *hash == sha256) return std::move(spec).value();
    if (why.empty() || !hash)
      why = hash ? "the files it names from " + base + " are not those it ran with" : hash.error().message;
  }
  return bad_input(copy + ": cannot check the rows against the spec's matrix (" + why +
                   "): merge from the folder the spec's file names are relative to");
}
}  // namespace

namespace {

// The shards' manifests: one spec, one split, disjoint, covering every run.
Result<std::vector<folder::Manifest>> shard_manifests(const std::string& out_dir,
                                                      const std::vector<std::string>& shard_dirs) {
  std::vector<folder::Manifest> manifests;
  for (const std::string& dir : shard_dirs) {
    if (same_folder(dir, out_dir)) return bad_input(dir + ": the merge's output is one of its shards");
    auto m = folder::read_manifest(dir);
    if (!m) return m.error();
    manifests.push_back(*m);
  }
  const folder::Manifest& first = manifests.front();
  std::map<std::size_t, std::string> shard_of_k;  // K → folder
  for (std::size_t i = 0; i < manifests.size(); ++i) {
    const folder::Manifest& m = manifests[i];
    if (m.spec_sha256 != first.spec_sha256)
      return bad_input(shard_dirs[i] + ": another spec than " + shard_dirs[0] + " (spec.sha256 " +
                       m.spec_sha256.substr(0, 12) + "… against " + first.spec_sha256.substr(0, 12) + "…)");
    if (m.shard.n != first.shard.n || m.matrix_runs != first.matrix_runs)
      return bad_input(shard_dirs[i] + ": shard " + shard_text(m.shard) + " is of another split than " +
                       shard_dirs[0] + "'s " + shard_text(first.shard));
    if (auto [it, fresh] = shard_of_k.emplace(m.shard.k, shard_dirs[i]); !fresh)
      return bad_input(shard_dirs[i] + ": shard " + shard_text(m.shard) + " again (also " + it->second +
                       "): shards must be disjoint");
  }
  if (shard_of_k.size() != first.shard.n) {
    std::string missing;
    for (std::size_t k = 1; k <= first.shard.n && missing.size() < 200; ++k) {
      if (shard_of_k.count(k) == 0)
        missing += (missing.empty() ? "" : ", ") + shard_text(Shard{k, first.shard.n});
    }
    return bad_input("shards missing (" + missing + "): the shards must cover every run");
  }
  return manifests;
}

// One shard's rows: each of its runs once, in order, none missing; each row as the spec's matrix has it
// (sim::check_campaign_row: its case, and its results consistent with it).
Status append_shard_rows(const std::string& dir, const folder::Manifest& manifest, std::size_t matrix_runs,
                         const std::string& header, const sim::CampaignSpec& spec,
                         std::vector<folder::Row>& all) {
  const std::string runs_csv = folder::path_in(dir, folder::kRunsFile);
  auto rows = folder::read_rows(runs_csv, header, false, [&](const sim::CampaignRow& row) {
    return sim::check_campaign_row(spec, row);
  });
  if (!rows) return rows.error();
  const Shard& shard = manifest.shard;
  std::size_t expected = shard.k - 1;
  for (const folder::Row& r : *rows) {
    if (!in_shard(shard, r.run) || r.run >= matrix_runs)
      return bad_input(runs_csv + ": run " + std::to_string(r.run) + " is not a run of shard " +
                       shard_text(shard));
    if (r.run != expected)
      return bad_input(runs_csv + ": run " + std::to_string(expected) +
                       " missing: the shard is not complete (run it again with the same command)");
    expected += shard.n;
  }
  if (expected < matrix_runs)
    return bad_input(runs_csv + ": run " + std::to_string(expected) +
                     " missing: the shard is not complete (run it again with the same command)");
  all.insert(all.end(), rows->begin(), rows->end());
  return ok_status();
}

// The output folder: this campaign's (merged again at will), or one holding no file the merge would write;
// each of its outputs one the merge may write (folder::check_outputs).
Status check_output_folder(const std::string& out_dir, const sim::CampaignSpec& spec,
                           const std::string& spec_sha256) {
  if (Status s = folder::check_outputs(out_dir, folder::output_names(spec)); !s) return s;
  if (auto old = folder::read_manifest(out_dir); old && old->spec_sha256 != spec_sha256)
    return bad_input(folder::path_in(out_dir, folder::kHashFile) +
                     ": the output folder holds a campaign of another spec: use another folder");
  return ok_status();
}

// The merged folder: the manifest first (a merge stopped half-way leaves a folder of this campaign), then
// the rows and the spec's copy.
Status write_merged(const std::string& out_dir, const std::string& first_shard, const folder::Manifest& first,
                    const std::string& header, const std::vector<folder::Row>& all,
                    const std::string& runs_csv) {
  std::error_code ec;
  std::filesystem::create_directories(out_dir, ec);
  if (ec) return failure(out_dir + ": cannot create the folder");
  auto spec_copy = read_input(folder::path_in(first_shard, folder::kSpecCopy), kMaxYamlBytes);
  if (!spec_copy) return spec_copy.error();
  if (Status st = write_text_file(folder::path_in(out_dir, folder::kShardFile),
                                  folder::manifest_text(Shard{1, 1}, first.matrix_runs));
      !st)
    return st;
  if (Status st = write_text_file(folder::path_in(out_dir, folder::kHashFile), first.spec_sha256 + "\n"); !st)
    return st;
  if (Status st = folder::write_rows(runs_csv, header, all); !st) return st;
  return write_text_file(folder::path_in(out_dir, folder::kSpecCopy), *spec_copy);
}

}  // namespace

Result<RunSummary> merge_shards(const std::string& out_dir, const std::vector<std::string>& shard_dirs) {
  if (shard_dirs.empty()) return bad_input("no shard folder given");
  auto manifests = shard_manifests(out_dir, shard_dirs);
  if (!manifests) return manifests.error();
  const folder::Manifest& first = manifests->front();
  // The header (with the spec's dispersion columns) is the first shard's; every shard must have it.
  auto header = folder::read_header(folder::path_in(shard_dirs[0], folder::kRunsFile));
  if (!header) return header.error();
  const auto spec = spec_of(shard_dirs[0], first.spec_sha256);
  if (!spec) return spec.error();
  std::vector<folder::Row> all;
  all.reserve(first.matrix_runs);
  for (std::size_t i = 0; i < manifests->size(); ++i) {
    if (Status s = append_shard_rows(shard_dirs[i], (*manifests)[i], first.matrix_runs, *header, *spec, all);
        !s)
      return s.error();
  }
  if (Status s = check_output_folder(out_dir, *spec, first.spec_sha256); !s) return s.error();
  std::sort(all.begin(), all.end(), [](const folder::Row& a, const folder::Row& b) { return a.run < b.run; });
  RunSummary summary;
  summary.total = all.size();
  summary.runs_csv = folder::path_in(out_dir, folder::kRunsFile);
  for (const folder::Row& r : all) summary.errors += r.error ? 1 : 0;
  if (Status s = write_merged(out_dir, shard_dirs[0], first, *header, all, summary.runs_csv); !s)
    return s.error();
  return summary;
}

Result<sim::CampaignReportOptions> folder_report_options(const std::string& dir) {
  sim::CampaignReportOptions options;
  auto header = folder::read_header(folder::path_in(dir, folder::kRunsFile));
  if (!header) return header.error();
  options.statistics = header->size() > sim::campaign_csv_header().size();
  const std::string spec_path = folder::path_in(dir, folder::kSpecCopy);
  auto text = read_input(spec_path, std::size_t{16} << 20);
  if (!text) return text.error();
  try {
    const YAML::Node list = YAML::Load(*text)["requirements"];
    if (!list) return options;
    for (std::size_t i = 0; i < list.size(); ++i) {
      auto r = sim::parse_requirement(list[i].as<std::string>());
      if (!r) return bad_input(spec_path + ": requirements[" + std::to_string(i) + "]: " + r.error().message);
      options.requirements.push_back(*r);
    }
  } catch (const YAML::Exception& e) {
    return bad_input(spec_path + ": " + e.what());
  }
  return options;
}

}  // namespace tetra::campaign
