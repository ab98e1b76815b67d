// The commands' work called as library functions (tetra/report/*.hpp): the same files as the command
// line's, typed results, and errors that carry the argument as their subject instead of naming an option.
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "test_support.hpp"
#include "tetra/report/allan_report.hpp"
#include "tetra/report/convert_log.hpp"
#include "tetra/report/replay_log.hpp"
#include "tetra/report/score_report.hpp"
#include "tetra/report/sim_files.hpp"

namespace tetra::report {
namespace {

using test::read_file;
using test::run_tetra;
using test::TempDir;

// A file's text without the provenance lines that name the process (its command line and run time).
std::string without_run_lines(const std::string& text) {
  std::istringstream in(text);
  std::string out;
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("# command=", 0) == 0 || line.rfind("# created_utc=", 0) == 0) continue;
    out += line + '\n';
  }
  return out;
}

// A one-minute static run at 20 Hz with a stuck gyro: small, and the pipeline has something to do.
SimRunOptions static_run(const std::string& out_path) {
  SimRunOptions o;
  o.scenario = "static";
  o.seed = 5;
  o.out_path = out_path;
  o.overrides.duration_min = 1.0;
  o.overrides.rate_hz = 20.0;
  o.faults = {"gyro=3,kind=stuck,at=30"};
  return o;
}

TEST(ReportLibrary, SimulationAndReplayWriteWhatTheCommandLineWrites) {
  TempDir dir;
  std::ostringstream notes;
  auto simulated = simulate_to_files(static_run(dir.file("lib.csv")), notes);
  ASSERT_TRUE(simulated) << simulated.error().message;
  EXPECT_EQ(simulated->epochs, 1200u);  // 60 s at 20 Hz
  EXPECT_EQ(simulated->gyros, 4);
  ASSERT_EQ(run_tetra("sim static --seed 5 --minutes 1 --rate-hz 20 --fault gyro=3,kind=stuck,at=30 -o " +
                      dir.file("cli.csv"))
                .exit_status,
            0);
  EXPECT_EQ(without_run_lines(read_file(dir.file("lib.csv"))),
            without_run_lines(read_file(dir.file("cli.csv"))));

  auto unit = write_simulated_unit("", dir.file("unit.yaml"), {}, notes);
  ASSERT_TRUE(unit) << unit.error().message;
  ReplayLogOptions replay;
  replay.log_path = dir.file("lib.csv");
  replay.calibration_path = dir.file("unit.yaml");
  replay.attitude_path = dir.file("att_lib.csv");
  replay.events_path = dir.file("ev_lib.jsonl");
  std::ostringstream summary;
  auto replayed = replay_log(replay, summary);
  ASSERT_TRUE(replayed) << replayed.error().message;
  EXPECT_EQ(replayed->epochs, 1200u);
  EXPECT_EQ(replayed->event_counts["isolated"], 1);
  EXPECT_EQ(replayed->health.gyros[2].state, fdi::GyroState::kExcluded);
  ASSERT_EQ(run_tetra("replay " + dir.file("lib.csv") + " --calibration " + dir.file("unit.yaml") +
                      " --attitude " + dir.file("att_cli.csv") + " --events " + dir.file("ev_cli.jsonl"))
                .exit_status,
            0);
  // Bit for bit: the same pipeline over the same log, whoever calls it.
  EXPECT_EQ(read_file(dir.file("ev_lib.jsonl")), read_file(dir.file("ev_cli.jsonl")));
  EXPECT_EQ(without_run_lines(read_file(dir.file("att_lib.csv"))),
            without_run_lines(read_file(dir.file("att_cli.csv"))));
}

TEST(ReportLibrary, ConvertRoundTripAndAllanTable) {
  TempDir dir;
  std::ostringstream notes;
  ASSERT_TRUE(simulate_to_files(static_run(dir.file("log.csv")), notes));
  auto to_h5 = convert_gyro_log({dir.file("log.csv"), dir.file("log.h5"), true, {}});
  ASSERT_TRUE(to_h5) << to_h5.error().message;
  EXPECT_EQ(to_h5->epochs, 1200u);
  ASSERT_TRUE(convert_gyro_log({dir.file("log.h5"), dir.file("back.csv"), false, {}}));
  EXPECT_EQ(read_file(dir.file("back.csv")), read_file(dir.file("log.csv")));

  AllanReportOptions allan;
  allan.log_path = dir.file("log.csv");
  allan.taus = "octave";
  allan.csv_path = dir.file("allan.csv");
  std::ostringstream table;
  std::ostringstream allan_notes;
  auto report = write_allan_report(allan, table, allan_notes);
  ASSERT_TRUE(report) << report.error().message;
  EXPECT_EQ(report->analysis.gyros.size(), 4u);
  EXPECT_FALSE(report->calibration_updated);
  EXPECT_NE(table.str().find("1200 epochs"), std::string::npos) << table.str();
  EXPECT_TRUE(allan_notes.str().empty()) << allan_notes.str();  // no progress asked for
}

TEST(ReportLibrary, ErrorsCarryTheArgumentNotAnOption) {
  TempDir dir;
  AllanReportOptions allan;
  allan.log_path = dir.file("none.csv");
  allan.confidence = 1.5;
  std::ostringstream out;
  auto a = write_allan_report(allan, out, out);
  ASSERT_FALSE(a);
  EXPECT_EQ(a.error().kind, ErrorKind::kBadInput);
  EXPECT_EQ(a.error().subject, ErrorSubject("confidence", "1.5"));
  EXPECT_EQ(a.error().message.find("--"), std::string::npos) << a.error().message;

  ScoreReportOptions score;
  score.attitude_path = dir.file("att.csv");
  score.truth_path = dir.file("truth.csv");
  score.axis = "0,0,0";
  auto s = write_score_report(score, out);
  ASSERT_FALSE(s);
  EXPECT_EQ(s.error().subject, ErrorSubject(kSubjectAxis, "0,0,0"));

  SimRunOptions sim = static_run("");
  auto no_out = simulate_to_files(sim, out);
  ASSERT_FALSE(no_out);
  EXPECT_EQ(no_out.error().subject.name, kSubjectMissingOut);

  ReplayLogOptions replay;
  replay.log_path = dir.file("none.csv");
  replay.calibration_path = dir.file("none.yaml");
  replay.attitude_path = dir.file("att.csv");
  replay.events_path = dir.file("ev.jsonl");
  replay.initial_q = "1,0,0";
  auto r = replay_log(replay, out);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().subject.name, kSubjectInitialQ);
  // Nothing was written: a failed run leaves no output behind.
  EXPECT_FALSE(std::filesystem::exists(dir.file("att.csv")));
}

}  // namespace
}  // namespace tetra::report
