// pneuma-cli conventions: --version, --help, exit code 2 with a one-line error for bad usage.
#include <string>

#include "CliRunner.h"

using pneuma::test::runCli;

TEST(CliMain, VersionPrintsProjectVersion) {
  auto r = runCli({"--version"});
  EXPECT_EQ(r.exitCode, 0);
  EXPECT_EQ(r.out, std::string("pneuma-cli ") + PNEUMA_VERSION + "\n");
}

TEST(CliMain, HelpListsSubcommandsAndExitsZero) {
  auto r = runCli({"--help"});
  EXPECT_EQ(r.exitCode, 0);
  EXPECT_NE(r.out.find("Usage:"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("--version"), std::string::npos) << r.out;
}

TEST(CliMain, UnknownOptionIsOneLineErrorPlusUsageExit2) {
  auto r = runCli({"--no-such-option"});
  EXPECT_EQ(r.exitCode, 2);
  EXPECT_EQ(r.err.rfind("pneuma-cli: error: ", 0), 0u) << r.err;
  EXPECT_NE(r.err.find("--no-such-option"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("Usage: pneuma-cli"), std::string::npos) << r.err;
  EXPECT_LE(pneuma::test::lineCount(r.err), 3) << r.err;
  EXPECT_TRUE(r.out.empty());
}

TEST(CliMain, UnknownSubcommandExits2) {
  auto r = runCli({"frobnicate"});
  EXPECT_EQ(r.exitCode, 2);
  EXPECT_NE(r.err.find("frobnicate"), std::string::npos) << r.err;
}

TEST(CliMain, MissingSubcommandExits2) {
  auto r = runCli({});
  EXPECT_EQ(r.exitCode, 2);
  EXPECT_EQ(r.err.rfind("pneuma-cli: error: ", 0), 0u) << r.err;
}
