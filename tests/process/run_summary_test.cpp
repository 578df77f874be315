// The findings of a run that found no pair to match: the advice follows the configuration (a
// swath that already follows the sonar's range is not to be widened again); a survey cut into
// pieces by slow turns is said to be; closures that wait for support are not called rejected.
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

// Closures that only wait for independent support (randomised rock_outcrops-1901767246: two
// closures, each the only one of its line pair) are not said to be rejected: nothing found them
// wrong, and the advice is more overlap. Rejected ones are said to be, with both counts.
TEST(RunSummary, ClosuresStillWaitingForSupportAreNotCalledRejected) {
  OfflineSummary s = linesTooFarApartForTheirOverlap();
  s.pairs_attempted = 6;
  s.matcher_closures = 2;
  s.closures_pending = 2;
  Options options;
  options.optimiser.graph.min_consistent_closures = 2;
  options.optimiser.graph.pcm_count_independent_subframes = true;
  std::vector<std::string> findings = explainRun(s, options);
  ASSERT_EQ(findings.size(), 1u);
  EXPECT_NE(findings[0].find("no closure accepted"), std::string::npos) << findings[0];
  EXPECT_EQ(findings[0].find("rejected"), std::string::npos) << findings[0];
  EXPECT_NE(findings[0].find("2 closures still wait for support"), std::string::npos) << findings[0];
  EXPECT_NE(findings[0].find("2 mutually consistent closures through different subframes"), std::string::npos)
      << findings[0];
  EXPECT_NE(findings[0].find("min_consistent_closures"), std::string::npos) << findings[0];

  s.closures_pending = 1;
  s.closures_rejected = 1;
  findings = explainRun(s, options);
  ASSERT_EQ(findings.size(), 1u);
  EXPECT_NE(findings[0].find("rejected 1 (inconsistent"), std::string::npos) << findings[0];
  EXPECT_NE(findings[0].find("1 closure still waits for support"), std::string::npos) << findings[0];
  EXPECT_NE(findings[0].find("would give it support"), std::string::npos) << findings[0];
}

}  // namespace
}  // namespace sss::offline
