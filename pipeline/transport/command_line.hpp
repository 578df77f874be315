// Command lines of every sss program, declared with CLI11 and parsed with one behaviour:
//   --help (-h): the usage on stdout, exit 0;
//   an unknown flag, a missing value, a value that is not of the flag's type or outside its range,
//   a stray argument: the reason and the usage on stderr, exit 2 (bad input, as everywhere here).
// A program declares its flags on a CommandLine (a CLI::App: names, types, checks such as
// CLI::Range, help text) and calls parseCommandLine before anything else; main() returns the code
// when it is >= 0.
#pragma once

#include <string>

#include <CLI/CLI.hpp>

namespace sss::cli {

// The App every program starts from: its name, what it does (first line of --help) and the longer
// explanation printed after the flags (empty: none). A flag is given at most once.
class CommandLine : public CLI::App {
 public:
  CommandLine(const std::string& program, const std::string& description, const std::string& footer = "");
};

// Checks for numeric flags with plain messages ("--seed: must be >= 0, got -1"; CLI11's own
// NonNegativeNumber quotes the largest double as its upper bound).
CLI::Validator nonNegative();
CLI::Validator positive();

// A MIN,MAX flag (--lce-swath-m 10,70): two numbers, each passing check, MIN < MAX; sets min and
// max only when given.
CLI::Option* addIncreasingPair(CLI::App& app, const std::string& name, double& min, double& max,
                               const std::string& description, const CLI::Validator& check);

// -1: parsed, go on; otherwise the exit code for main() (0 after --help, 2 for a bad command line).
int parseCommandLine(CLI::App& app, int argc, const char* const* argv);

}  // namespace sss::cli
