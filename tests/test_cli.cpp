// The command-line contract (docs/interfaces.md §3): help everywhere, exit 2 on bad usage.
#include <gtest/gtest.h>

#include "test_support.hpp"

namespace tetra {
namespace {

TEST(Cli, HelpListsEveryCommand) {
  const auto r = test::run_tetra("help");
  EXPECT_EQ(r.exit_status, 0);
  for (const char* c : {"calibrate", "allan", "sim", "replay", "fusion", "monitor", "command", "record",
                        "play", "ingest", "demo"}) {
    EXPECT_NE(r.out.find(c), std::string::npos) << c;
  }
}

TEST(Cli, UnknownCommandIsBadUsage) {
  const auto r = test::run_tetra("frobnicate");
  EXPECT_EQ(r.exit_status, 2);
  EXPECT_NE(r.err.find("unknown command 'frobnicate'"), std::string::npos);
  EXPECT_EQ(test::run_tetra("").exit_status, 2);
}

TEST(Cli, HelpOfAnUnknownCommandIsBadUsage) {
  const auto r = test::run_tetra("help frobnicate");
  EXPECT_EQ(r.exit_status, 2);
  EXPECT_EQ(r.err, "tetra help: unknown command 'frobnicate' (tetra help lists them)\n");
  EXPECT_EQ(test::run_tetra("help sim").exit_status, 0);
}

TEST(Cli, VersionEverywhere) {
  const auto r = test::run_tetra("--version");
  EXPECT_EQ(r.exit_status, 0);
  EXPECT_EQ(r.out, std::string("tetra ") + TETRA_VERSION + "\n");
  EXPECT_EQ(test::run_tetra("sim --version").out, r.out);
}

TEST(Cli, SingleValuedOptionGivenTwiceIsRefusedNamingIt) {
  const auto r = test::run_tetra("sim static --minutes 1 --minutes 2 -o /dev/null");
  EXPECT_EQ(r.exit_status, 2);
  EXPECT_NE(r.err.find("--minutes"), std::string::npos) << r.err;
}

// A user name may start with '-' (docs/ground.md, "Accounts"), and as the first argument it reads as an
// option: the help and the docs show it after "--", and that command works.
TEST(Cli, GroundPasswdTakesANameStartingWithADashAfterDoubleDash) {
  test::TempDir dir;
  test::write_file(dir.file("pw"), "correct horse\n");
  const std::string users = dir.file("users");
  const std::string tail = " --password-stdin < " + dir.file("pw");
  EXPECT_EQ(test::run_tetra("ground passwd -x --users " + users + tail).exit_status, 2);
  const auto help = test::run_tetra("ground passwd --help");
  EXPECT_NE(help.out.find("ground passwd --users FILE -- -x"), std::string::npos) << help.out;
  const auto added = test::run_tetra("ground passwd --users " + users + tail + " -- -x");
  EXPECT_EQ(added.exit_status, 0) << added.err;
  const std::string accounts = test::read_file(users);
  EXPECT_NE(accounts.find("\n-x:viewer:$argon2id$"), std::string::npos) << accounts;
}

}  // namespace
}  // namespace tetra
