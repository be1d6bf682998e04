// The command line's help, version and dispatch, run through the real binary.
#include <gtest/gtest.h>

#include "app/version.hpp"
#include "app_test_support.hpp"

namespace arcsim::app_test {
namespace {

// Exit code 2 with exactly one stderr line that starts "arcsim: " and contains `needle`; nothing on stdout.
void expect_usage_error(const RunResult& r, const std::string& needle) {
  EXPECT_EQ(r.exit_code, 2) << r.err;
  const std::vector<std::string> lines = lines_of(r.err);
  ASSERT_EQ(lines.size(), 1u) << r.err;
  EXPECT_EQ(lines[0].rfind("arcsim: ", 0), 0u) << lines[0];
  EXPECT_NE(lines[0].find(needle), std::string::npos) << lines[0];
  EXPECT_EQ(r.out, "");
}

TEST(CommandLine, HelpListsTheCommandsAndExitsZero) {
  ARCSIM_REQUIRE_BINARY();
  for (const char* flag : {"--help", "-h", "help"}) {
    const RunResult r = run_arcsim({flag});
    EXPECT_EQ(r.exit_code, 0) << flag << ": " << r.err;
    EXPECT_NE(r.out.find("Usage: arcsim <command>"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("simulate"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("--version"), std::string::npos) << r.out;
    EXPECT_EQ(r.err, "");
  }
}

TEST(CommandLine, CommandHelpTwoWaysAgree) {
  ARCSIM_REQUIRE_BINARY();
  const RunResult via_help = run_arcsim({"help", "simulate"});
  const RunResult via_flag = run_arcsim({"simulate", "--help"});
  const RunResult anywhere = run_arcsim({"simulate", "scene-that-does-not-exist.json", "-h"});
  EXPECT_EQ(via_help.exit_code, 0);
  EXPECT_EQ(via_flag.exit_code, 0);
  EXPECT_EQ(anywhere.exit_code, 0);
  EXPECT_EQ(via_help.out, via_flag.out);
  EXPECT_EQ(via_help.out, anywhere.out);
  EXPECT_EQ(via_help.out.rfind("Usage: arcsim simulate <scene.json> [<out-dir>]", 0), 0u) << via_help.out;
  for (const char* option : {"--end-time", "--end-frame", "--threads", "--quiet", "--progress json"})
    EXPECT_NE(via_help.out.find(option), std::string::npos) << option;
}

TEST(CommandLine, VersionComesFromVersionHeader) {
  ARCSIM_REQUIRE_BINARY();
  const RunResult r = run_arcsim({"--version"});
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_EQ(r.out, std::string("arcsim ") + kVersion + "\n");
  EXPECT_EQ(r.err, "");
}

TEST(CommandLine, UsageErrorsExitTwoWithOneLine) {
  ARCSIM_REQUIRE_BINARY();
  expect_usage_error(run_arcsim({}), "no command");
  expect_usage_error(run_arcsim({"simulat"}), "unknown command 'simulat'");
  expect_usage_error(run_arcsim({"--frobnicate"}), "unknown option '--frobnicate'");
  expect_usage_error(run_arcsim({"help", "nonsense"}), "unknown command 'nonsense'");
  expect_usage_error(run_arcsim({"simulate"}), "missing the scene file");
  expect_usage_error(run_arcsim({"simulate", "a.json", "out", "extra"}), "unexpected argument 'extra'");
  expect_usage_error(run_arcsim({"simulate", "a.json", "--fast"}), "unknown option '--fast'");
  expect_usage_error(run_arcsim({"simulate", "a.json", "--end-time"}), "--end-time needs a value");
  expect_usage_error(run_arcsim({"simulate", "a.json", "--quiet=yes"}), "--quiet takes no value");
}

TEST(CommandLine, BadOptionValuesExitTwoNamingTheOption) {
  ARCSIM_REQUIRE_BINARY();
  // The scene need not exist: options are checked first.
  expect_usage_error(run_arcsim({"simulate", "a.json", "--end-time", "soon"}), "--end-time: expected a number");
  expect_usage_error(run_arcsim({"simulate", "a.json", "--end-time=-1"}), "got '-1'");
  expect_usage_error(run_arcsim({"simulate", "a.json", "--end-time", "nan"}), "--end-time");
  expect_usage_error(run_arcsim({"simulate", "a.json", "--end-time", "1e999"}), "--end-time");
  expect_usage_error(run_arcsim({"simulate", "a.json", "--end-frame", "2.5"}), "--end-frame: expected an integer");
  expect_usage_error(run_arcsim({"simulate", "a.json", "--threads", "0"}), "--threads: expected an integer in [1,");
  expect_usage_error(run_arcsim({"simulate", "a.json", "--threads", "99999999999999999999"}), "--threads");
  expect_usage_error(run_arcsim({"simulate", "a.json", "--progress", "xml"}), "--progress");
}

}  // namespace
}  // namespace arcsim::app_test
