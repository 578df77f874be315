// Dense matcher on synthetic lawnmower pairs with exact ground truth: accuracy for parallel and
// anti-parallel lines under DR error, rejection of wrong pairs, masks, determinism, options.
#include "pipeline/matcher/dense_matcher.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "pipeline/matcher/synthetic_pair.hpp"

namespace sss::matcher {
namespace {

using synthetic::Direction;

// A smaller pair than the 200 x 2600 so the suite stays fast: 120 pings, 65 m per side,
// lines 60 m apart (about 54% overlap).
synthetic::SurveyLine smallLine() {
  synthetic::SurveyLine line;
  line.rows = 120;
  line.columns_per_side = 500;
  return line;
}

struct Pair {
  synthetic::SurveyLine line_a, line_b;
  GeoImage a, b;
};

// Each image is geo-referenced with its true positions plus a DR error; the error between the
// two is dr_error_m (60% along-track, 80% across) and a 0.2 degree rotation.
Pair makePair(Direction direction, double dr_error_m, const synthetic::Seabed& seabed_a,
              const synthetic::Seabed& seabed_b, double line_spacing_m = 60.0) {
  Pair pair;
  pair.line_a = smallLine();
  pair.line_b = synthetic::secondLine(pair.line_a, direction, line_spacing_m, 2.0);
  synthetic::RenderOptions render_a, render_b;
  render_a.speckle_seed = 11;
  render_b.speckle_seed = 12;
  render_b.gain = 0.7;
  pair.a = synthetic::render(seabed_a, pair.line_a, render_a);
  pair.b = synthetic::render(seabed_b, pair.line_b, render_b);
  synthetic::addDrError(pair.a, {0.4, -0.2}, 0.001);
  synthetic::addDrError(pair.b, {0.4 + 0.6 * dr_error_m, -0.2 + 0.8 * dr_error_m}, -0.0025);
  return pair;
}

synthetic::Seabed seabed(std::uint64_t seed) {
  synthetic::Seabed s;
  s.seed = seed;
  return s;
}

TEST(DenseMatcher, ParallelAndAntiParallelMatchWithinTwoPixelsUnderDrErrorUpTo5m) {
  const DenseMatcher matcher{DenseMatcherOptions{}};
  for (const Direction direction : {Direction::kParallel, Direction::kAntiParallel}) {
    for (const double dr_error_m : {0.0, 2.0, 5.0}) {
      const Pair pair = makePair(direction, dr_error_m, seabed(3), seabed(3));
      MatchTimings timings;
      const std::vector<Correspondence> matches = matcher.match(pair.a, pair.b, &timings);
      const synthetic::Evaluation e = synthetic::evaluate(matches, pair.line_a, pair.a, pair.line_b, pair.b,
                                                          matcher.options().stride, matcher.options().patch_size, 2.0);
      const char* name = direction == Direction::kParallel ? "parallel" : "anti-parallel";
      std::printf("%-13s DR error %.0f m: %ld matches, within 2 px %.3f, recall %.3f, %.3f s\n", name, dr_error_m,
                  e.matches, e.withinFraction(), e.recall(), timings.total_s);
      SCOPED_TRACE(std::string(name) + " at " + std::to_string(dr_error_m) + " m");
      EXPECT_GE(e.withinFraction(), 0.8);  // the matcher's acceptance
      // Patches straddling nadir, B's border or too little texture are rightly rejected; most of
      // the overlap must still be matched correctly.
      EXPECT_GE(e.recall(), 0.5);
    }
  }
}

TEST(DenseMatcher, TextureFreeSeabedYieldsFewMatches) {
  synthetic::Seabed flat;
  flat.flat = true;  // speckle only: nothing repeatable to correlate
  const Pair pair = makePair(Direction::kParallel, 2.0, flat, flat);
  MatchTimings timings;
  const std::vector<Correspondence> matches = DenseMatcher(DenseMatcherOptions{}).match(pair.a, pair.b, &timings);
  ASSERT_GT(timings.overlapping_pixels, 10000);
  EXPECT_LT(static_cast<double>(matches.size()), 0.01 * timings.overlapping_pixels);
}

TEST(DenseMatcher, PatchesOfOneStraightFeatureAreNotMatchedWithTheApertureCheck) {
  // One straight diagonal line on a flat bed, the same in both images, B geo-referenced 2 m off
  // along the line: every patch on it fits anywhere along the line (the aperture problem), so a
  // match there says nothing about the offset. Without the check they match; with it they do not.
  GeoImage a;
  const int rows = 80, cols = 80;
  a.intensity = cv::Mat1f(rows, cols, 0.5f);
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      const float distance = std::abs(static_cast<float>(r - c)) / std::sqrt(2.0f);
      a.intensity(r, c) += 0.5f * std::exp(-distance * distance / 2.0f);
    }
  }
  a.valid = cv::Mat1b(rows, cols, 255);
  a.position_ne_m = cv::Mat2f(rows, cols);
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) a.position_ne_m(r, c) = cv::Vec2f(0.5f * r, 0.5f * c);
  a.heading_rad = cv::Mat1f(rows, 1, 0.0f);
  GeoImage b = a;
  b.intensity = a.intensity.clone();
  b.position_ne_m = a.position_ne_m.clone();
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) b.position_ne_m(r, c) += cv::Vec2f(1.41f, 1.41f);  // 2 m along the line
  DenseMatcherOptions options;
  options.patch_size = 13;
  options.max_dr_error_m = 3.0;
  const size_t without_check = DenseMatcher(options).match(a, b).size();
  options.min_structure_ratio = 0.2;
  const size_t with_check = DenseMatcher(options).match(a, b).size();
  std::printf("straight feature: %zu matches without the aperture check, %zu with it\n", without_check, with_check);
  EXPECT_GT(without_check, 50u);
  EXPECT_EQ(with_check, 0u);
}

