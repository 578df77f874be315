// Ping-nav fusion: interpolation, bounded waiting, drops that are counted and never guessed,
// reordering, duplicates, altitude fallback and the lever arm; hand-built nav and pings.
#include "pipeline/subframe/ping_nav_fusion.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

namespace sss::subframe {
namespace {

constexpr int64_t kT0 = 1780300800000000;

NavInput nav(double t_s, double north_m, double heading_rad, double altitude_m = 18.0, bool altitude_valid = true) {
  NavInput n;
  n.utime_us = kT0 + static_cast<int64_t>(std::llround(t_s * 1e6));
  n.position_ned_m = Eigen::Vector3d(north_m, 0.0, 22.0);
  n.heading_rad = heading_rad;
  n.altitude_m = altitude_m;
  n.altitude_valid = altitude_valid;
  n.distance_travelled_m = north_m;
  return n;
}

PingInput ping(double t_s, int64_t number, double altitude_m = -1.0) {
  PingInput p;
  p.utime_us = kT0 + static_cast<int64_t>(std::llround(t_s * 1e6));
  p.ping_number = number;
  p.sample_interval_s = 0.01;  // 10 samples 7.5 m apart: a 75 m range, beyond the altitudes used
  p.altitude_m = altitude_m;
  p.port.assign(10, 1.0f);
  p.starboard.assign(10, 1.0f);
  return p;
}

// Pings released as soon as one nav sample lies past them (no look-ahead for the heading rate).
PingNavFusionOptions immediate() {
  PingNavFusionOptions options;
  options.heading_rate_window_s = 0.0;
  return options;
}

TEST(PingNavFusion, WaitsHalfAHeadingRateWindowPastThePingForACentredRate) {
  PingNavFusionOptions options;
  options.heading_rate_window_s = 1.0;
  PingNavFusion fusion(options);
  std::vector<FusedPing> out;
  for (int i = 0; i <= 10; ++i) {
    fusion.addNav(nav(0.1 * i, 0.2 * i, 0.02 * i * i), out);  // heading accelerating
    if (i == 3) fusion.addPing(ping(0.3, 1), out);
    if (i < 8) {
      EXPECT_TRUE(out.empty()) << i;
    }
  }
  ASSERT_EQ(out.size(), 1u);
  // Rate over [0.0, 0.8] s: (0.02 * 64 - 0) / 0.8.
  EXPECT_NEAR(out[0].heading_rate_rad_s, 1.6, 1e-9);
}

TEST(PingNavFusion, InterpolatesPositionAndSlerpsAttitudeAtThePingTime) {
  PingNavFusion fusion(immediate());
  std::vector<FusedPing> out;
  fusion.addNav(nav(0.0, 0.0, 0.2), out);
  fusion.addPing(ping(0.25, 1), out);
  EXPECT_TRUE(out.empty());  // waits for the nav sample after it
  fusion.addNav(nav(0.5, 1.0, 0.4, 20.0), out);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_NEAR(out[0].T_world_body.translation.x(), 0.5, 1e-9);
  EXPECT_NEAR(out[0].heading_rad, 0.3, 1e-9);
  EXPECT_NEAR(sss::core::eulerFromQuaternion(out[0].T_world_body.rotation).heading_rad, 0.3, 1e-9);
  EXPECT_NEAR(out[0].altitude_m, 19.0, 1e-9);
  EXPECT_NEAR(out[0].distance_travelled_m, 0.5, 1e-9);
  EXPECT_NEAR(out[0].heading_rate_rad_s, 0.4, 1e-9);  // 0.2 rad in 0.5 s
  EXPECT_EQ(fusion.counters().pings_out, 1u);
}

TEST(PingNavFusion, InterpolatesHeadingAcrossNorth) {
  PingNavFusion fusion(immediate());
  std::vector<FusedPing> out;
  fusion.addNav(nav(0.0, 0.0, 3.1), out);
  fusion.addNav(nav(0.5, 1.0, -3.1), out);
  fusion.addPing(ping(0.25, 1), out);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_NEAR(std::abs(out[0].heading_rad), M_PI, 1e-9);
}

TEST(PingNavFusion, DropsAPingWhoseNavNeverComes) {
  PingNavFusionOptions options = immediate();
  options.max_ping_wait_s = 1.0;
  PingNavFusion fusion(options);
  std::vector<FusedPing> out;
  fusion.addNav(nav(0.0, 0.0, 0.0), out);
  for (int i = 1; i <= 8; ++i) fusion.addPing(ping(0.25 * i, i), out);  // nav silent for 2 s
  EXPECT_TRUE(out.empty());
  EXPECT_EQ(fusion.counters().dropped_no_nav, 3u);  // pings more than 1 s behind the newest one
  fusion.finish(out);
  EXPECT_TRUE(out.empty());
  EXPECT_EQ(fusion.counters().dropped_no_nav, 8u);
  EXPECT_EQ(fusion.pendingPings(), 0u);
}

// An INS that stalled and then carries on late (its samples queued, delivered behind the pings
// from then on): with the default options every ping still gets its nav, as long as the lag
// stays under max_ping_wait_s less half the heading-rate window (30 - 4 = 26 s).
TEST(PingNavFusion, NavLaggingThePingsByTwentySecondsLosesNoPing) {
  PingNavFusion fusion(PingNavFusionOptions{});
  std::vector<FusedPing> out;
  constexpr double kLagS = 20.0;
  constexpr int kPings = 4 * 120;  // 2 min at 4 Hz
  int next_nav = 0;
  for (int i = 0; i < kPings; ++i) {
    const double t_s = 0.25 * i;
    fusion.addPing(ping(t_s, i), out);
    // Nav at 10 Hz, each sample arriving kLagS after its time (ping time stands for the clock).
    for (; 0.1 * next_nav <= t_s - kLagS; ++next_nav) fusion.addNav(nav(0.1 * next_nav, 0.2 * next_nav, 0.0), out);
  }
  for (; 0.1 * next_nav <= 0.25 * (kPings - 1) + 5.0; ++next_nav) fusion.addNav(nav(0.1 * next_nav, 0.2 * next_nav, 0.0), out);
  fusion.finish(out);
  EXPECT_EQ(fusion.counters().droppedWithoutNav(), 0u);
  ASSERT_EQ(out.size(), static_cast<size_t>(kPings));
  EXPECT_NEAR(out.back().T_world_body.translation.x(), 2.0 * 0.25 * (kPings - 1), 1e-9);
  // ... and a lag beyond the wait drops pings (counted) rather than holding them for ever.
  PingNavFusion late(PingNavFusionOptions{});
  out.clear();
  next_nav = 0;
  for (int i = 0; i < kPings; ++i) {
    const double t_s = 0.25 * i;
    late.addPing(ping(t_s, i), out);
    for (; 0.1 * next_nav <= t_s - 40.0; ++next_nav) late.addNav(nav(0.1 * next_nav, 0.2 * next_nav, 0.0), out);
  }
  EXPECT_GT(late.counters().dropped_no_nav, 0u);
  EXPECT_LE(late.pendingPings(), static_cast<size_t>(30.0 * 4 + 1));
}

TEST(PingNavFusion, DropsPingsInsideANavGapAndBeforeTheHistory) {
  PingNavFusionOptions options = immediate();
  options.max_nav_gap_s = 0.5;
  PingNavFusion fusion(options);
  std::vector<FusedPing> out;
  fusion.addNav(nav(1.0, 0.0, 0.0), out);
  fusion.addPing(ping(0.5, 1), out);  // before any nav: before the navigation's first fix
  fusion.addNav(nav(3.0, 4.0, 0.0), out);
  fusion.addPing(ping(2.0, 2), out);  // bracketed by nav 2 s apart
  fusion.addNav(nav(3.2, 4.4, 0.0), out);
  fusion.addPing(ping(3.1, 3), out);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].ping.ping_number, 3);
  EXPECT_EQ(fusion.counters().dropped_before_first_fix, 1u);
  EXPECT_EQ(fusion.counters().dropped_too_old, 0u);
  EXPECT_EQ(fusion.counters().dropped_nav_gap, 1u);
  EXPECT_EQ(fusion.counters().droppedWithoutNav(), 2u);
}

