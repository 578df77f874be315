// Footprint overlap on hand-built straight subframes: parallel lines at known spacing give the
// analytic overlap, crossing lines overlap at any angle, candidates are bounded and ordered.
#include "pipeline/matcher/overlap.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace sss::matcher {
namespace {

constexpr int kBins = 500;         // per side
constexpr double kBinM = 0.1;      // 50 m swath per side
constexpr double kAltitudeM = 10.0;

// A straight 100 m subframe starting at (north, east) with the given heading, every bin valid
// except 20 nadir bins per side.
sss::core::Subframe straightSubframe(int64_t id, int line, double north_m, double east_m, double heading_rad) {
  sss::core::Subframe s;
  s.id = id;
  s.line_id = line;
  s.geometry.bins_per_side = kBins;
  s.geometry.bin_size_m = kBinM;
  const Eigen::Vector2d direction(std::cos(heading_rad), std::sin(heading_rad));
  for (int i = 0; i < 200; ++i) {
    sss::core::SubframePing ping;
    const Eigen::Vector2d p = Eigen::Vector2d(north_m, east_m) + 0.5 * i * direction;
    ping.T_world_body = sss::core::Pose(sss::core::quaternionFromEuler(0.0, 0.0, heading_rad), Eigen::Vector3d(p.x(), p.y(), 20.0));
    ping.altitude_m = kAltitudeM;
    s.pings.push_back(ping);
  }
  s.centre_ping_index = 100;
  s.image.assign(static_cast<size_t>(200) * 2 * kBins, 1.0f);
  s.mask.assign(s.image.size(), 0);
  for (int r = 0; r < 200; ++r) {
    for (int c = kBins - 20; c < kBins + 20; ++c) s.mask[static_cast<size_t>(r) * 2 * kBins + c] = 1;
  }
  return s;
}

std::vector<sss::core::Pose> posesOf(const sss::core::Subframe& s) {
  std::vector<sss::core::Pose> poses;
  for (const auto& p : s.pings) poses.push_back(p.T_world_body);
  return poses;
}

Footprint footprintOf(const sss::core::Subframe& s) { return computeFootprint(s, posesOf(s), OverlapOptions{}); }

TEST(Overlap, FootprintAreaIsTheTwoSwathsWithoutNadir) {
  const Footprint f = footprintOf(straightSubframe(0, 0, 0.0, 0.0, 0.0));
  // Each side: valid bins 0..479 from nadir, i.e. ground range 2.0 .. 49.9 m (+/- half a bin of
  // georeference rounding), along 99.5 m.
  const double expected = 2.0 * (49.9 - 2.0) * 99.5;
  EXPECT_NEAR(f.area_m2, expected, 0.01 * expected);
}

TEST(Overlap, ParallelLinesOverlapByTheAnalyticStrip) {
  const Footprint a = footprintOf(straightSubframe(0, 0, 0.0, 0.0, 0.0));
  // 60 m east, flown south over the same stretch: A's starboard (2..49.9 m east) meets B's
  // starboard (west of B: 10.1..58 m east): strip 10.1..49.9 m east; A's starboard also meets
  // B's port? No: B's port is east of B.
  const Footprint b = footprintOf(straightSubframe(1, 1, 99.5, 60.0, M_PI));
  const double expected = (49.9 - 10.1) * 99.5;
  EXPECT_NEAR(overlapAreaM2(a, b), expected, 0.02 * expected);
  EXPECT_NEAR(overlapAreaM2(b, a), expected, 0.02 * expected);
}

TEST(Overlap, CrossingLinesOverlapAtAnyAngle) {
  const Footprint a = footprintOf(straightSubframe(0, 0, 0.0, 0.0, 0.0));
  for (double angle_deg : {30.0, 60.0, 90.0, 135.0}) {
    const double heading = angle_deg * M_PI / 180.0;
    // B's centre over A's centre.
    const Eigen::Vector2d direction(std::cos(heading), std::sin(heading));
    const Eigen::Vector2d start = Eigen::Vector2d(49.75, 0.0) - 49.75 * direction;
    const Footprint b = footprintOf(straightSubframe(1, 1, start.x(), start.y(), heading));
    const double area = overlapAreaM2(a, b);
    EXPECT_GT(area, 1000.0) << angle_deg;
    EXPECT_LT(area, std::min(a.area_m2, b.area_m2)) << angle_deg;
  }
}

TEST(Overlap, CandidatesAreBoundedOrderedAndSkipTheSameLineAndDistantOnes) {
  const auto s = straightSubframe(10, 5, 0.0, 0.0, 0.0);
  const Footprint f = footprintOf(s);
  std::vector<Footprint> others;
  others.push_back(footprintOf(straightSubframe(1, 1, 99.5, 60.0, M_PI)));   // 40 % overlap
  others.push_back(footprintOf(straightSubframe(2, 2, 99.5, 20.0, M_PI)));   // most overlap
  others.push_back(footprintOf(straightSubframe(3, 3, 99.5, 95.0, M_PI)));   // ~5 %: below min
  others.push_back(footprintOf(straightSubframe(4, 5, 0.0, 0.0, 0.0)));      // same line
  others.push_back(footprintOf(straightSubframe(5, 6, 500.0, 0.0, 0.0)));    // far away
  others.push_back(footprintOf(straightSubframe(6, 7, 99.5, 40.0, M_PI)));
  OverlapOptions options;
  options.max_candidates = 2;
  const auto candidates = findOverlaps(f, others, options);
  ASSERT_EQ(candidates.size(), 2u);
  EXPECT_EQ(candidates[0].subframe_id, 2);
  EXPECT_EQ(candidates[1].subframe_id, 6);
  EXPECT_GT(candidates[0].overlap_fraction, candidates[1].overlap_fraction);
  options.max_candidates = 10;
  const auto all = findOverlaps(f, others, options);
  ASSERT_EQ(all.size(), 3u);  // 2, 6, 1: not the 5 % one, the same line or the far one
  EXPECT_EQ(all[2].subframe_id, 1);
}

TEST(Overlap, FarRangePairsHalfASubframeApartAreCandidatesWithTheFractionOfTheSwath) {
  // Lines 80 m apart with 50 m swaths: the shared strip is 30.1..49.9 m east of A, 41 % of a side's
  // swath (2..49.9 m) but 21 % of the footprint (both sides). Survey lines' subframes rarely meet end
  // to end: B starts half a subframe further north, so the pair shares half of that, 21 % of a
  // swath and 10 % of the footprint, which a fraction of the footprint (15 %) does not match.
  const Footprint a = footprintOf(straightSubframe(0, 0, 0.0, 0.0, 0.0));
  const Footprint aligned = footprintOf(straightSubframe(1, 1, 99.5, 80.0, M_PI));
  const Footprint shifted = footprintOf(straightSubframe(2, 1, 149.25, 80.0, M_PI));
  const double strip_m = 49.9 - 30.1;
  EXPECT_NEAR(overlapAreaM2(a, aligned), strip_m * 99.5, 0.02 * strip_m * 99.5);
  EXPECT_NEAR(overlapAreaM2(a, shifted), strip_m * 49.75, 0.02 * strip_m * 49.75);
  const auto of_footprint = findOverlaps(a, {aligned, shifted}, OverlapOptions{});
  ASSERT_EQ(of_footprint.size(), 1u);
  EXPECT_EQ(of_footprint[0].subframe_id, 1);
  EXPECT_NEAR(of_footprint[0].overlap_fraction, strip_m / (2.0 * (49.9 - 2.0)), 0.02);
  OverlapOptions per_swath;
  per_swath.fraction_of_swath = true;
  const auto candidates = findOverlaps(a, {aligned, shifted}, per_swath);
  ASSERT_EQ(candidates.size(), 2u);
  EXPECT_EQ(candidates[0].subframe_id, 1);
  EXPECT_NEAR(candidates[0].overlap_fraction, strip_m / (49.9 - 2.0), 0.02);
  EXPECT_NEAR(candidates[1].overlap_fraction, 0.5 * strip_m / (49.9 - 2.0), 0.02);
}

TEST(Overlap, OptionsFromConfigNameBadValues) {
  auto config = sss::core::Config::fromString("overlap: {min_overlap_fraction: 1.5, max_candidates: 0}\n");
  auto section = config.section("overlap");
  OverlapOptions options;
  readOverlapOptions(section, options);
  EXPECT_FALSE(config.ok());
  EXPECT_NE(config.problemReport().find("overlap.min_overlap_fraction"), std::string::npos);
  EXPECT_NE(config.problemReport().find("overlap.max_candidates"), std::string::npos);
}

}  // namespace
}  // namespace sss::matcher