TEST(DenseMatcher, WrongPairWithClaimedOverlapYieldsFewMatches) {
  // The geo-references say the images overlap, but B shows a different piece of seabed.
  // Known limit (see report): chance correlations that are locally coherent survive ZNCC, FB and
  // coherence checks at ~5% of a true pair's count; they share no common offset, so the RANSAC
  // relative pose has to reject the pair. Here: an order of magnitude fewer than a true pair.
  const Pair pair = makePair(Direction::kAntiParallel, 2.0, seabed(3), seabed(99));
  const Pair true_pair = makePair(Direction::kAntiParallel, 2.0, seabed(3), seabed(3));
  MatchTimings timings;
  const DenseMatcher matcher{DenseMatcherOptions{}};
  const std::vector<Correspondence> matches = matcher.match(pair.a, pair.b, &timings);
  const std::vector<Correspondence> true_matches = matcher.match(true_pair.a, true_pair.b);
  std::printf("wrong pair: %zu matches, true pair: %zu, overlap %ld\n", matches.size(), true_matches.size(),
              timings.overlapping_pixels);
  ASSERT_GT(timings.overlapping_pixels, 10000);
  EXPECT_LT(static_cast<double>(matches.size()), 0.1 * static_cast<double>(true_matches.size()));
}

TEST(DenseMatcher, GeoReferencesWithoutOverlapYieldNoMatches) {
  const Pair pair = makePair(Direction::kParallel, 0.0, seabed(3), seabed(3), 400.0);
  MatchTimings timings;
  EXPECT_TRUE(DenseMatcher(DenseMatcherOptions{}).match(pair.a, pair.b, &timings).empty());
  EXPECT_EQ(timings.overlapping_pixels, 0);
}

TEST(DenseMatcher, MaskedPixelsAreNeverMatched) {
  Pair pair = makePair(Direction::kAntiParallel, 2.0, seabed(3), seabed(3));
  synthetic::maskRows(pair.a, 30, 45);  // e.g. a turn
  synthetic::maskRows(pair.b, 70, 90);
  const std::vector<Correspondence> matches = DenseMatcher(DenseMatcherOptions{}).match(pair.a, pair.b);
  ASSERT_GT(matches.size(), 1000u);
  for (const Correspondence& m : matches) {
    ASSERT_TRUE(pair.a.valid(static_cast<int>(m.row_a), static_cast<int>(m.col_a)));
    const int row_b = static_cast<int>(std::lround(m.row_b)), col_b = static_cast<int>(std::lround(m.col_b));
    ASSERT_TRUE(row_b >= 0 && col_b >= 0 && row_b < pair.b.valid.rows && col_b < pair.b.valid.cols);
    ASSERT_TRUE(pair.b.valid(row_b, col_b)) << "B pixel " << row_b << ", " << col_b;
    ASSERT_GE(m.zncc, DenseMatcherOptions{}.min_zncc);
  }
}

TEST(DenseMatcher, SameMatchesForOneAndTwoThreads) {
  const Pair pair = makePair(Direction::kParallel, 5.0, seabed(3), seabed(3));
  DenseMatcherOptions one, two;
  one.threads = 1;
  two.threads = 2;
  const std::vector<Correspondence> a = DenseMatcher(one).match(pair.a, pair.b);
  const std::vector<Correspondence> b = DenseMatcher(two).match(pair.a, pair.b);
  ASSERT_EQ(a.size(), b.size());
  ASSERT_GT(a.size(), 1000u);
  for (std::size_t i = 0; i < a.size(); ++i) {
    ASSERT_EQ(a[i].row_a, b[i].row_a);
    ASSERT_EQ(a[i].col_a, b[i].col_a);
    ASSERT_EQ(a[i].row_b, b[i].row_b);
    ASSERT_EQ(a[i].col_b, b[i].col_b);
    ASSERT_EQ(a[i].zncc, b[i].zncc);
  }
}

TEST(DenseMatcher, ImagesWithMismatchedMatricesAreRejected) {
  Pair pair = makePair(Direction::kParallel, 0.0, seabed(3), seabed(3));
  pair.b.valid = cv::Mat1b(10, 10, 255);
  EXPECT_THROW(DenseMatcher(DenseMatcherOptions{}).match(pair.a, pair.b), std::invalid_argument);
}

TEST(DenseMatcherOptions, ConfigFillsOptionsAndNamesBadValues) {
  sss::core::Config config =
      sss::core::Config::fromString("matcher:\n  patch_size: 15\n  max_dr_error_m: 3.5\n  threads: 1\n");
  sss::core::ConfigSection section = config.section("matcher");
  DenseMatcherOptions options;
  readDenseMatcherOptions(section, options);
  ASSERT_TRUE(config.ok()) << config.problemReport();
  EXPECT_EQ(options.patch_size, 15);
  EXPECT_DOUBLE_EQ(options.max_dr_error_m, 3.5);
  EXPECT_EQ(options.threads, 1);
  EXPECT_TRUE(validateDenseMatcherOptions(options).empty());

  sss::core::Config bad = sss::core::Config::fromString("matcher:\n  patch_size: 12\n");
  sss::core::ConfigSection bad_section = bad.section("matcher");
  readDenseMatcherOptions(bad_section, options);
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.problemReport().find("matcher.patch_size"), std::string::npos);

  DenseMatcherOptions even;
  even.patch_size = 12;
  EXPECT_THROW(DenseMatcher{even}, std::invalid_argument);
}

}  // namespace
}  // namespace sss::matcher
