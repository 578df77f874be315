// The RFC 7946 geometry rules on hand-made lines and rings: cut at the antimeridian with the crossing
// latitude interpolated, every vertex wrapped into [-180, 180], rings closed and counterclockwise.
#include "products/geojson_geometry.hpp"

#include <gtest/gtest.h>

#include <vector>

namespace sss::products {
namespace {

// Shoelace on the wrapped vertices: positive when counterclockwise.
double signedArea(const std::vector<LonLat>& ring) {
  double twice = 0.0;
  for (size_t i = 0; i + 1 < ring.size(); ++i)
    twice += ring[i].lon_deg * ring[i + 1].lat_deg - ring[i + 1].lon_deg * ring[i].lat_deg;
  return 0.5 * twice;
}

TEST(AntimeridianCut, ALineThatCrossesNothingComesBackWhole) {
  const std::vector<LonLat> line = {{18.0, 59.0}, {18.1, 59.1}, {18.2, 59.0}};
  const auto pieces = cutLineAtAntimeridian(line);
  ASSERT_EQ(pieces.size(), 1u);
  ASSERT_EQ(pieces[0].size(), 3u);
  EXPECT_DOUBLE_EQ(pieces[0][1].lon_deg, 18.1);
}

TEST(AntimeridianCut, AnEastwardLineEndsAt180AndGoesOnFromMinus180AtTheInterpolatedLatitude) {
  // 179.9 -> 180.3 continuous: the crossing is a quarter of the way, latitude -45 + 0.25 * 0.4.
  const std::vector<LonLat> line = {{179.8, -45.0}, {179.9, -45.0}, {180.3, -44.6}, {180.4, -44.6}};
  const auto pieces = cutLineAtAntimeridian(line);
  ASSERT_EQ(pieces.size(), 2u);
  ASSERT_EQ(pieces[0].size(), 3u);
  ASSERT_EQ(pieces[1].size(), 3u);
  EXPECT_DOUBLE_EQ(pieces[0].back().lon_deg, 180.0);
  EXPECT_NEAR(pieces[0].back().lat_deg, -44.9, 1e-12);
  EXPECT_DOUBLE_EQ(pieces[1].front().lon_deg, -180.0);
  EXPECT_NEAR(pieces[1].front().lat_deg, -44.9, 1e-12);
  EXPECT_NEAR(pieces[1][1].lon_deg, -179.7, 1e-12);
  EXPECT_NEAR(pieces[1][2].lon_deg, -179.6, 1e-12);
}

TEST(AntimeridianCut, ALawnmowerAcrossTheLineIsCutAtEveryCrossingInBothDirections) {
  // East, back west, east again across 180: three crossings, four pieces alternating sides.
  const std::vector<LonLat> line = {{179.9, 10.0}, {180.1, 10.0}, {180.1, 10.01}, {179.9, 10.01},
                                    {179.9, 10.02}, {180.1, 10.02}};
  const auto pieces = cutLineAtAntimeridian(line);
  ASSERT_EQ(pieces.size(), 4u);
  EXPECT_DOUBLE_EQ(pieces[0].back().lon_deg, 180.0);
  EXPECT_DOUBLE_EQ(pieces[1].front().lon_deg, -180.0);
  EXPECT_DOUBLE_EQ(pieces[1].back().lon_deg, -180.0);  // the westward leg back
  EXPECT_DOUBLE_EQ(pieces[2].front().lon_deg, 180.0);
  EXPECT_NEAR(pieces[2].front().lat_deg, 10.01, 1e-12);
  for (const auto& piece : pieces)
    for (const LonLat& p : piece) {
      EXPECT_GE(p.lon_deg, -180.0);
      EXPECT_LE(p.lon_deg, 180.0);
    }
}

TEST(AntimeridianCut, AVertexOnTheMeridianLeavesNoOnePointPiece) {
  const std::vector<LonLat> line = {{179.9, 0.0}, {180.0, 0.0}, {179.9, 0.1}};
  const auto pieces = cutLineAtAntimeridian(line);
  for (const auto& piece : pieces) EXPECT_GE(piece.size(), 2u);
  size_t vertices = 0;
  for (const auto& piece : pieces) vertices += piece.size();
  EXPECT_LE(vertices, 4u);
}

TEST(AntimeridianCut, ARingAcrossTheLineBecomesTwoClosedRingsThatKeepItsArea) {
  // A 0.4 x 0.2 deg footprint from 179.8 to 180.2: halves of 0.2 x 0.2 either side.
  const std::vector<LonLat> ring =
      counterClockwise({{179.8, 50.0}, {179.8, 50.2}, {180.2, 50.2}, {180.2, 50.0}, {179.8, 50.0}});
  const auto pieces = cutRingAtAntimeridian(ring);
  ASSERT_EQ(pieces.size(), 2u);
  for (const auto& piece : pieces) {
    ASSERT_GE(piece.size(), 4u);
    EXPECT_DOUBLE_EQ(piece.front().lon_deg, piece.back().lon_deg);
    EXPECT_DOUBLE_EQ(piece.front().lat_deg, piece.back().lat_deg);
    EXPECT_NEAR(signedArea(piece), 0.04, 1e-9);  // counterclockwise kept
    for (const LonLat& p : piece) {
      EXPECT_GE(p.lon_deg, -180.0);
      EXPECT_LE(p.lon_deg, 180.0);
    }
  }
}

TEST(AntimeridianCut, ARingThatCrossesNothingIsReturnedAsItIs) {
  const std::vector<LonLat> ring = {{10.0, 0.0}, {10.1, 0.0}, {10.1, 0.1}, {10.0, 0.0}};
  const auto pieces = cutRingAtAntimeridian(ring);
  ASSERT_EQ(pieces.size(), 1u);
  EXPECT_EQ(pieces[0].size(), 4u);
}

TEST(RingOrientation, AClockwiseRingIsReversedACounterclockwiseOneKept) {
  const std::vector<LonLat> clockwise = {{0.0, 0.0}, {0.0, 1.0}, {1.0, 1.0}, {1.0, 0.0}, {0.0, 0.0}};
  EXPECT_LT(signedArea(clockwise), 0.0);
  const std::vector<LonLat> turned = counterClockwise(clockwise);
  EXPECT_NEAR(signedArea(turned), 1.0, 1e-12);
  EXPECT_NEAR(signedArea(counterClockwise(turned)), 1.0, 1e-12);
}

TEST(UnwrapLongitude, RunsOnPastTheAntimeridianNearTheReference) {
  EXPECT_NEAR(unwrapLongitudeNear(-179.9, 179.95), 180.1, 1e-12);
  EXPECT_NEAR(unwrapLongitudeNear(179.9, -179.95), -180.1, 1e-12);
  EXPECT_NEAR(unwrapLongitudeNear(18.07, 18.0), 18.07, 1e-12);
}

}  // namespace
}  // namespace sss::products
