// The matcher's state directory on hand-built subframes: files round-trip exactly, every flipped
// byte and every truncation is refused with the file's name, ids come only from well-formed names,
// and the figures (bytes per subframe, write and restore times) at the deployment's size.
#include "pipeline/matcher/matcher_state.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "pipeline/matcher/matcher_engine.hpp"
#include "tests/support/status_assertions.hpp"

namespace sss::matcher {
namespace {

namespace fs = std::filesystem;
using sss::core::Pose;

// A straight subframe flown north with every pixel different, so a misplaced byte cannot go unseen.
sss::core::Subframe testSubframe(int64_t id, int rows, int bins_per_side, double east_m = 0.0) {
  sss::core::Subframe s;
  s.id = id;
  s.line_id = static_cast<int>(id / 2);
  s.centre_ping_index = rows / 2;
  s.geometry.bins_per_side = bins_per_side;
  s.geometry.bin_size_m = 0.13;
  s.geometry.first_bin_range_m = 0.065;
  s.geometry.T_body_sonar = Pose(sss::core::quaternionFromEuler(0.01, -0.02, 0.0), Eigen::Vector3d(0.5, 0.0, 0.3));
  for (int r = 0; r < rows; ++r) {
    sss::core::SubframePing ping;
    ping.utime_us = 1700000000000000 + 250000 * (id * rows + r);
    ping.ping_number = id * rows + r;
    ping.T_world_body = Pose(sss::core::quaternionFromEuler(0.001 * r, 0.002, 0.1 + 1e-4 * r),
                             Eigen::Vector3d(0.5 * r + 1.0 / 3.0, east_m, 20.0 + 1e-3 * r));
    ping.altitude_m = 18.0 + 0.01 * r;
    ping.distance_travelled_m = 100.0 * id + 0.5 * r;
    s.pings.push_back(ping);
  }
  const size_t pixels = static_cast<size_t>(rows) * 2 * bins_per_side;
  s.image.resize(pixels);
  s.mask.resize(pixels);
  for (size_t i = 0; i < pixels; ++i) {
    s.image[i] = 1.0f + 0.5f * static_cast<float>(std::sin(0.37 * static_cast<double>(i)));
    s.mask[i] = static_cast<uint8_t>(i % 7 == 0 ? 1 : 0);
  }
  return s;
}

size_t subframeFileBytes(int rows, int bins_per_side) {
  // magic 16, header 96, 88 per ping, 5 per pixel (float + mask), checksum 8
  return 16 + 96 + 88 * static_cast<size_t>(rows) + 5 * static_cast<size_t>(rows) * 2 * bins_per_side + 8;
}

bool samePose(const Pose& a, const Pose& b) {
  return a.translation == b.translation && a.rotation.coeffs() == b.rotation.coeffs();
}

std::string readBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}
void writeBytes(const std::string& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
}
// In place: rewriting the whole file for each of hundreds of cases is slow on some file systems.
void patchByte(const std::string& path, size_t offset, char value) {
  std::fstream file(path, std::ios::binary | std::ios::in | std::ios::out);
  file.seekp(static_cast<std::streamoff>(offset));
  file.put(value);
}

class MatcherStateStoreTest : public ::testing::Test {
 protected:
  void SetUp() override {
    fs::remove_all(dir_);
    ASSERT_OK(store_.open());
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string dir_ = (fs::temp_directory_path() / ("sss_matcher_state_test_" + std::to_string(getpid()))).string();
  MatcherStateStore store_{dir_};
};

TEST_F(MatcherStateStoreTest, SubframeFileRoundTripsExactly) {
  const sss::core::Subframe s = testSubframe(42, 20, 30);
  ASSERT_OK(store_.writeSubframe(s));
  EXPECT_EQ(fs::file_size(store_.subframePath(42)), subframeFileBytes(20, 30));
  EXPECT_FALSE(fs::exists(store_.subframePath(42) + ".tmp"));
  const auto read = store_.readSubframe(42);
  ASSERT_OK(read);
  ASSERT_TRUE(read->has_value());
  const sss::core::Subframe& back = **read;
  EXPECT_EQ(back.id, 42);
  EXPECT_EQ(back.line_id, s.line_id);
  EXPECT_EQ(back.centre_ping_index, s.centre_ping_index);
  EXPECT_EQ(back.geometry.bins_per_side, 30);
  EXPECT_EQ(back.geometry.bin_size_m, s.geometry.bin_size_m);
  EXPECT_EQ(back.geometry.first_bin_range_m, s.geometry.first_bin_range_m);
  EXPECT_TRUE(samePose(back.geometry.T_body_sonar, s.geometry.T_body_sonar));
  ASSERT_EQ(back.pings.size(), s.pings.size());
  for (size_t r = 0; r < s.pings.size(); ++r) {
    EXPECT_EQ(back.pings[r].utime_us, s.pings[r].utime_us);
    EXPECT_EQ(back.pings[r].ping_number, s.pings[r].ping_number);
    EXPECT_TRUE(samePose(back.pings[r].T_world_body, s.pings[r].T_world_body)) << "ping " << r;
    EXPECT_EQ(back.pings[r].altitude_m, s.pings[r].altitude_m);
    EXPECT_EQ(back.pings[r].distance_travelled_m, s.pings[r].distance_travelled_m);
  }
  EXPECT_EQ(back.image, s.image);  // exact: the image is stored as the engine holds it
  EXPECT_EQ(back.mask, s.mask);
  // Missing and removed.
  const auto missing = store_.readSubframe(43);
  EXPECT_TRUE(missing.ok() && !missing->has_value());
  ASSERT_OK(store_.removeSubframe(42));
  EXPECT_FALSE(fs::exists(store_.subframePath(42)));
  EXPECT_OK(store_.removeSubframe(42)) << "removing a file that is gone is not an error";
}

TEST_F(MatcherStateStoreTest, EveryFlippedByteAndEveryTruncationOfASubframeFileIsRefused) {
  ASSERT_OK(store_.writeSubframe(testSubframe(7, 3, 4)));
  const std::string path = store_.subframePath(7);
  const std::string good = readBytes(path);
  ASSERT_EQ(good.size(), subframeFileBytes(3, 4));
  for (size_t i = 0; i < good.size(); ++i) {
    patchByte(path, i, static_cast<char>(good[i] ^ 0x10));
    const auto read = store_.readSubframe(7);
    ASSERT_FALSE(read.ok()) << "byte " << i;
    EXPECT_NE(read.message().find(path), std::string::npos) << read.message();
    patchByte(path, i, good[i]);
  }
  for (size_t size = good.size(); size-- > 0;) {
    fs::resize_file(path, size);
    ASSERT_FALSE(store_.readSubframe(7).ok()) << "truncated to " << size;
  }
  // A good file under another subframe's name.
  writeBytes(store_.subframePath(8), good);
  const auto renamed = store_.readSubframe(8);
  EXPECT_FALSE(renamed.ok());
  EXPECT_NE(renamed.message().find("holds subframe 7"), std::string::npos) << renamed.message();
  writeBytes(path, good);
  const auto restored = store_.readSubframe(7);
  EXPECT_TRUE(restored.ok() && restored->has_value()) << restored.message();
}

MatcherState testState() {
  MatcherState state;
  state.corrections.push_back({3, Pose::identity()});
  state.corrections.push_back(
      {5, Pose(sss::core::quaternionFromEuler(1e-3, -2e-3, 0.1 / 3.0), Eigen::Vector3d(1.0 / 3.0, -2.5e-7, 1e9))});
  state.pairs.push_back({3, 5, 2, Pose(sss::core::quaternionFromEuler(0.0, 0.0, -0.7), Eigen::Vector3d(-4.0, 0.1, 0.0))});
  state.pairs.push_back({-1, 5, 0, Pose::identity()});
  return state;
}

TEST_F(MatcherStateStoreTest, StateFileRoundTripsExactly) {
  const MatcherState state = testState();
  const auto missing = store_.readState();
  EXPECT_TRUE(missing.ok() && !missing->has_value());
  ASSERT_OK(store_.writeState(state));
  const auto read = store_.readState();
  ASSERT_OK(read);
  ASSERT_TRUE(read->has_value());
  const MatcherState& back = **read;
  ASSERT_EQ(back.corrections.size(), 2u);
  ASSERT_EQ(back.pairs.size(), 2u);
  for (size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(back.corrections[i].subframe_id, state.corrections[i].subframe_id);
    EXPECT_TRUE(samePose(back.corrections[i].correction, state.corrections[i].correction)) << i;
    EXPECT_EQ(back.pairs[i].subframe_id_a, state.pairs[i].subframe_id_a);
    EXPECT_EQ(back.pairs[i].subframe_id_b, state.pairs[i].subframe_id_b);
    EXPECT_EQ(back.pairs[i].rounds_done, state.pairs[i].rounds_done);
    EXPECT_TRUE(samePose(back.pairs[i].relative_at_match, state.pairs[i].relative_at_match)) << i;
  }
}

TEST_F(MatcherStateStoreTest, EveryFlippedByteAndEveryTruncationOfTheStateFileIsRefused) {
  ASSERT_OK(store_.writeState(testState()));
  const std::string path = store_.statePath();
  const std::string good = readBytes(path);
  for (size_t i = 0; i < good.size(); ++i) {
    patchByte(path, i, static_cast<char>(good[i] ^ 0x01));
    const auto read = store_.readState();
    ASSERT_FALSE(read.ok()) << "byte " << i;
    EXPECT_NE(read.message().find(path), std::string::npos) << read.message();
    patchByte(path, i, good[i]);
  }
  for (size_t size = good.size(); size-- > 0;) {
    fs::resize_file(path, size);
    ASSERT_FALSE(store_.readState().ok()) << "truncated to " << size;
  }
}

TEST_F(MatcherStateStoreTest, IdsComeFromWellFormedNamesAndOpenRemovesTemporaryFiles) {
  for (int64_t id : {12, 7, -3}) ASSERT_OK(store_.writeSubframe(testSubframe(id, 2, 1)));
  for (const char* name : {"x.subframe", "007.subframe", "12.subframe.tmp", "5.lcm", "+5.subframe"})
    writeBytes(dir_ + "/subframes/" + name, "junk");
  writeBytes(dir_ + "/matcher.state.tmp", "junk");
  EXPECT_EQ(store_.subframeIds(), (std::vector<int64_t>{-3, 7, 12}));
  ASSERT_OK(store_.open());
  EXPECT_FALSE(fs::exists(dir_ + "/subframes/12.subframe.tmp"));
  EXPECT_FALSE(fs::exists(dir_ + "/matcher.state.tmp"));
  EXPECT_TRUE(fs::exists(dir_ + "/subframes/x.subframe"));  // not ours to remove
}

TEST_F(MatcherStateStoreTest, UnwritableDirectoryIsReportedNotThrown) {
  writeBytes(dir_ + "/file", "not a directory");
  MatcherStateStore store(dir_ + "/file/state");
  const sss::core::Status opened = store.open();
  EXPECT_FALSE(opened.ok);
  EXPECT_NE(opened.message.find(dir_ + "/file/state"), std::string::npos) << opened.message;
  EXPECT_FALSE(store.writeSubframe(testSubframe(1, 2, 1)).ok);
  EXPECT_FALSE(store.writeState(testState()).ok);
}

// Figures at the deployment's size (200 pings x 2 x 1250 bins), printed for the README; the engine
// restores them in id order with their corrections and matches nothing (one line: no pairs).
TEST_F(MatcherStateStoreTest, FullSizeFiguresAndRestoreOfTenSubframes) {
  using Clock = std::chrono::steady_clock;
  const auto seconds = [](Clock::time_point since) {
    return std::chrono::duration<double>(Clock::now() - since).count();
  };
  MatcherEngineOptions options;
  MatcherEngine engine(options);
  ASSERT_EQ(engine.restore(store_).subframes, 0u);
  double add_s = 0.0;
  for (int64_t id = 0; id < 10; ++id) {
    sss::core::Subframe s = testSubframe(id, 200, 1250);
    s.line_id = 0;
    const auto start = Clock::now();
    EXPECT_TRUE(engine.addSubframe(std::move(s)).empty());
    add_s += seconds(start);
  }
  EXPECT_EQ(engine.counters().state_write_errors, 0u);
  EXPECT_EQ(fs::file_size(store_.subframePath(0)), subframeFileBytes(200, 1250));
  const auto write_start = Clock::now();
  ASSERT_OK(store_.writeSubframe(testSubframe(99, 200, 1250)));
  const double write_subframe_s = seconds(write_start);
  ASSERT_OK(store_.removeSubframe(99));
  const auto state_start = Clock::now();
  ASSERT_OK(store_.writeState(engine.state()));
  const double write_state_s = seconds(state_start);

  MatcherEngine restored(options);
  const auto restore_start = Clock::now();
  const RestoreReport report = restored.restore(store_);
  const double restore_s = seconds(restore_start);
  EXPECT_EQ(report.subframes, 10u);
  EXPECT_TRUE(report.problems.empty());
  EXPECT_LE(restored.memoryBytes(), engine.memoryBytes());  // no encoded copies kept
  std::printf("subframe file %zu bytes, written in %.1f ms (addSubframe without pairs %.1f ms); state file %zu "
              "bytes in %.2f ms; restore of 10 subframes %.0f ms\n",
              subframeFileBytes(200, 1250), 1e3 * write_subframe_s, 1e3 * add_s / 10,
              static_cast<size_t>(fs::file_size(store_.statePath())), 1e3 * write_state_s, 1e3 * restore_s);
}

}  // namespace
}  // namespace sss::matcher
