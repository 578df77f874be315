// Runs a command line (a tool under test) through the shell, its stdout and stderr each captured
// in a file of a scratch folder, and hands back the exit code and both texts.
#pragma once

#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace sss::testing {

struct ProgramRun {
  int exit_code = -1;  // -1 when it did not exit normally
  std::string out;
  std::string err;
};

inline std::string slurp(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// command_line: the program and its arguments, as the shell reads them.
inline ProgramRun runProgram(const std::string& command_line, const std::filesystem::path& scratch_dir) {
  const std::filesystem::path out_path = scratch_dir / "stdout.txt", err_path = scratch_dir / "stderr.txt";
  const std::string command = command_line + " >" + out_path.string() + " 2>" + err_path.string();
  const int status = std::system(command.c_str());
  ProgramRun result;
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  result.out = slurp(out_path);
  result.err = slurp(err_path);
  return result;
}

}  // namespace sss::testing
