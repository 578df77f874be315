// The findings of a run that found no pair to match: the advice follows the configuration (a
// swath that already follows the sonar's range is not to be widened again).
#include "tools/process/run_summary.hpp"

#include <gtest/gtest.h>

namespace sss::offline {
namespace {

OfflineSummary linesTooFarApartForTheirOverlap() {
  OfflineSummary s;
  s.pings = 10490;
  s.pings_with_pose = 10490;
  s.subframes = 107;
  s.survey_lines = 6;
  s.pairs_attempted = 0;
  s.canonical_swath_m = 141.0;
  s.nearest_other_line_m = 136.0;  // within twice the swath, but too little overlap for a pair
  return s;
}

TEST(RunSummary, NoPairWithTheSwathFollowingTheRangeAsksForOverlapNotAWiderSwath) {
  Options options;
  options.buffer.canonical.swath_from_range = true;
  const std::vector<std::string> findings = explainRun(linesTooFarApartForTheirOverlap(), options);
  ASSERT_EQ(findings.size(), 1u);
  EXPECT_NE(findings[0].find("no pair to match"), std::string::npos) << findings[0];
  EXPECT_NE(findings[0].find("min_overlap_fraction"), std::string::npos) << findings[0];
  EXPECT_EQ(findings[0].find("swath_from_range"), std::string::npos) << "already on: " << findings[0];
}

TEST(RunSummary, NoPairWithAFixedSwathNamesTheOptionThatWidensIt) {
  Options options;
  options.buffer.canonical.swath_from_range = false;
  const std::vector<std::string> findings = explainRun(linesTooFarApartForTheirOverlap(), options);
  ASSERT_EQ(findings.size(), 1u);
  EXPECT_NE(findings[0].find("swath_from_range: true"), std::string::npos) << findings[0];
}

}  // namespace
}  // namespace sss::offline
