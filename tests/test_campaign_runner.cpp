// The campaign runner on the command line: a run that cannot run (a coplanar unit), hangs (longer than
// --run-timeout) or loses its worker (kill -9) is an error row naming its case, and the campaign
// completes with every row; a folder of another spec or shard is refused; shards merge into the files
// of a one-machine campaign.

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include "test_support.hpp"

namespace tetra::test {
namespace {

std::vector<std::string> rows_of(const std::string& path) {
  std::vector<std::string> out;
  std::stringstream in(read_file(path));
  std::string line;
  std::getline(in, line);  // the header
  while (std::getline(in, line)) out.push_back(line);
  return out;
}

std::vector<std::string> error_rows(const std::vector<std::string>& rows) {
  std::vector<std::string> out;
  std::copy_if(rows.begin(), rows.end(), std::back_inserter(out),
               [](const std::string& r) { return r.find(",error,") != std::string::npos; });
  return out;
}

//! Scenario files beside the spec: short.yaml (the closed-loop example, 2 min), long.yaml (the same,
//! 1e5 s: several seconds a run) and flat.yaml (the same with a unit whose gyro axes are coplanar).
void write_scenarios(const TempDir& dir) {
  const std::string nadir = read_file(source_path("examples/sim/closed_loop_nadir.yaml"));
  std::string base = nadir.substr(0, nadir.find("faults:")) + nadir.substr(nadir.find("closed_loop:"));
  base.replace(base.find("duration_s: 2400"), 16, "duration_s: 120");
  write_file(dir.file("short.yaml"), base);
  std::string long_run = base;
  long_run.replace(long_run.find("duration_s: 120"), 15, "duration_s: 100000");
  write_file(dir.file("long.yaml"), long_run);
  std::string flat_unit = "unit: flat\ngyros:\n";
  const char* axes[] = {"[1, 0, 0]", "[0, 1, 0]", "[0.6, 0.8, 0]", "[0.8, -0.6, 0]"};
  for (int i = 0; i < 4; ++i) {
    flat_unit += "  - {id: " + std::to_string(i + 1) +
                 ", scale_factor_V_per_dps: 0.08, bias_V: 0, axis: " + axes[i] +
                 ", noise: {arw_dps_rtHz: 3e-5}}\n";
  }
  write_file(dir.file("flat_unit.yaml"), flat_unit);
  std::string flat = base;
  flat.replace(flat.find("scenario: orbit"), 15, "scenario: orbit\nunit: flat_unit.yaml");
  write_file(dir.file("flat.yaml"), flat);
}

// 2 kinds × 2 gyros × 2 seeds + 2 fault-free = 10 runs of 2 min.
void write_small_spec(const std::string& path, const std::string& seeds = "[1, 2]") {
  write_file(path, "scenarios: [" + source_path("examples/sim/closed_loop_nadir.yaml") +
                       "]\nduration_s: 120\nkinds: [bias, stuck]\nsizes: {bias: [0.01]}\ngyros: [1, 4]\n"
                       "onsets_s: [60]\nseeds: " +
                       seeds + "\nfault_free: true\n");
}

// The acceptance's case: a spec holding a coplanar scenario and a hung run completes, those rows errors.
TEST(CampaignRunner, CoplanarUnitAndHungRunAreErrorRows) {
  TempDir dir;
  write_scenarios(dir);
  write_file(dir.file("spec.yaml"),
             "scenarios: [short.yaml, flat.yaml, long.yaml]\nkinds: [stuck]\ngyros: [1]\nonsets_s: [60]\n"
             "seeds: [1]\nfault_free: true\n");
  const std::string out = dir.file("out");
  // 1 s: a long.yaml run takes several seconds even on an idle core, a short.yaml one about 0.01 s.
  const auto run =
      run_tetra("campaign " + dir.file("spec.yaml") + " --out " + out + " --jobs 2 --run-timeout 1");
  ASSERT_EQ(run.exit_status, 0) << run.err;
  const auto rows = rows_of(out + "/runs.csv");
  ASSERT_EQ(rows.size(), 6u);  // 3 scenarios × (1 fault-free + 1 stuck), sorted by run
  EXPECT_EQ(rows[0].rfind("0,short.yaml,none,0,0,0,1,none,", 0), 0u) << rows[0];
  EXPECT_EQ(rows[1].rfind("1,short.yaml,stuck,1,60,0,1,right,", 0), 0u) << rows[1];
  for (std::size_t i = 2; i < 4; ++i) {
    EXPECT_EQ(rows[i].rfind(std::to_string(i) + ",flat.yaml,", 0), 0u) << rows[i];
    EXPECT_NE(rows[i].find(",error,,,,,,,,,,,,,,,,,the fusion pipeline cannot run this unit: geometry: the "
                           "gyro axes do not span "
                           "three dimensions"),
              std::string::npos)
        << rows[i];
  }
  for (std::size_t i = 4; i < 6; ++i) {
    EXPECT_EQ(rows[i].rfind(std::to_string(i) + ",long.yaml,", 0), 0u) << rows[i];
    EXPECT_NE(rows[i].find(",error,,,,,,,,,,,,,,,,,timeout: no result after 1 s (--run-timeout)"),
              std::string::npos)
        << rows[i];
  }
  EXPECT_NE(run.err.find("4 of 6 runs ended in an error"), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("runs/s"), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("6/6 runs (4 errors)"), std::string::npos) << run.err;
  const std::string report = read_file(out + "/report.md");
  EXPECT_NE(report.find("2 runs (`runs.csv`), and 4 that ended in an error"), std::string::npos) << report;
  EXPECT_NE(report.find("| 4 | long.yaml | none | 0 | 0 | 0 | 1 | timeout"), std::string::npos) << report;

  // A resume runs the error rows again (a deterministic error comes back, a transient one may not).
  const auto again = run_tetra("campaign " + dir.file("spec.yaml") + " --out " + out +
                               " --jobs 2 --run-timeout 1 --no-report");
  ASSERT_EQ(again.exit_status, 0) << again.err;
  EXPECT_NE(again.err.find("2 already done"), std::string::npos) << again.err;
  EXPECT_EQ(rows_of(out + "/runs.csv").size(), 6u);
}

// A worker killed with kill -9 in the middle of its run: that run is an error row, a new worker takes
// the rest, every row is in and the progress says done only then.
TEST(CampaignRunner, KilledWorkerIsAnErrorRowAndReplaced) {
  TempDir dir;
  write_scenarios(dir);
  write_file(dir.file("spec.yaml"),
             "scenarios: [long.yaml]\nduration_s: 10000\nkinds: [stuck]\ngyros: [1, 2]\nonsets_s: [60]\n"
             "seeds: [1, 2]\n");
  const std::string out = dir.file("out");
  // A worker (the lowest pid among the campaign's children, found in /proc with the shell's builtins:
  // field 4 of stat is the parent's pid; no procps needed) is killed 0.2 s after it appears: a run of
  // 10000 s takes about 1 s on an idle core, and a worker is without a run only for the microseconds
  // between its row and its next run index.
  const std::string children =
      "children() { for d in /proc/[0-9]*; do read -r _ _ _ pp _ <$d/stat 2>/dev/null && "
      "[ \"$pp\" = \"$1\" ] && echo ${d#/proc/}; done; }; ";
  const auto run =
      run_shell(children + "cd " + dir.path().string() + " && { " + TETRA_BINARY +
                " campaign spec.yaml --out " + out + " --jobs 2 --no-report 2>err.txt & p=$!; " +
                "for i in $(seq 200); do w=$(children $p | sort -n | head -1); [ -n \"$w\" ] && break; "
                "sleep 0.05; done; sleep 0.2; echo \"killing worker $w\"; kill -9 $w; wait $p; }");
  ASSERT_EQ(run.exit_status, 0) << read_file(dir.file("err.txt"));
  const auto rows = rows_of(out + "/runs.csv");
  ASSERT_EQ(rows.size(), 4u) << read_file(out + "/runs.csv");
  for (std::size_t i = 0; i < rows.size(); ++i) EXPECT_EQ(rows[i].rfind(std::to_string(i) + ",", 0), 0u);
  const auto errors = error_rows(rows);
  ASSERT_EQ(errors.size(), 1u) << run.out << read_file(dir.file("err.txt")) << read_file(out + "/runs.csv");
  EXPECT_NE(errors[0].find("worker killed by signal 9"), std::string::npos) << errors[0];
  const std::string err = read_file(dir.file("err.txt"));
  EXPECT_NE(err.find("4/4 runs (1 error)"), std::string::npos) << err;
  EXPECT_NE(err.find("done"), std::string::npos) << err;
}

// The spec's identity covers the files its scenarios name: the unit file of flat.yaml changed after a
// run, the same command refuses the folder (it resumed into the old rows without a word).
TEST(CampaignRunner, ResumeRefusesAChangedUnitFile) {
  TempDir dir;
  write_scenarios(dir);
  write_file(dir.file("spec.yaml"),
             "scenarios: [flat.yaml]\nkinds: [stuck]\ngyros: [1]\nonsets_s: [60]\nseeds: [1]\n");
  const std::string out = dir.file("out");
  const std::string command = "campaign " + dir.file("spec.yaml") + " --out " + out + " --no-report";
  const auto first = run_tetra(command);
  ASSERT_EQ(first.exit_status, 0) << first.err;
  std::string unit = read_file(dir.file("flat_unit.yaml"));
  unit.replace(unit.find("0.08"), 4, "0.09");
  write_file(dir.file("flat_unit.yaml"), unit);
  const auto changed = run_tetra(command);
  EXPECT_EQ(changed.exit_status, 2) << changed.err;
  EXPECT_NE(changed.err.find("spec.sha256: this folder holds a campaign of another spec"), std::string::npos)
      << changed.err;
}

TEST(CampaignRunner, ResumeRefusesAnotherSpecOrShard) {
  TempDir dir;
  write_small_spec(dir.file("spec.yaml"));
  const std::string out = dir.file("out");
  const auto first = run_tetra("campaign " + dir.file("spec.yaml") + " --out " + out + " --no-report");
  ASSERT_EQ(first.exit_status, 0) << first.err;
  const std::string rows = read_file(out + "/runs.csv");
  write_small_spec(dir.file("spec.yaml"), "[1, 3]");
  const auto changed = run_tetra("campaign " + dir.file("spec.yaml") + " --out " + out);
  EXPECT_EQ(changed.exit_status, 2);
  EXPECT_NE(changed.err.find("spec.sha256: this folder holds a campaign of another spec"), std::string::npos)
      << changed.err;
  EXPECT_EQ(read_file(out + "/runs.csv"), rows) << "nothing touched";
  // Comments and layout are not the spec: the same spec written otherwise continues the campaign.
  write_file(dir.file("spec.yaml"), "# the same spec\n" + read_file(out + "/spec.yaml"));
  const auto same = run_tetra("campaign " + dir.file("spec.yaml") + " --out " + out + " --no-report");
  EXPECT_EQ(same.exit_status, 0) << same.err;
  EXPECT_NE(same.err.find("10 already done"), std::string::npos) << same.err;
  const auto shard = run_tetra("campaign " + dir.file("spec.yaml") + " --out " + out + " --shard 1/2");
  EXPECT_EQ(shard.exit_status, 2);
  EXPECT_NE(shard.err.find("shard.txt: this folder holds shard 1/1, not 1/2"), std::string::npos)
      << shard.err;
  for (const char* bad : {"0/2", "3/2", "1", "a/b", "1/0"}) {
    const auto r =
        run_tetra("campaign " + dir.file("spec.yaml") + " --out " + dir.file("x") + " --shard " + bad);
    EXPECT_EQ(r.exit_status, 2) << bad;
    EXPECT_NE(r.err.find(std::string("--shard ") + bad + ":"), std::string::npos) << r.err;
  }
}

// Three shards merge into the runs.csv and report.md of the campaign run whole, byte for byte; merge
// refuses shards missing, twice, incomplete or of another spec.
TEST(CampaignRunner, ShardsMergeToTheOneMachineFiles) {
  TempDir dir;
  write_small_spec(dir.file("spec.yaml"));
  const std::string spec = dir.file("spec.yaml");
  ASSERT_EQ(run_tetra("campaign " + spec + " --out " + dir.file("one") + " --jobs 2").exit_status, 0);
  for (int k = 1; k <= 3; ++k) {
    const auto r = run_tetra("campaign " + spec + " --out " + dir.file("s" + std::to_string(k)) +
                             " --shard " + std::to_string(k) + "/3 --jobs 1");
    ASSERT_EQ(r.exit_status, 0) << r.err;
    EXPECT_NE(r.err.find(k == 1 ? "4 runs of shard 1/3" : "3 runs of shard"), std::string::npos) << r.err;
  }
  const std::string shards = dir.file("s1") + " " + dir.file("s2") + " " + dir.file("s3");
  const auto merged = run_tetra("campaign merge " + dir.file("m") + " " + shards);
  ASSERT_EQ(merged.exit_status, 0) << merged.err;
  EXPECT_EQ(read_file(dir.file("m/runs.csv")), read_file(dir.file("one/runs.csv")));
  EXPECT_EQ(read_file(dir.file("m/report.md")), read_file(dir.file("one/report.md")));
  EXPECT_EQ(read_file(dir.file("m/spec.sha256")), read_file(dir.file("one/spec.sha256")));
  // Merged again into its own folder: the same files. Into a folder whose runs.csv is no campaign's
  // (no shard.txt and spec.sha256): refused, the file untouched.
  ASSERT_EQ(run_tetra("campaign merge " + dir.file("m") + " " + shards + " --no-report").exit_status, 0);
  EXPECT_EQ(read_file(dir.file("m/runs.csv")), read_file(dir.file("one/runs.csv")));
  std::filesystem::create_directories(dir.file("foreign"));
  write_file(dir.file("foreign/runs.csv"), "id,value\n1,2\n");
  const auto foreign = run_tetra("campaign merge " + dir.file("foreign") + " " + shards);
  EXPECT_EQ(foreign.exit_status, 2);
  EXPECT_NE(foreign.err.find("foreign/runs.csv: the output folder holds files of no campaign"),
            std::string::npos)
      << foreign.err;
  EXPECT_EQ(read_file(dir.file("foreign/runs.csv")), "id,value\n1,2\n");

  const auto missing =
      run_tetra("campaign merge " + dir.file("m2") + " " + dir.file("s1") + " " + dir.file("s3"));
  EXPECT_EQ(missing.exit_status, 2);
  EXPECT_NE(missing.err.find("shards missing (2/3)"), std::string::npos) << missing.err;
  const auto twice = run_tetra("campaign merge " + dir.file("m2") + " " + shards + " " + dir.file("s2"));
  EXPECT_EQ(twice.exit_status, 2);
  EXPECT_NE(twice.err.find("shard 2/3 again"), std::string::npos) << twice.err;
  write_small_spec(dir.file("other.yaml"), "[1, 3]");
  ASSERT_EQ(run_tetra("campaign " + dir.file("other.yaml") + " --out " + dir.file("o3") + " --shard 3/3")
                .exit_status,
            0);
  const auto other = run_tetra("campaign merge " + dir.file("m2") + " " + dir.file("s1") + " " +
                               dir.file("s2") + " " + dir.file("o3"));
  EXPECT_EQ(other.exit_status, 2);
  EXPECT_NE(other.err.find("another spec than"), std::string::npos) << other.err;
  // A forged row (negative false alarms, gyro 77, a NaN delay) is refused by file and line, never merged.
  const std::string s2 = read_file(dir.file("s2/runs.csv"));
  for (const auto& [field, value, message] : std::vector<std::tuple<int, std::string, std::string>>{
           {12, "-540", "false_alarms '-540' (a count >= 0)"},
           {3, "77", "gyro '77' (a gyro 0..32)"},
           {9, "nan", "detection_delay_s 'nan'"},
           {8, "5", "isolated_gyro '5' (a gyro 1..4 of the scenario's unit)"},
           {7, "missed", "outcome 'missed' (a run without a fault is none or wrong)"},
           {13, "1e6",
            "fault_free_s '1e+06' (a run without a fault is fault-free to the run's end at 120 s)"}}) {
    std::vector<std::string> lines;
    std::stringstream in(s2);
    for (std::string line; std::getline(in, line);) lines.push_back(line);
    ASSERT_GE(lines.size(), 3U);
    std::vector<std::string> f;
    std::stringstream cells(lines[1]);
    for (std::string c; std::getline(cells, c, ',');) f.push_back(c);
    f[static_cast<std::size_t>(field)] = value;
    std::string forged;
    for (std::size_t i = 0; i < f.size(); ++i) forged += (i ? "," : "") + f[i];
    lines[1] = forged + (lines[1].back() == ',' ? "," : "");
    std::string text;
    for (const auto& l : lines) text += l + "\n";
    write_file(dir.file("s2/runs.csv"), text);
    const auto bad = run_tetra("campaign merge " + dir.file("m3") + " " + shards);
    EXPECT_EQ(bad.exit_status, 2) << bad.err;
    EXPECT_NE(bad.err.find("s2/runs.csv:2: campaign row: " + message), std::string::npos) << bad.err;
  }
  // A row whose values are in range but whose case is not the spec's (gyro 0 of a fault-free run made 1).
  {
    std::string shifted = s2;
    const auto row = shifted.find('\n') + 1;
    std::size_t at = row;
    for (int commas = 0; commas < 3; ++at) commas += shifted[at] == ',' ? 1 : 0;
    ASSERT_EQ(shifted[at], '0');
    shifted[at] = '1';
    write_file(dir.file("s2/runs.csv"), shifted);
    const auto bad = run_tetra("campaign merge " + dir.file("m3") + " " + shards);
    EXPECT_EQ(bad.exit_status, 2) << bad.err;
    EXPECT_NE(bad.err.find("s2/runs.csv:2: campaign row: gyro '1' (run 1 of the spec's matrix has gyro 0)"),
              std::string::npos)
        << bad.err;
  }
  write_file(dir.file("s2/runs.csv"), s2);
  // Shard 3 with its last row torn off (an interrupted task): incomplete.
  const std::string s3 = read_file(dir.file("s3/runs.csv"));
  write_file(dir.file("s3/runs.csv"), s3.substr(0, s3.rfind('\n', s3.size() - 2) + 1));
  const auto torn = run_tetra("campaign merge " + dir.file("m2") + " " + shards);
  EXPECT_EQ(torn.exit_status, 2);
  EXPECT_NE(torn.err.find("s3/runs.csv: run 8 missing: the shard is not complete"), std::string::npos)
      << torn.err;
}

// A spec naming its scenario relative to its own folder, its shards given as relative folders: every row
// is still checked against the spec's matrix (the spec's copy in a shard does not find the scenario
// there, and the check was skipped: a row of gyro 1 for gyro 0 merged with exit 0); merged from a folder
// where the scenario is not found either, an error says the rows cannot be checked.
TEST(CampaignRunner, ShardsGivenAsRelativeFoldersAreCheckedAgainstTheMatrix) {
  TempDir dir;
  write_file(dir.file("nadir.yaml"), read_file(source_path("examples/sim/closed_loop_nadir.yaml")));
  write_file(dir.file("spec.yaml"),
             "scenarios: [nadir.yaml]\nduration_s: 120\nkinds: [stuck]\ngyros: [1]\nonsets_s: [60]\n"
             "seeds: [1, 2]\nfault_free: true\n");
  const std::string in_dir = "cd " + dir.path().string() + " && " + std::string(TETRA_BINARY) + " ";
  for (const char* k : {"1", "2"}) {
    const auto r = run_shell(in_dir + "campaign spec.yaml --out s" + k + " --shard " + k + "/2 --jobs 1");
    ASSERT_EQ(r.exit_status, 0) << r.err;
  }
  const std::string s2 = read_file(dir.file("s2/runs.csv"));
  std::string forged = s2;  // run 1: fault-free, gyro 0, made gyro 1
  std::size_t at = forged.find('\n') + 1;
  for (int commas = 0; commas < 3; ++at) commas += forged[at] == ',' ? 1 : 0;
  ASSERT_EQ(forged[at], '0') << s2;
  forged[at] = '1';
  write_file(dir.file("s2/runs.csv"), forged);
  auto r = run_shell(in_dir + "campaign merge m s1 s2");
  EXPECT_EQ(r.exit_status, 2) << r.err;
  EXPECT_NE(r.err.find("s2/runs.csv:2: campaign row: gyro '1' (run 1 of the spec's matrix has gyro 0)"),
            std::string::npos)
      << r.err;
  EXPECT_FALSE(std::filesystem::exists(dir.file("m/runs.csv")));
  write_file(dir.file("s2/runs.csv"), s2);
  std::filesystem::create_directories(dir.file("elsewhere"));
  r = run_shell("cd " + dir.file("elsewhere") + " && " + std::string(TETRA_BINARY) +
                " campaign merge ../m ../s1 ../s2");
  EXPECT_EQ(r.exit_status, 2) << r.err;
  EXPECT_NE(r.err.find("../s1/spec.yaml: cannot check the rows against the spec's matrix"), std::string::npos)
      << r.err;
  r = run_shell(in_dir + "campaign merge m s1 s2");
  EXPECT_EQ(r.exit_status, 0) << r.err;
  EXPECT_TRUE(std::filesystem::exists(dir.file("m/runs.csv")));
}

// Every file a campaign writes in its folder (runs.csv, the manifest, report.md and its plots) is checked
// before any is written, by run and merge alike: in a folder of no campaign any of them is another
// program's and refused (report.md was replaced); a symbolic link out of the folder, a FIFO or a
// write-protected file is refused in a campaign's folder too. Each refusal is one line naming the file,
// exit 2, the file untouched.
TEST(CampaignRunner, OutputsOfNoCampaignOrOutOfTheFolderAreRefused) {
  TempDir dir;
  write_file(dir.file("spec.yaml"),
             "loop: open\nscenarios: [orbit]\nduration_s: 30\nkinds: [stuck]\ngyros: [1]\nonsets_s: [10]\n"
             "seeds: [1]\n");
  const std::string spec = dir.file("spec.yaml");
  const auto run = [&](const std::string& out) { return run_tetra("campaign " + spec + " --out " + out); };
  const auto refused = [&](const CommandResult& r, const std::string& message, const std::string& file,
                           const std::string& text) {
    EXPECT_EQ(r.exit_status, 2) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_NE(r.err.find(message), std::string::npos) << r.err;
    EXPECT_EQ(read_file(file), text) << file;
  };
  const std::string no_campaign = "the output folder holds files of no campaign";
  for (const char* name : {"report.md", "outcomes.png", "detection_vs_size_bias.png"}) {
    const std::string out = dir.file(std::string("foreign_") + name);
    std::filesystem::create_directories(out);
    write_file(out + "/" + name, "someone's\n");
    refused(run(out), out + "/" + name + ": " + no_campaign, out + "/" + name, "someone's\n");
    EXPECT_FALSE(std::filesystem::exists(out + "/runs.csv")) << name;
  }
  // A campaign's folder whose report.md leads out of it, is write-protected or a FIFO.
  const std::string out = dir.file("out");
  ASSERT_EQ(run(out).exit_status, 0);
  const std::string report = out + "/report.md";
  const std::string elsewhere = dir.file("elsewhere.md");
  write_file(elsewhere, "elsewhere\n");
  std::filesystem::remove(report);
  std::filesystem::create_symlink(elsewhere, report);
  refused(run(out), report + ": a symbolic link out of the output folder", elsewhere, "elsewhere\n");
  std::filesystem::remove(report);
  write_file(report, "protected\n");
  std::filesystem::permissions(report, std::filesystem::perms::owner_read);
  refused(run(out), report + ": is write-protected", report, "protected\n");  // root too: no write bit
  std::filesystem::remove(report);
  ASSERT_EQ(run_shell("mkfifo " + report).exit_status, 0);
  const auto fifo = run(out);
  EXPECT_EQ(fifo.exit_status, 2) << fifo.err;
  EXPECT_NE(fifo.err.find(report + ": is a FIFO"), std::string::npos) << fifo.err;
  std::filesystem::remove(report);

  // merge: the same checks on its output folder.
  ASSERT_EQ(run_tetra("campaign " + spec + " --out " + dir.file("s1") + " --shard 1/1").exit_status, 0);
  const std::string merged = dir.file("merged");
  std::filesystem::create_directories(merged);
  write_file(merged + "/report.md", "someone's\n");
  refused(run_tetra("campaign merge " + merged + " " + dir.file("s1")), merged + "/report.md: " + no_campaign,
          merged + "/report.md", "someone's\n");
  std::filesystem::remove(merged + "/report.md");
  std::filesystem::create_symlink(elsewhere, merged + "/runs.csv");
  refused(run_tetra("campaign merge " + merged + " " + dir.file("s1")),
          merged + "/runs.csv: a symbolic link out of the output folder", elsewhere, "elsewhere\n");
  std::filesystem::remove(merged + "/runs.csv");
  const auto fine = run_tetra("campaign merge " + merged + " " + dir.file("s1"));
  EXPECT_EQ(fine.exit_status, 0) << fine.err;
}

}  // namespace
}  // namespace tetra::test
