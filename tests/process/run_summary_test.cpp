// The findings of a run that found no pair to match: the advice follows the configuration (a
// swath that already follows the sonar's range is not to be widened again); a survey cut into
// pieces by slow turns is said to be.
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

// A ship's wide turns (0.015 rad/s, under the 0.02 rad/s turn threshold) cut into one-subframe
// lines, as on randomised seed 3798961521 (49 lines of a 4-line survey): said, with the option.
TEST(RunSummary, MostLinesShorterThanASubframeAreExplainedAsSlowTurns) {
  OfflineSummary s = linesTooFarApartForTheirOverlap();
  s.pairs_attempted = 31;
  s.matcher_closures = 26;
  s.closures_accepted = 13;
  s.survey_lines = 49;
  s.short_lines = 45;
  const std::vector<std::string> findings = explainRun(s, Options{});
  ASSERT_FALSE(findings.empty());
  EXPECT_NE(findings[0].find("45 of the 49 survey lines hold less than one subframe"), std::string::npos) << findings[0];
  EXPECT_NE(findings[0].find("max_heading_rate_rad_s (0.02 rad/s)"), std::string::npos) << findings[0];

  // A survey of straight lines with the odd short one says nothing of it.
  s.survey_lines = 6;
  s.short_lines = 2;
  for (const std::string& finding : explainRun(s, Options{}))
    EXPECT_EQ(finding.find("less than one subframe"), std::string::npos) << finding;
}

}  // namespace
}  // namespace sss::offline
