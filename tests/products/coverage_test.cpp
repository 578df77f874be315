// Coverage: distinct lines per cell from subframe footprints, the area covered and seen twice.
#include <gtest/gtest.h>

#include <filesystem>

#include "products/coverage.hpp"
#include "tests/support/status_assertions.hpp"

namespace sss::products {
namespace {

// A strip running north from 0 to length_m, between east_min_m and east_max_m.
FootprintStrip strip(int line, double east_min_m, double east_max_m, double north_from_m = 0.0, double length_m = 100.0) {
  FootprintStrip s;
  s.line_id = line;
  for (double n = north_from_m; n <= north_from_m + length_m + 1e-9; n += length_m / 4.0) {
    s.port_ne_m.push_back({n, east_min_m});
    s.starboard_ne_m.push_back({n, east_max_m});
  }
  return s;
}

TEST(Coverage, TwoOverlappingLinesSeeAThirdTwice) {
  // Line 0 over east -50..50, line 1 over 0..100, both 100 m long: 150 x 100 covered, 50 x 100 twice.
  const CoverageGrid grid = computeCoverage({strip(0, -50.0, 50.0), strip(1, 0.0, 100.0)}, 1.0);
  EXPECT_NEAR(grid.covered_m2, 15000.0, 400.0);  // cell centres on the edges: a cell's width around them
  EXPECT_NEAR(grid.seen_twice_m2, 5000.0, 250.0);
  EXPECT_NEAR(grid.fractionSeenTwice(), 1.0 / 3.0, 0.02);
  // A cell inside both, one inside line 0 only, one outside.
  auto at = [&](double north, double east) {
    const int r = static_cast<int>(std::lround((north - grid.north_min_m) / grid.resolution_m));
    const int c = static_cast<int>(std::lround((east - grid.east_min_m) / grid.resolution_m));
    return grid.lines[static_cast<size_t>(r) * grid.cols + c];
  };
  EXPECT_EQ(at(50.0, 25.0), 2);
  EXPECT_EQ(at(50.0, -25.0), 1);
  EXPECT_EQ(grid.lines.size(), static_cast<size_t>(grid.rows) * grid.cols);
}

TEST(Coverage, SubframesOfOneLineCountOnce) {
  // Two subframes of the same line overlapping along track, and a second line beside: the along-track
  // overlap is one line's, not two.
  const CoverageGrid grid =
      computeCoverage({strip(3, 0.0, 40.0, 0.0, 60.0), strip(3, 0.0, 40.0, 40.0, 60.0), strip(4, 60.0, 100.0)}, 1.0);
  EXPECT_NEAR(grid.seen_twice_m2, 0.0, 1e-9);
  EXPECT_NEAR(grid.covered_m2, 40.0 * 100.0 + 40.0 * 100.0, 400.0);
}

TEST(Coverage, FilesAreWrittenAndNothingIsAnError) {
  const CoverageGrid grid = computeCoverage({strip(0, -50.0, 50.0), strip(1, 0.0, 100.0)}, 5.0);
  const std::string dir = (std::filesystem::temp_directory_path() / "sss_coverage_test").string();
  std::filesystem::create_directories(dir);
  ASSERT_OK(writeCoverageFiles(dir + "/coverage.yaml", grid, sss::core::MissionOrigin{59.35, 18.07}));
  EXPECT_EQ(std::filesystem::file_size(dir + "/coverage_lines.u8"), grid.lines.size());
  EXPECT_TRUE(std::filesystem::is_regular_file(dir + "/coverage.png"));
  std::filesystem::remove_all(dir);
  const CoverageGrid empty = computeCoverage({}, 5.0);
  EXPECT_EQ(empty.rows, 0);
  const sss::core::Status nothing = writeCoverageFiles(dir + "/none.yaml", empty, std::nullopt);
  EXPECT_FALSE(nothing.ok);
  EXPECT_NE(nothing.message.find("no cells"), std::string::npos) << nothing.message;
}

}  // namespace
}  // namespace sss::products
