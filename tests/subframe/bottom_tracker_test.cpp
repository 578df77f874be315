// Bottom tracking on hand-built envelopes: speckled water column, a seabed edge at a known slant
// range, fish and surface echoes, a dead side, a seabed step; and the fusion's altitude policy.
#include "pipeline/subframe/bottom_tracker.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "pipeline/subframe/ping_nav_fusion.hpp"

namespace sss::subframe {
namespace {

constexpr double kSpacingM = 0.02;  // 2205-like sample spacing
constexpr int kSamples = 4000;      // 80 m of slant range

struct Echo {
  double range_m;
  double length_m;
  double level;
};

// Exponential (one-look) speckle on a mean profile: water column at `water` up to the seabed at
// `altitude_m`, then seabed at 1 / (r / altitude)^2 (spreading and grazing), plus echoes.
std::vector<float> envelope(std::mt19937& random, double altitude_m, double water = 0.03,
                            const std::vector<Echo>& echoes = {}, bool dead = false) {
  std::exponential_distribution<double> speckle(1.0);
  std::vector<float> out(kSamples);
  for (int i = 0; i < kSamples; ++i) {
    const double r = i * kSpacingM;
    double mean = water;
    if (!dead && r >= altitude_m) mean += 1.0 / std::pow(r / altitude_m, 2.0);
    for (const Echo& echo : echoes) {
      if (r >= echo.range_m && r < echo.range_m + echo.length_m) mean += echo.level;
    }
    out[i] = static_cast<float>(mean * speckle(random));
  }
  return out;
}

TEST(BottomTracker, FindsTheFirstSeabedReturnPastFishAndABrightPatch) {
  std::mt19937 random(7);
  BottomTrackerOptions options;
  int within_10cm = 0;
  for (int trial = 0; trial < 50; ++trial) {
    const double altitude_m = 8.0 + 0.37 * trial;
    // A fish at half the altitude (as bright as the seabed, 0.4 m long) and a rock 20 m out.
    const auto side = envelope(random, altitude_m, 0.03,
                               {{0.5 * altitude_m, 0.4, 1.0}, {altitude_m + 20.0, 5.0, 3.0}});
    const SideDetection d = detectFirstReturn(side, 0.0, kSpacingM, options);
    ASSERT_TRUE(d.valid) << trial;
    EXPECT_NEAR(d.slant_range_m, altitude_m, 0.3) << trial;
    within_10cm += std::abs(d.slant_range_m - altitude_m) <= 0.1 ? 1 : 0;
    EXPECT_GT(d.contrast_db, 10.0);
  }
  EXPECT_GE(within_10cm, 45);  // the bin is 0.1 m
}

// A water column of exact zeros (quantised, or simulated without noise) with one stray sample:
// the stray sample is no seabed.
TEST(BottomTracker, ASilentWaterColumnWithAStraySampleStillGivesTheSeabed) {
  std::mt19937 random(4);
  std::vector<float> side = envelope(random, 18.0, 0.0);
  side[50] = 1e-4f;  // 1 m out
  const SideDetection d = detectFirstReturn(side, 0.0, kSpacingM, {});
  ASSERT_TRUE(d.valid);
  EXPECT_NEAR(d.slant_range_m, 18.0, 0.15);
}

TEST(BottomTracker, ADeadSideOrAllWaterIsNoDetection) {
  std::mt19937 random(3);
  const auto dead = envelope(random, 15.0, 0.03, {}, true);
  EXPECT_FALSE(detectFirstReturn(dead, 0.0, kSpacingM, {}).valid);
  EXPECT_FALSE(detectFirstReturn({}, 0.0, kSpacingM, {}).valid);
  EXPECT_FALSE(detectFirstReturn(std::vector<float>(kSamples, 0.0f), 0.0, kSpacingM, {}).valid);
  // Seabed beyond the recorded range: nothing to find.
  EXPECT_FALSE(detectFirstReturn(envelope(random, 120.0), 0.0, kSpacingM, {}).valid);
}

TEST(BottomTracker, TracksAlongTrackWithOneDeadSideAndRejectsSurfaceEchoes) {
  std::mt19937 random(11);
  BottomTracker tracker;
  std::vector<double> errors;
  for (int ping = 0; ping < 200; ++ping) {
    const double altitude_m = 15.0 + 3.0 * std::sin(ping / 40.0);  // slow relief
    const bool echo = ping % 17 == 5;  // a surface echo on both sides, as bright as the seabed
    const std::vector<Echo> echoes = echo ? std::vector<Echo>{{6.0, 3.0, 2.0}} : std::vector<Echo>{};
    const auto port = envelope(random, altitude_m, 0.03, echoes);
    const auto starboard = envelope(random, altitude_m, 0.03, echoes, ping >= 100);  // dies half way
    const BottomTrack track = tracker.track(port, starboard, 0.0, kSpacingM);
    ASSERT_TRUE(track.valid) << ping;
    if (ping >= 10) errors.push_back(std::abs(track.altitude_m - altitude_m));
    if (ping >= 120 && !echo) {
      EXPECT_LE(track.quality, 0.5 + 1e-9) << "one side only";
    }
    if (ping >= 20 && ping < 100 && !echo) {
      EXPECT_GT(track.quality, 0.8) << ping;
    }
  }
  std::sort(errors.begin(), errors.end());
  const double p95 = errors[errors.size() * 95 / 100];
  std::printf("bottom track along 200 pings: p50 %.3f m, p95 %.3f m, outliers %llu, one side %llu\n",
              errors[errors.size() / 2], p95, static_cast<unsigned long long>(tracker.counters().outliers),
              static_cast<unsigned long long>(tracker.counters().one_side_only));
  EXPECT_LT(p95, 0.15);  // measured 0.045 m
  EXPECT_GE(tracker.counters().outliers, 10u);  // the 12 surface echoes
  // 100 pings with the starboard dead, less the echo pings (the echo is on both sides).
  EXPECT_GE(tracker.counters().one_side_only, 85u);
}

TEST(BottomTracker, ALastingStepInTheSeabedRestartsTheTrack) {
  std::mt19937 random(5);
  BottomTracker tracker;
  BottomTrack track;
  for (int ping = 0; ping < 30; ++ping) track = tracker.track(envelope(random, 20.0), envelope(random, 20.0), 0.0, kSpacingM);
  EXPECT_NEAR(track.altitude_m, 20.0, 0.2);
  for (int ping = 0; ping < 30; ++ping) track = tracker.track(envelope(random, 14.0), envelope(random, 14.0), 0.0, kSpacingM);
  EXPECT_NEAR(track.altitude_m, 14.0, 0.2);  // a 6 m mound, not an outlier
  EXPECT_EQ(tracker.counters().restarts, 1u);
}

// The fusion's policy: auto uses the navigation's altitude when it has one and the bottom track
// when neither the navigation nor the ping carries any; nav drops such pings.
TEST(BottomTracker, FusionUsesTheBottomTrackOnlyWhenNoAltitudeIsRecorded) {
  std::mt19937 random(9);
  auto run = [&](AltitudePolicy policy, bool nav_has_altitude) {
    PingNavFusionOptions options;
    options.heading_rate_window_s = 0.0;
    options.altitude_source = policy;
    PingNavFusion fusion(options);
    std::vector<FusedPing> out;
    constexpr int64_t kT0 = 1'780'300'800'000'000;
    for (int i = 0; i <= 40; ++i) {
      NavInput nav;
      nav.utime_us = kT0 + i * 250'000;
      nav.position_ned_m = Eigen::Vector3d(0.5 * i, 0.0, 30.0);
      nav.altitude_m = nav_has_altitude ? 17.0 : 0.0;
      nav.altitude_valid = nav_has_altitude;
      fusion.addNav(nav, out);
      if (i < 40) {
        PingInput ping;
        ping.utime_us = nav.utime_us + 100'000;
        ping.ping_number = i;
        ping.sample_interval_s = 2.0 * kSpacingM / 1500.0;
        ping.sound_speed_m_s = 1500.0;
        ping.port = envelope(random, 18.0);
        ping.starboard = envelope(random, 18.0);
        fusion.addPing(std::move(ping), out);
      }
    }
    fusion.finish(out);
    return std::make_pair(out, fusion.counters());
  };
  const auto [with_nav, with_nav_counters] = run(AltitudePolicy::kAuto, true);
  ASSERT_EQ(with_nav.size(), 40u);
  EXPECT_EQ(with_nav_counters.altitude_from_nav, 40u);
  EXPECT_EQ(with_nav.front().altitude_source, AltitudeSource::kNav);
  EXPECT_NEAR(with_nav.front().altitude_m, 17.0, 1e-9);

  const auto [tracked, tracked_counters] = run(AltitudePolicy::kAuto, false);
  ASSERT_EQ(tracked.size(), 40u);
  EXPECT_EQ(tracked_counters.altitude_from_bottom_track, 40u);
  for (const FusedPing& p : tracked) {
    EXPECT_EQ(p.altitude_source, AltitudeSource::kBottomTrack);
    EXPECT_NEAR(p.altitude_m, 18.0, 0.2);
  }
  const auto [forced, forced_counters] = run(AltitudePolicy::kBottomTrack, true);
  EXPECT_EQ(forced_counters.altitude_from_bottom_track, 40u);
  EXPECT_NEAR(forced.back().altitude_m, 18.0, 0.2);  // the returns, not the nav's 17 m

  const auto [dropped, dropped_counters] = run(AltitudePolicy::kNav, false);
  EXPECT_TRUE(dropped.empty());
  EXPECT_EQ(dropped_counters.dropped_no_altitude, 40u);
}

}  // namespace
}  // namespace sss::subframe
