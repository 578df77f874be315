// sss-subframe-buffer's service: the numbering across restarts (saved before the subframes leave,
// an unreadable or unwritable file reported), the idle flush of the open line, and the status
// counters with each cause of lost pings logged once. Hand-built straight lines, no middleware.
#include "pipeline/subframe/subframe_buffer_service.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "pipeline/core/state_file.hpp"

namespace sss::subframe {
namespace {

namespace fs = std::filesystem;

constexpr int64_t kT0 = 1780300800000000;
constexpr double kPingPeriodS = 0.2;
constexpr double kSpeedMPerS = 1.5;

int64_t utimeAt(double t_s) { return kT0 + static_cast<int64_t>(std::llround(t_s * 1e6)); }

sss::core::NavSample navAt(double t_s) {
  sss::core::NavSample n;
  n.utime_us = utimeAt(t_s);
  n.position_ned_m = Eigen::Vector3d(kSpeedMPerS * t_s, 0.0, 20.0);
  n.altitude_m = 18.0;
  n.altitude_valid = true;
  n.distance_travelled_m = kSpeedMPerS * t_s;
  return n;
}

sss::core::PingSample pingAt(double t_s, int64_t number) {
  sss::core::PingSample p;
  p.utime_us = utimeAt(t_s);
  p.ping_number = number;
  p.sample_interval_s = 0.01;  // 10 samples 7.5 m apart: 75 m of range
  p.port.assign(10, 1.0f);
  p.starboard.assign(10, 1.0f);
  return p;
}

// A straight line of `pings` pings from t0_s, nav at 20 Hz 2 s ahead of each ping (as it comes
// live); the monotonic clock is the ping time. Returns every subframe the service handed out.
std::vector<Subframe> flyLine(SubframeBufferService& service, ServiceLog& log, double t0_s, int pings,
                              int64_t& ping_number) {
  std::vector<Subframe> out;
  const auto take = [&](std::vector<Subframe> subframes) {
    for (Subframe& s : subframes) out.push_back(std::move(s));
  };
  double nav_t_s = t0_s;
  for (int i = 0; i < pings; ++i) {
    const double t_s = t0_s + i * kPingPeriodS;
    for (; nav_t_s <= t_s + 2.0; nav_t_s += 0.05) take(service.addNav(navAt(nav_t_s), log));
    take(service.addPing(pingAt(t_s, ping_number++), utimeAt(t_s), log));
  }
  return out;
}

class SubframeBufferServiceTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("subframe_buffer_service_" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  SubframeBufferServiceOptions options(const std::string& numbering_path) const {
    SubframeBufferServiceOptions o;
    o.numbering_path = numbering_path;
    return o;
  }
  static long long savedNextSubframeId(const std::string& path) {
    const sss::core::Result<sss::core::StateValues> read =
        sss::core::readStateFile(path, SubframeBufferService::kNumberingFormat);
    long long id = -1;
    if (!read || !sss::core::stateInteger(*read, "next_subframe_id", id))
      return -1;
    return id;
  }

  fs::path dir_;
};

TEST_F(SubframeBufferServiceTest, NumberingSurvivesARestartAndIsSavedBeforeTheSubframesLeave) {
  const std::string path = (dir_ / "numbering").string();
  int64_t ping_number = 0;
  std::vector<int64_t> first_run_ids;
  int first_run_line = -1;
  {
    ServiceLog log;
    SubframeBufferService service(options(path), log);
    EXPECT_TRUE(log.empty()) << "no file yet: nothing to resume, nothing to say";
    // 450 pings: two full subframes of 200 while flying, a tail of 50 at the end.
    std::vector<Subframe> subframes = flyLine(service, log, 0.0, 450, ping_number);
    ASSERT_EQ(subframes.size(), 2u);
    // The file already names the id after the last subframe handed out.
    EXPECT_EQ(savedNextSubframeId(path), subframes.back().id + 1);
    for (Subframe& s : service.finish(log)) subframes.push_back(std::move(s));
    ASSERT_EQ(subframes.size(), 3u);
    EXPECT_EQ(subframes.back().rows(), 50);
    for (const Subframe& s : subframes) first_run_ids.push_back(s.id);
    first_run_line = subframes.back().line_id;
    EXPECT_EQ(savedNextSubframeId(path), subframes.back().id + 1);
    EXPECT_TRUE(log.errors.empty());
  }
  EXPECT_EQ(first_run_ids, (std::vector<int64_t>{0, 1, 2}));

  // A restart (same state file): the ids go on from where the first run stopped.
  ServiceLog log;
  SubframeBufferService restarted(options(path), log);
  ASSERT_EQ(log.info.size(), 1u);
  EXPECT_NE(log.info[0].find("resumed the numbering"), std::string::npos) << log.info[0];
  EXPECT_NE(log.info[0].find("next subframe 3"), std::string::npos) << log.info[0];
  const std::vector<Subframe> later = flyLine(restarted, log, 1000.0, 250, ping_number);
  ASSERT_EQ(later.size(), 1u);
  EXPECT_EQ(later[0].id, 3);
  EXPECT_GT(later[0].line_id, first_run_line);
}

TEST_F(SubframeBufferServiceTest, TheOpenLineIsClosedOnceAfterIdleFlushSecondsWithoutPings) {
  ServiceLog log;
  SubframeBufferServiceOptions o = options((dir_ / "numbering").string());
  o.idle_flush_s = 5.0;
  SubframeBufferService service(o, log);
  int64_t ping_number = 0;
  ASSERT_TRUE(flyLine(service, log, 0.0, 120, ping_number).empty());  // under one subframe
  const int64_t last_ping_us = utimeAt(119 * kPingPeriodS);
  EXPECT_TRUE(service.flushIfIdle(last_ping_us + 4'900'000, log).empty()) << "4.9 s: still waiting";
  EXPECT_TRUE(log.info.empty());
  const std::vector<Subframe> flushed = service.flushIfIdle(last_ping_us + 5'000'000, log);
  ASSERT_EQ(flushed.size(), 1u);
  EXPECT_EQ(flushed[0].rows(), 120);
  ASSERT_EQ(log.info.size(), 1u);
  EXPECT_NE(log.info[0].find("closed the open survey line"), std::string::npos) << log.info[0];
  EXPECT_EQ(savedNextSubframeId((dir_ / "numbering").string()), 1);
  // Once per pause: later ticks hand out nothing and say nothing.
  log = {};
  EXPECT_TRUE(service.flushIfIdle(last_ping_us + 60'000'000, log).empty());
  EXPECT_TRUE(log.empty());
}

TEST_F(SubframeBufferServiceTest, AnUnreadableNumberingFileIsReportedAndTheIdsStartFromZero) {
  const std::string path = (dir_ / "numbering").string();
  std::ofstream(path) << "not a numbering file\n";
  ServiceLog log;
  SubframeBufferService service(options(path), log);
  ASSERT_EQ(log.errors.size(), 1u);
  EXPECT_NE(log.errors[0].find("not resumed"), std::string::npos) << log.errors[0];
  EXPECT_NE(log.errors[0].find(path), std::string::npos) << log.errors[0];
  int64_t ping_number = 0;
  const std::vector<Subframe> subframes = flyLine(service, log, 0.0, 250, ping_number);
  ASSERT_EQ(subframes.size(), 1u);
  EXPECT_EQ(subframes[0].id, 0);
  EXPECT_EQ(savedNextSubframeId(path), 1) << "the bad file is replaced by a good one";

  // Without a state directory: a warning that says what a restart does.
  ServiceLog no_directory_log;
  SubframeBufferService no_directory(options(""), no_directory_log);
  ASSERT_EQ(no_directory_log.warnings.size(), 1u);
  EXPECT_NE(no_directory_log.warnings[0].find("start from 0 again"), std::string::npos);
}

TEST_F(SubframeBufferServiceTest, NumberingThatCannotBeSavedIsCountedAndLoggedOnceAndTheSubframesStillLeave) {
  const std::string path = (dir_ / "missing_directory" / "numbering").string();
  ServiceLog log;
  SubframeBufferService service(options(path), log);
  int64_t ping_number = 0;
  const std::vector<Subframe> subframes = flyLine(service, log, 0.0, 450, ping_number);
  EXPECT_EQ(subframes.size(), 2u);
  EXPECT_EQ(service.numberingWriteFailures(), 2u);
  ASSERT_EQ(log.errors.size(), 1u);
  EXPECT_NE(log.errors[0].find("not saved"), std::string::npos) << log.errors[0];
  sss::core::HealthMonitor health(0);
  service.reportHealth(health, kT0, log);
  EXPECT_EQ(health.counter("numbering_write_failures"), 2.0);
}

TEST_F(SubframeBufferServiceTest, StatusCountsEachCauseOfLostPingsAndLogsItOnce) {
  ServiceLog log;
  SubframeBufferService service(options((dir_ / "numbering").string()), log);
  sss::core::HealthMonitor health(0);
  // Pings long before any navigation, then navigation that never brackets them.
  for (int i = 0; i < 5; ++i) (void)service.addPing(pingAt(i * kPingPeriodS, i), utimeAt(i * kPingPeriodS), log);
  for (int k = 0; k < 60; ++k) (void)service.addNav(navAt(100.0 + k * 0.05), log);
  service.reportHealth(health, kT0, log);
  EXPECT_EQ(health.counter("pings_in"), 5.0);
  const double dropped = health.counter("pings_dropped_without_nav");
  EXPECT_EQ(dropped, 5.0);
  ASSERT_EQ(log.warnings.size(), 1u);
  EXPECT_NE(log.warnings[0].find("without bracketing navigation"), std::string::npos) << log.warnings[0];

  // More of the same cause: counted, not logged again.
  log = {};
  for (int i = 5; i < 8; ++i) (void)service.addPing(pingAt(50.0 + i * kPingPeriodS, i), utimeAt(50.0), log);
  for (int k = 60; k < 120; ++k) (void)service.addNav(navAt(100.0 + k * 0.05), log);
  service.reportHealth(health, kT0 + 1'000'000, log);
  EXPECT_EQ(health.counter("pings_in"), 8.0);
  EXPECT_EQ(health.counter("pings_dropped_without_nav"), 8.0);
  EXPECT_TRUE(log.warnings.empty());
  EXPECT_EQ(health.counter("nav_in"), 120.0);
}

}  // namespace
}  // namespace sss::subframe
