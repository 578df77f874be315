// Matching accuracy: pair types by heading, and sss-eval's evaluation of sss-process's matches.csv
// against the same figures computed in process, on a parallel and a crossing pair of a small
// simulated cross survey (integration: renders ~1800 pings and matches two pairs, a few seconds).
#include "tools/eval/match_metrics.hpp"
#include "tools/eval/survey_footprints.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "pipeline/matcher/overlap.hpp"
#include "pipeline/matcher/pair_matcher.hpp"
#include "pipeline/core/georeference.hpp"
#include "tools/process/match_writer.hpp"
#include "tools/sim/simulated_survey.hpp"
#include "tests/support/status_assertions.hpp"

namespace sss::eval {
namespace {

namespace fs = std::filesystem;

double deg(double d) { return d * M_PI / 180.0; }

TEST(ClassifyPair, SplitsByHeadingDifferenceAcrossTheWrap) {
  EXPECT_EQ(classifyPair(deg(0), deg(30)), PairType::kParallel);
  EXPECT_EQ(classifyPair(deg(350), deg(10)), PairType::kParallel);
  EXPECT_EQ(classifyPair(deg(0), deg(31)), PairType::kCrossing);
  EXPECT_EQ(classifyPair(deg(10), deg(100)), PairType::kCrossing);
  EXPECT_EQ(classifyPair(deg(0), deg(149)), PairType::kCrossing);
  EXPECT_EQ(classifyPair(deg(0), deg(150)), PairType::kAntiParallel);
  EXPECT_EQ(classifyPair(deg(-170), deg(170)), PairType::kParallel);
  EXPECT_EQ(classifyPair(deg(90), deg(-90)), PairType::kAntiParallel);
  EXPECT_STREQ(pairTypeName(PairType::kAntiParallel), "anti_parallel");
}

TEST(MatchFile, EvaluationFromTheFileEqualsTheInProcessOne) {
  // Two 200 m lines 40 m apart and two crossing lines 120 m long (one full subframe each).
  sss::sim::SimOptions sim;
  sim.trajectory.pattern = "cross";
  sim.trajectory.lines = 2;
  sim.trajectory.line_length_m = 200.0;
  sim.trajectory.line_spacing_m = 40.0;
  const sss::sim::SimulatedSurvey survey = sss::sim::simulateSurvey(sim);

  // The best-overlapping full pair of each type present (anti-parallel and crossing here).
  const SurveyFootprints candidates = fullSubframeFootprints(survey, sss::matcher::OverlapOptions());
  const std::vector<const sss::core::Subframe*>& full = candidates.subframes;
  const std::vector<sss::matcher::Footprint>& footprints = candidates.footprints;
  std::pair<size_t, size_t> best[kPairTypes];
  double best_area[kPairTypes] = {0.0, 0.0, 0.0};
  for (size_t i = 0; i < full.size(); ++i) {
    for (size_t j = i + 1; j < full.size(); ++j) {
      if (full[i]->line_id == full[j]->line_id) continue;
      const int type = static_cast<int>(classifyPair(*full[i], *full[j]));
      const double area = sss::matcher::overlapAreaM2(footprints[i], footprints[j]);
      if (area > best_area[type]) best_area[type] = area, best[type] = {i, j};
    }
  }
  ASSERT_GT(best_area[static_cast<int>(PairType::kAntiParallel)], 0.0);
  ASSERT_GT(best_area[static_cast<int>(PairType::kCrossing)], 0.0);

  const fs::path dir = fs::temp_directory_path() / "sss_match_metrics_test";
  fs::create_directories(dir);
  {
    // The mission folder as sss-sim writes it, as far as the evaluation reads it.
    std::ofstream yaml(dir / "mission.yaml");
    yaml << "sim:\n";
    std::istringstream sim_yaml(sss::sim::simOptionsYaml(survey.mission->options()));
    for (std::string line; std::getline(sim_yaml, line);) yaml << "  " << line << "\n";
  }
  const sss::matcher::PairMatcherOptions options;
  const sss::matcher::DenseMatcher dense(options.dense);
  sss::offline::MatchCsvWriter writer;
  ASSERT_OK(writer.open((dir / "matches.csv").string(), options.dense.stride, 4));
  std::vector<MatchEvaluation> in_process;
  for (const PairType type : {PairType::kAntiParallel, PairType::kCrossing}) {
    const auto& a = *full[best[static_cast<int>(type)].first];
    const auto& b = *full[best[static_cast<int>(type)].second];
    const auto match = sss::matcher::matchPair(a, sss::core::drPoses(a), b, sss::sim::posesWithDrError(a, b, 3.0, 2.0),
                                               dense, options);
    in_process.push_back(evaluateMatches(survey, a, b, match.matches, options.dense.stride, match.decimation));
    writer.addPair(a, b, 0, match);
    const MatchEvaluation& e = in_process.back();
    if (type == PairType::kAntiParallel) {
      // The signed biases: every match moved half a metre nearer B's track (8 bins of 6 cm) moves
      // the mean outward error by exactly that and the along-track one not at all.
      std::vector<sss::matcher::Correspondence> nearer = match.matches;
      const double bins = 8.0;
      for (auto& m : nearer) m.col_b += static_cast<float>(m.col_b < b.geometry.bins_per_side ? bins : -bins);
      const MatchEvaluation shifted = evaluateMatches(survey, a, b, nearer, options.dense.stride, match.decimation);
      ASSERT_EQ(shifted.evaluated, e.evaluated);
      EXPECT_NEAR(shifted.meanOutwardErrorM() - e.meanOutwardErrorM(), bins * b.geometry.bin_size_m, 1e-6);
      EXPECT_NEAR(shifted.meanAlongErrorM(), e.meanAlongErrorM(), 1e-9);
      // Matches as good as these are not off by a systematic half metre to begin with.
      EXPECT_LT(std::abs(e.meanOutwardErrorM()), 0.3);
    }
    std::printf("%s pair %lld-%lld: %ld matches, within 2 px %.3f, recall %.3f, EPE %.2f px %.3f m\n",
                pairTypeName(type), static_cast<long long>(a.id), static_cast<long long>(b.id), e.matches,
                e.withinFraction(), e.recall(), e.meanErrorPx(), e.meanErrorM());
    std::printf("  bias along %+.3f m, outward %+.3f m\n", e.meanAlongErrorM(), e.meanOutwardErrorM());
  }
  ASSERT_OK(writer.close());
  std::string error;

  MatchFileEvaluation file;
  ASSERT_OK(evaluateMatchFile((dir / "matches.csv").string(), dir.string(), file));
  ASSERT_EQ(file.pairs.size(), 2u);
  EXPECT_EQ(file.pairs[0].type, PairType::kAntiParallel);
  EXPECT_EQ(file.pairs[1].type, PairType::kCrossing);
  EXPECT_EQ(file.pairs_by_type[static_cast<int>(PairType::kCrossing)], 1);
  for (size_t k = 0; k < 2; ++k) {
    const MatchEvaluation& expected = in_process[k];
    const MatchEvaluation& got = file.pairs[k].evaluation;
    EXPECT_GT(expected.evaluated, 100) << k;  // something to compare
    EXPECT_EQ(got.matches, expected.matches) << k;
    EXPECT_EQ(got.evaluated, expected.evaluated) << k;
    EXPECT_EQ(got.within_2px, expected.within_2px) << k;
    EXPECT_EQ(got.probes, expected.probes) << k;
    EXPECT_EQ(got.matchable, expected.matchable) << k;
    // The file keeps every input exactly (floats round-trip, altitudes at 17 digits).
    EXPECT_NEAR(got.error_sum_px, expected.error_sum_px, 1e-9 * expected.error_sum_px) << k;
    EXPECT_NEAR(got.error_sum_m, expected.error_sum_m, 1e-9 * expected.error_sum_m) << k;
    EXPECT_NEAR(got.along_error_sum_m, expected.along_error_sum_m, 1e-9 * expected.error_sum_m) << k;
    EXPECT_NEAR(got.outward_error_sum_m, expected.outward_error_sum_m, 1e-9 * expected.error_sum_m) << k;
  }
  EXPECT_EQ(file.overall.within_2px, in_process[0].within_2px + in_process[1].within_2px);
  EXPECT_NEAR(file.matching_pixel_m, 0.48, 1e-9);  // 8 bins of 6 cm

  // A damaged row is refused with its line number.
  {
    std::ofstream append(dir / "matches.csv", std::ios::app);
    append << "match,1,2,0,abc,1,1,1,0,0,port,port,0,0,0,0,0,0,0,1,\n";
  }
  error = sss::testing::failureMessage(evaluateMatchFile((dir / "matches.csv").string(), dir.string(), file));
  EXPECT_NE(error.find("matches.csv:"), std::string::npos) << error;
  EXPECT_NE(error.find("row_a is not a number"), std::string::npos) << error;
  fs::remove_all(dir);
}

}  // namespace
}  // namespace sss::eval