// Nav without a position (before the INS's first fix) founds no frame: ignored and counted.
TEST(PingNavFusion, NavWithoutPositionIsIgnored) {
  PingNavFusion fusion(immediate());
  std::vector<FusedPing> out;
  NavInput no_fix = nav(0.0, 0.0, 0.0);
  no_fix.position_valid = false;
  fusion.addNav(no_fix, out);
  fusion.addPing(ping(0.5, 1), out);
  fusion.addNav(nav(1.0, 2.0, 0.0), out);
  fusion.addNav(nav(1.2, 2.4, 0.0), out);
  fusion.finish(out);
  EXPECT_TRUE(out.empty());
  EXPECT_EQ(fusion.counters().nav_without_position, 1u);
  EXPECT_EQ(fusion.counters().dropped_before_first_fix, 1u);
}

// After a pause in the navigation longer than the history (a 90 s stop between lines), the pings
// just before the pause still get their pose: the new sample releases them before the history is
// trimmed to nav_history_s behind it.
TEST(PingNavFusion, PingsBeforeALongNavPauseKeepTheirPose) {
  PingNavFusionOptions options;  // 8 s heading window: pings wait 4 s past them
  PingNavFusion fusion(options);
  std::vector<FusedPing> out;
  for (int i = 0; i <= 100; ++i) fusion.addNav(nav(0.1 * i, 0.2 * i, 0.0), out);  // 0 .. 10 s
  for (int k = 0; k < 40; ++k) fusion.addPing(ping(0.05 + 0.25 * k, k), out);        // up to 9.8 s
  EXPECT_LT(out.size(), 40u);  // the last ones wait for nav 4 s past them
  for (int i = 0; i <= 10; ++i) fusion.addNav(nav(100.0 + 0.1 * i, 50.0 + 0.2 * i, 0.0), out);  // 90 s later
  EXPECT_EQ(out.size(), 40u);
  EXPECT_EQ(fusion.counters().droppedWithoutNav(), 0u);
}

