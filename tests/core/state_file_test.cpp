// State files: the round trip, the atomic replacement, and every malformed file refused with a
// message (a restarted process must never resume from a torn or foreign file).
#include "pipeline/core/state_file.hpp"

#include "tests/support/status_assertions.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

namespace sss::core {
namespace {

namespace fs = std::filesystem;

class StateFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("sss_state_file_test_" + std::to_string(getpid()));
    fs::create_directories(dir_);
    path_ = (dir_ / "state").string();
  }
  void TearDown() override { fs::remove_all(dir_); }
  void writeRaw(const std::string& text) { std::ofstream(path_, std::ios::binary) << text; }

  fs::path dir_;
  std::string path_;
};

TEST_F(StateFileTest, RoundTripAndReplacement) {
  ASSERT_OK(writeStateFile(path_, "demo 1", {{"next_id", "41"}, {"distance_m", "317.25"}}));
  ASSERT_OK(writeStateFile(path_, "demo 1", {{"next_id", "42"}, {"distance_m", "1e3"}}));
  EXPECT_FALSE(fs::exists(path_ + ".tmp"));
  const Result<StateValues> read = readStateFile(path_, "demo 1");
  ASSERT_OK(read);
  const StateValues& values = read.value();
  long long id = 0;
  double distance_m = 0.0;
  EXPECT_TRUE(stateInteger(values, "next_id", id));
  EXPECT_EQ(id, 42);
  EXPECT_TRUE(stateNumber(values, "distance_m", distance_m));
  EXPECT_EQ(distance_m, 1000.0);
  EXPECT_FALSE(stateNumber(values, "missing", distance_m));
}

TEST_F(StateFileTest, RefusesForeignTornAndMalformedFiles) {
  Result<StateValues> read = readStateFile(path_, "demo 1");
  EXPECT_FALSE(read.ok());  // missing
  EXPECT_NE(read.message().find("cannot open"), std::string::npos) << read.message();
  writeRaw("demo 2\nnext_id 4\n");
  read = readStateFile(path_, "demo 1");
  EXPECT_FALSE(read.ok());
  EXPECT_NE(read.message().find("not a 'demo 1' file"), std::string::npos) << read.message();
  writeRaw("demo 1\nnext_id\n");
  read = readStateFile(path_, "demo 1");
  EXPECT_FALSE(read.ok());
  EXPECT_NE(read.message().find("line 2"), std::string::npos) << read.message();
  writeRaw("demo 1\nnext_id 4\nnext_id 5\n");
  read = readStateFile(path_, "demo 1");
  EXPECT_FALSE(read.ok());
  EXPECT_NE(read.message().find("repeats"), std::string::npos) << read.message();
  // Values that are not numbers, or not whole ones, are not read as numbers.
  writeRaw("demo 1\nnext_id 4x\ndistance_m nan\nbig 99999999999999999999\n");
  read = readStateFile(path_, "demo 1");
  ASSERT_OK(read);
  const StateValues& values = read.value();
  long long id = 0;
  double distance_m = 0.0;
  EXPECT_FALSE(stateInteger(values, "next_id", id));
  EXPECT_FALSE(stateNumber(values, "distance_m", distance_m));
  EXPECT_FALSE(stateInteger(values, "big", id));
  // Keys or values that would break the line format are refused before anything is written.
  EXPECT_FALSE(writeStateFile(path_, "demo 1", {{"two words", "1"}}).ok);
  EXPECT_FALSE(writeStateFile(path_, "demo 1", {{"key", "a\nb"}}).ok);
  // A directory that does not exist: an error, no exception.
  const Status written = writeStateFile((dir_ / "no" / "state").string(), "demo 1", {{"k", "v"}});
  EXPECT_FALSE(written.ok);
  EXPECT_NE(written.message.find("state.tmp: cannot open for writing"), std::string::npos) << written.message;
}

TEST(ResolveSystemdDirectory, ConfiguredThenTheFirstEntryOfTheEnvironmentThenNone) {
  EXPECT_EQ(resolveSystemdDirectory("/data/state", "/var/lib/sss-slam/matcher"), "/data/state");
  EXPECT_EQ(resolveSystemdDirectory("", "/var/lib/a:/var/lib/b"), "/var/lib/a");
  EXPECT_EQ(resolveSystemdDirectory("", nullptr), "");
  EXPECT_EQ(resolveSystemdDirectory("", ""), "");
}

}  // namespace
}  // namespace sss::core
