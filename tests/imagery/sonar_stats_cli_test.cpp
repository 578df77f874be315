// sss-sonar-stats end to end: a simulated JSF gives its figures, JSON and a waterfall PNG; bad
// arguments exit 2, a file with no side-scan ping exits 1 and says what to try.
#include "tools/sim/mission.hpp"
#include "tests/support/status_assertions.hpp"

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include <sys/wait.h>
#include <unistd.h>

namespace {

namespace fs = std::filesystem;

struct ToolRun {
  int exit_code = -1;
  std::string output;  // stdout and stderr
};

ToolRun run(const std::string& arguments) {
  const fs::path log = fs::temp_directory_path() / ("sss_sonar_stats_cli_" + std::to_string(::getpid()) + ".log");
  const std::string command = std::string(SSS_SONAR_STATS_PATH) + " " + arguments + " > " + log.string() + " 2>&1";
  const int status = std::system(command.c_str());
  ToolRun result;
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  std::ifstream in(log);
  result.output.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  fs::remove(log);
  return result;
}

fs::path scratch(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("sss_sonar_stats_cli_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

TEST(SonarStatsCli, SimulatedJsfGivesFiguresJsonAndAWaterfall) {
  const fs::path dir = scratch("jsf");
  sss::sim::SimOptions options;
  options.trajectory.lines = 1;
  options.trajectory.line_length_m = 60.0;
  options.duration_s = 20.0;  // 81 pings
  options.seabed.resolution_m = 0.2;
  options.sonar.samples_per_side = 2000;
  sss::sim::MissionReport report;
  ASSERT_OK(sss::sim::writeMission(sss::sim::Mission(options), (dir / "mission").string(), report));
  const ToolRun r = run("--sonar " + (dir / "mission" / "sonar.jsf").string() + " --json " + (dir / "s.json").string() +
                    " --waterfall " + (dir / "w.png").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("pings 81, range 75.0 m"), std::string::npos) << r.output;
  // What the reader found: type 80 only, no layback (the simulator's AUV carries its sonar).
  EXPECT_NE(r.output.find("older message 82: 0; records with a towfish layback: 0;"), std::string::npos) << r.output;
  std::ifstream json(dir / "s.json");
  const std::string text((std::istreambuf_iterator<char>(json)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("\"speckle_std_over_mean\""), std::string::npos);
  EXPECT_NE(text.find("\"pings\": 81"), std::string::npos) << text;
  EXPECT_GT(fs::file_size(dir / "w.png"), 1000u);
  // The same file read for the high-frequency subsystem holds nothing and says what to try.
  const ToolRun other = run("--sonar " + (dir / "mission" / "sonar.jsf").string() + " --subsystem 21");
  EXPECT_EQ(other.exit_code, 1);
  EXPECT_NE(other.output.find("no side-scan ping of subsystem 21"), std::string::npos) << other.output;
  fs::remove_all(dir);
}

TEST(SonarStatsCli, BadInputIsNamedAndExitsNonZero) {
  const fs::path dir = scratch("bad");
  EXPECT_EQ(run("").exit_code, 2);
  EXPECT_EQ(run("--sonar").exit_code, 2);
  EXPECT_EQ(run("--sonar x.jsf --block 1,2").exit_code, 2);
  const ToolRun missing = run("--sonar " + (dir / "absent.jsf").string());
  EXPECT_EQ(missing.exit_code, 2);
  EXPECT_NE(missing.output.find("cannot open"), std::string::npos) << missing.output;
  {
    std::ofstream garbage(dir / "garbage.jsf", std::ios::binary);
    for (int i = 0; i < 100000; ++i) garbage.put(static_cast<char>((i * 7919) & 0xff));
  }
  const ToolRun none = run("--sonar " + (dir / "garbage.jsf").string());
  EXPECT_EQ(none.exit_code, 1) << none.output;
  EXPECT_NE(none.output.find("holds no side-scan ping"), std::string::npos) << none.output;
  fs::remove_all(dir);
}

}  // namespace
