// One command-line behaviour for every program (command_line.hpp): the values land where declared;
// --help prints the usage on stdout and gives 0; every kind of bad command line gives 2 and says
// which flag and why on stderr.
#include "pipeline/transport/command_line.hpp"
#include "pipeline/transport/process_options.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace sss::cli {
namespace {

struct Parsed {
  int exit_code = -1;
  std::string out, err;
  std::string path;
  double speed_m_s = 1.0;
  int count = 3;
  bool verbose = false;
  std::vector<double> pair;
  double min_m = -1.0, max_m = -1.0;
};

Parsed parse(std::vector<std::string> arguments) {
  Parsed parsed;
  CommandLine command_line("sss-test", "a test program", "More words after the flags.");
  command_line.add_option("--path", parsed.path, "a path")->required();
  command_line.add_option("--speed-m-s", parsed.speed_m_s, "a speed")->check(positive());
  command_line.add_option("--count", parsed.count, "a count")->check(nonNegative());
  command_line.add_flag("--verbose", parsed.verbose, "say more");
  command_line.add_option("--pair", parsed.pair, "A,B")->delimiter(',')->expected(2);
  addIncreasingPair(command_line, "--range-m", parsed.min_m, parsed.max_m, "MIN,MAX", nonNegative());
  arguments.insert(arguments.begin(), "sss-test");
  std::vector<const char*> argv;
  for (const std::string& argument : arguments) argv.push_back(argument.c_str());
  testing::internal::CaptureStdout();
  testing::internal::CaptureStderr();
  parsed.exit_code = parseCommandLine(command_line, static_cast<int>(argv.size()), argv.data());
  parsed.out = testing::internal::GetCapturedStdout();
  parsed.err = testing::internal::GetCapturedStderr();
  return parsed;
}

TEST(CommandLine, ValuesLandWhereDeclared) {
  const Parsed parsed = parse({"--path", "/tmp/a b", "--speed-m-s", "2.5", "--count=0", "--verbose", "--pair", "1,-2"});
  EXPECT_EQ(parsed.exit_code, -1);
  EXPECT_EQ(parsed.path, "/tmp/a b");
  EXPECT_DOUBLE_EQ(parsed.speed_m_s, 2.5);
  EXPECT_EQ(parsed.count, 0);
  EXPECT_TRUE(parsed.verbose);
  EXPECT_EQ(parsed.pair, (std::vector<double>{1.0, -2.0}));
  EXPECT_DOUBLE_EQ(parse({"--path", "x", "--range-m", "10,70.5"}).max_m, 70.5);
  EXPECT_DOUBLE_EQ(parse({"--path", "x", "--range-m", "10,70.5"}).min_m, 10.0);
  EXPECT_EQ(parsed.out + parsed.err, "");
  const Parsed defaults = parse({"--path", "x"});
  EXPECT_DOUBLE_EQ(defaults.speed_m_s, 1.0);  // what the program set stays unless given
  EXPECT_EQ(defaults.count, 3);
  EXPECT_FALSE(defaults.verbose);
  EXPECT_EQ(defaults.min_m, -1.0);
}

TEST(CommandLine, HelpGoesToStdoutWithExitZero) {
  for (const char* help : {"--help", "-h"}) {
    const Parsed parsed = parse({help});  // even without the required --path
    EXPECT_EQ(parsed.exit_code, 0);
    EXPECT_NE(parsed.out.find("a test program"), std::string::npos) << parsed.out;
    EXPECT_NE(parsed.out.find("--speed-m-s"), std::string::npos) << parsed.out;
    EXPECT_NE(parsed.out.find("More words after the flags."), std::string::npos) << parsed.out;
    EXPECT_EQ(parsed.err, "");
  }
}

TEST(CommandLine, EveryBadCommandLineExitsTwoAndSaysWhy) {
  struct Case {
    std::vector<std::string> arguments;
    std::string says;
  };
  const std::vector<Case> cases = {
      {{}, "--path is required"},
      {{"--path"}, "--path"},                                    // no value
      {{"--path", "x", "--bogus"}, "--bogus"},                   // unknown flag
      {{"--path", "x", "stray"}, "stray"},                       // stray argument
      {{"--path", "x", "--speed-m-s", "fast"}, "fast"},          // not a number
      {{"--path", "x", "--speed-m-s", "0"}, "must be > 0, got 0"},
      {{"--path", "x", "--count", "-1"}, "must be >= 0, got -1"},
      {{"--path", "x", "--count", "1.5"}, "1.5"},                // not an integer
      {{"--path", "x", "--count", "1", "--count", "2"}, "--count"},  // given twice
      {{"--path", "x", "--pair", "1,2,3"}, "--pair"},            // three values for two
      {{"--path", "x", "--range-m", "70,10"}, "MIN < MAX, got 70,10"},
      {{"--path", "x", "--range-m", "-1,10"}, "must be >= 0, got -1"},
  };
  for (const Case& c : cases) {
    const Parsed parsed = parse(c.arguments);
    EXPECT_EQ(parsed.exit_code, 2) << c.says;
    EXPECT_NE(parsed.err.find("sss-test: "), std::string::npos) << parsed.err;
    EXPECT_NE(parsed.err.find(c.says), std::string::npos) << "expected '" << c.says << "' in: " << parsed.err;
    EXPECT_NE(parsed.err.find("Usage:"), std::string::npos) << parsed.err;  // and how to call it
    EXPECT_EQ(parsed.out, "");
  }
}

TEST(CommandLine, NodeFlagsAreSharedByEveryProcess) {
  transport::NodeArguments arguments;
  const char* argv[] = {"sss-node", "--config", "a.yaml", "--check-config", "--lcm-url", "memq://"};
  EXPECT_EQ(transport::parseNodeArguments("sss-node", "a node", 6, const_cast<char**>(argv), arguments), -1);
  EXPECT_EQ(arguments.config_path, "a.yaml");
  EXPECT_TRUE(arguments.check_config_only);
  EXPECT_EQ(arguments.lcm_url_override, "memq://");
  transport::NodeArguments bad;
  const char* bad_argv[] = {"sss-node", "--file", "x"};
  testing::internal::CaptureStderr();
  EXPECT_EQ(transport::parseNodeArguments("sss-node", "a node", 3, const_cast<char**>(bad_argv), bad), 2);
  EXPECT_NE(testing::internal::GetCapturedStderr().find("--file"), std::string::npos);
}

}  // namespace
}  // namespace sss::cli
