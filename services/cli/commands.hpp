#pragma once
// Entry points of the `tetra` subcommands. Each takes the arguments after "tetra" (argv[0] is the
// subcommand's name) and returns the process exit status.

namespace tetra::cli {

int cmd_calibrate(int argc, char** argv);
int cmd_allan(int argc, char** argv);
int cmd_sim(int argc, char** argv);
int cmd_replay(int argc, char** argv);
int cmd_convert(int argc, char** argv);
int cmd_fusion(int argc, char** argv);
int cmd_monitor(int argc, char** argv);
int cmd_command(int argc, char** argv);
int cmd_record(int argc, char** argv);
int cmd_play(int argc, char** argv);
int cmd_ingest(int argc, char** argv);
int cmd_demo(int argc, char** argv);
int cmd_campaign(int argc, char** argv);
//! `tetra campaign merge OUT SHARD_DIRS...` (argv[0] is "merge").
int cmd_campaign_merge(int argc, char** argv);
int cmd_ground(int argc, char** argv);
int cmd_ground_passwd(int argc, char** argv);
int cmd_score(int argc, char** argv);

}  // namespace tetra::cli