TEST(PingNavFusion, ReordersWaitingPingsAndDropsLateOnesAndDuplicates) {
  PingNavFusion fusion(immediate());
  std::vector<FusedPing> out;
  fusion.addNav(nav(0.0, 0.0, 0.0), out);
  fusion.addPing(ping(0.50, 3), out);
  fusion.addPing(ping(0.25, 2), out);  // late but the other one still waits: reordered
  fusion.addPing(ping(0.50, 3), out);  // duplicate ping number
  fusion.addNav(nav(0.5, 1.0, 0.0), out);
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(out[0].ping.ping_number, 2);
  EXPECT_EQ(out[1].ping.ping_number, 3);
  fusion.addPing(ping(0.4, 4), out);  // older than one released: dropped
  EXPECT_EQ(out.size(), 2u);
  const auto& c = fusion.counters();
  EXPECT_EQ(c.pings_reordered, 1u);
  EXPECT_EQ(c.pings_duplicate, 1u);
  EXPECT_EQ(c.pings_out_of_order, 1u);
  EXPECT_EQ(c.pings_in, 4u);
}

TEST(PingNavFusion, FallsBackToThePingAltitudeAndDropsWithoutAny) {
  PingNavFusion fusion(immediate());
  std::vector<FusedPing> out;
  fusion.addNav(nav(0.0, 0.0, 0.0, 18.0, false), out);
  fusion.addNav(nav(0.5, 1.0, 0.0, 18.0, false), out);
  fusion.addPing(ping(0.25, 1, 17.5), out);
  fusion.addPing(ping(0.4, 2, -1.0), out);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_TRUE(out[0].altitude_from_ping);
  EXPECT_NEAR(out[0].altitude_m, 17.5, 1e-6);
  EXPECT_EQ(fusion.counters().altitude_from_ping, 1u);
  EXPECT_EQ(fusion.counters().dropped_no_altitude, 1u);
}

TEST(PingNavFusion, LeverArmBelowTheBodyShortensTheAltitude) {
  PingNavFusionOptions options = immediate();
  options.sonar_position_body_m = Eigen::Vector3d(1.0, 0.0, 0.5);
  PingNavFusion fusion(options);
  std::vector<FusedPing> out;
  fusion.addNav(nav(0.0, 0.0, 0.0), out);
  fusion.addNav(nav(0.5, 0.0, 0.0), out);
  fusion.addPing(ping(0.25, 1), out);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_NEAR(out[0].altitude_m, 17.5, 1e-9);
}

