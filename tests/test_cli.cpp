// The command-line contract (docs/interfaces.md §3): help everywhere, exit 2 on bad usage.
#include <gtest/gtest.h>

#include "test_support.hpp"

namespace tetra {
namespace {

TEST(Cli, HelpListsEveryCommand) {
  const auto r = test::run_tetra("help");
  EXPECT_EQ(r.exit_status, 0);
  for (const char* c :
       {"calibrate", "allan", "sim", "replay", "fusion", "monitor", "command", "record", "demo"}) {
    EXPECT_NE(r.out.find(c), std::string::npos) << c;
  }
}

TEST(Cli, UnknownCommandIsBadUsage) {
  const auto r = test::run_tetra("frobnicate");
  EXPECT_EQ(r.exit_status, 2);
  EXPECT_NE(r.err.find("unknown command 'frobnicate'"), std::string::npos);
  EXPECT_EQ(test::run_tetra("").exit_status, 2);
}

}  // namespace
}  // namespace tetra
