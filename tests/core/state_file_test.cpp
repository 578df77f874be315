// State files: the round trip, the atomic replacement, and every malformed file refused with a
// message (a restarted process must never resume from a torn or foreign file).
#include "pipeline/core/state_file.hpp"

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
  std::string error;
  ASSERT_TRUE(writeStateFile(path_, "demo 1", {{"next_id", "41"}, {"distance_m", "317.25"}}, error)) << error;
  ASSERT_TRUE(writeStateFile(path_, "demo 1", {{"next_id", "42"}, {"distance_m", "1e3"}}, error)) << error;
  EXPECT_FALSE(fs::exists(path_ + ".tmp"));
  StateValues values;
  ASSERT_TRUE(readStateFile(path_, "demo 1", values, error)) << error;
  long long id = 0;
  double distance_m = 0.0;
  EXPECT_TRUE(stateInteger(values, "next_id", id));
  EXPECT_EQ(id, 42);
  EXPECT_TRUE(stateNumber(values, "distance_m", distance_m));
  EXPECT_EQ(distance_m, 1000.0);
  EXPECT_FALSE(stateNumber(values, "missing", distance_m));
}

TEST_F(StateFileTest, RefusesForeignTornAndMalformedFiles) {
  StateValues values;
  std::string error;
  EXPECT_FALSE(readStateFile(path_, "demo 1", values, error));  // missing
  EXPECT_NE(error.find("cannot open"), std::string::npos) << error;
  writeRaw("demo 2\nnext_id 4\n");
  EXPECT_FALSE(readStateFile(path_, "demo 1", values, error));
  EXPECT_NE(error.find("not a 'demo 1' file"), std::string::npos) << error;
  writeRaw("demo 1\nnext_id\n");
  EXPECT_FALSE(readStateFile(path_, "demo 1", values, error));
  EXPECT_NE(error.find("line 2"), std::string::npos) << error;
  writeRaw("demo 1\nnext_id 4\nnext_id 5\n");
  EXPECT_FALSE(readStateFile(path_, "demo 1", values, error));
  EXPECT_NE(error.find("repeats"), std::string::npos) << error;
  // Values that are not numbers, or not whole ones, are not read as numbers.
  writeRaw("demo 1\nnext_id 4x\ndistance_m nan\nbig 99999999999999999999\n");
  ASSERT_TRUE(readStateFile(path_, "demo 1", values, error)) << error;
  long long id = 0;
  double distance_m = 0.0;
  EXPECT_FALSE(stateInteger(values, "next_id", id));
  EXPECT_FALSE(stateNumber(values, "distance_m", distance_m));
  EXPECT_FALSE(stateInteger(values, "big", id));
  // Keys or values that would break the line format are refused before anything is written.
  EXPECT_FALSE(writeStateFile(path_, "demo 1", {{"two words", "1"}}, error));
  EXPECT_FALSE(writeStateFile(path_, "demo 1", {{"key", "a\nb"}}, error));
  // A directory that does not exist: an error, no exception.
  EXPECT_FALSE(writeStateFile((dir_ / "no" / "state").string(), "demo 1", {{"k", "v"}}, error));
  EXPECT_NE(error.find("state.tmp: cannot open for writing"), std::string::npos) << error;
}

TEST(ResolveSystemdDirectory, ConfiguredThenTheFirstEntryOfTheEnvironmentThenNone) {
  EXPECT_EQ(resolveSystemdDirectory("/data/state", "/var/lib/sss-slam/matcher"), "/data/state");
  EXPECT_EQ(resolveSystemdDirectory("", "/var/lib/a:/var/lib/b"), "/var/lib/a");
  EXPECT_EQ(resolveSystemdDirectory("", nullptr), "");
  EXPECT_EQ(resolveSystemdDirectory("", ""), "");
}

}  // namespace
}  // namespace sss::core