TEST(PingNavFusion, ABurstOfPingsWithoutNavStaysBoundedAndCounted) {
  PingNavFusionOptions options = immediate();
  options.max_pending_pings = 64;
  options.max_ping_wait_s = 1000.0;
  PingNavFusion fusion(options);
  std::vector<FusedPing> out;
  fusion.addNav(nav(0.0, 0.0, 0.0), out);
  for (int i = 1; i <= 5000; ++i) fusion.addPing(ping(0.001 * i, i), out);
  EXPECT_LE(fusion.pendingPings(), 64u);
  EXPECT_EQ(fusion.counters().dropped_no_nav, 5000u - 64u);
  fusion.addNav(nav(10.0, 0.0, 0.0), out);  // 10 s gap: the survivors are dropped as nav gap
  EXPECT_EQ(fusion.pendingPings(), 0u);
  EXPECT_EQ(fusion.counters().dropped_nav_gap, 64u);
  EXPECT_TRUE(out.empty());
}

}  // namespace
}  // namespace sss::subframe

namespace sss::subframe {
namespace {

// The paper's heading-noise study: 0.05 rad of white INS heading noise (drawn every 0.25 s) on a
// straight line must neither read as a turn (max_heading_rate_rad_s 0.02 in the deployment
// config) nor reach the ping poses; a real 0.05 rad/s survey turn still does read as one.
TEST(PingNavFusion, HeadingNoiseIsFilteredButTurnsAreDetected) {
  std::mt19937_64 rng(5);
  std::normal_distribution<double> noise(0.0, 0.05);
  PingNavFusion fusion({});  // 8 s window, pose heading from the fit
  std::vector<FusedPing> out;
  const double line_heading_rad = 0.3, turn_start_s = 120.0, turn_rate_rad_s = 0.05;
  auto trueHeading = [&](double t_s) {
    return t_s < turn_start_s ? line_heading_rad : line_heading_rad + turn_rate_rad_s * (t_s - turn_start_s);
  };
  double held_noise = 0.0;
  for (int i = 0; i <= 20 * 180; ++i) {  // 20 Hz nav for 180 s
    const double t_s = 0.05 * i;
    if (i % 5 == 0) held_noise = noise(rng);
    fusion.addNav(nav(t_s, 2.0 * t_s, sss::core::wrapAngle(trueHeading(t_s) + held_noise)), out);
    if (i % 5 == 0 && t_s >= 10.0 && t_s <= 170.0) fusion.addPing(ping(t_s, i), out);
  }
  double max_straight_rate = 0.0, max_straight_heading_error = 0.0;
  int turn_pings = 0, turning = 0;
  for (const FusedPing& p : out) {
    const double t_s = static_cast<double>(p.ping.utime_us - kT0) * 1e-6;
    const double heading = sss::core::eulerFromQuaternion(p.T_world_body.rotation).heading_rad;
    if (t_s < turn_start_s - 4.0) {
      max_straight_rate = std::max(max_straight_rate, std::abs(p.heading_rate_rad_s));
      max_straight_heading_error =
          std::max(max_straight_heading_error, std::abs(sss::core::wrapAngle(heading - line_heading_rad)));
    } else if (t_s > turn_start_s + 4.0) {
      ++turn_pings;
      turning += std::abs(p.heading_rate_rad_s) > 0.02;
    }
  }
  std::printf("straight: max |rate| %.4f rad/s, max pose heading error %.4f rad; turn: %d of %d pings flagged\n",
              max_straight_rate, max_straight_heading_error, turning, turn_pings);
  EXPECT_LT(max_straight_rate, 0.02);            // no false turn on the line
  EXPECT_LT(max_straight_heading_error, 0.035);  // vs 0.05 rad sigma (0.15 rad peaks) unfiltered
  EXPECT_GT(turn_pings, 100);
  EXPECT_EQ(turning, turn_pings);
}

}  // namespace
}  // namespace sss::subframe
