// The matcher engine on a simulated three-line survey: subframes arrive in order, closures appear
// only between overlapping lines and agree with the truth, the covariance is consistent over the
// batch, optimised poses trigger the re-association round, memory stays bounded; an engine restored
// from its state directory continues where the previous one stopped.
#include "pipeline/matcher/matcher_engine.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <set>

#include "tests/matcher/matcher_test_survey.hpp"
#include "tests/support/status_assertions.hpp"

namespace sss::matcher {
namespace {

struct Check {
  int accepted = 0;
  // Largest along- or across-track error (the matcher's acceptance: "within 0.3 m in both directions") over
  // closures between two full (200-ping) subframes.
  double max_horizontal_error_m = 0.0;
  double max_nees = 0.0;
  double nees_sum = 0.0;  // horizontal translation, 2 dof
};

Check checkAgainstTruth(const std::vector<PairOutcome>& outcomes, const sss::sim::SimulatedSurvey& survey) {
  const sss::sim::SubframeTruth truth(*survey.mission);
  auto find = [&](int64_t id) -> const sss::core::Subframe& {
    for (const auto& s : survey.subframes) {
      if (s.id == id) return s;
    }
    throw std::runtime_error("unknown subframe");
  };
  Check check;
  for (const PairOutcome& o : outcomes) {
    const auto& a = find(o.subframe_id_a);
    const auto& b = find(o.subframe_id_b);
    if (!o.accepted) {
      std::printf("  pair %lld-%lld (lines %d-%d, rows %d/%d, round %d): rejected: %s\n", (long long)o.subframe_id_a,
                  (long long)o.subframe_id_b, a.line_id, b.line_id, a.rows(), b.rows(), o.association_round,
                  o.reason.c_str());
      continue;
    }
    ++check.accepted;
    EXPECT_NE(a.line_id, b.line_id);
    const Eigen::Vector3d error = o.closure.T_a_b.translation - truth.trueRelativePose(a, b).translation;
    const Eigen::Vector2d e2 = error.head<2>();
    const double nees = e2.transpose() * o.closure.covariance.topLeftCorner<2, 2>().inverse() * e2;
    check.nees_sum += nees;
    if (a.rows() == 200 && b.rows() == 200)
      check.max_horizontal_error_m = std::max(check.max_horizontal_error_m, e2.cwiseAbs().maxCoeff());
    check.max_nees = std::max(check.max_nees, nees);
    std::printf("  pair %lld-%lld (lines %d-%d, rows %d/%d, round %d): %d inliers of %d, error [%.3f %.3f %.3f] m, "
                "sigma [%.3f %.3f], NEES %.2f, %.2f s\n",
                (long long)o.subframe_id_a, (long long)o.subframe_id_b, a.line_id, b.line_id, a.rows(), b.rows(),
                o.association_round, o.closure.num_inliers, o.closure.num_matches, error.x(), error.y(), error.z(),
                std::sqrt(o.closure.covariance(0, 0)), std::sqrt(o.closure.covariance(1, 1)), nees, o.seconds);
    // Every inlier up to the cap goes to the optimiser's point cloud.
    EXPECT_EQ(o.closure.correspondences.size(),
              std::min<size_t>(o.closure.num_inliers, MatcherEngineOptions{}.max_closure_correspondences));
    for (const ClosureCorrespondence& c : o.closure.correspondences) EXPECT_TRUE(c.landmark_a_m.allFinite());
  }
  return check;
}

TEST(MatcherEngine, SurveyClosuresAgreeWithTheTruthAndReassociationRunsOnOptimisedPoses) {
  const auto& survey = test::threeLineSurvey();
  MatcherEngine engine{MatcherEngineOptions{}};
  std::vector<PairOutcome> outcomes;
  // DR error between the lines: line k is off by k * (2 m north, 1.5 m east) on top of the
  // simulated drift (which is only ~0.2 m on this short survey).
  for (auto s : survey.subframes) {
    const Eigen::Vector3d offset = s.line_id * Eigen::Vector3d(2.0, 1.5, 0.0);
    for (auto& ping : s.pings) ping.T_world_body.translation += offset;
    for (auto& o : engine.addSubframe(s)) outcomes.push_back(std::move(o));
  }
  std::printf("DR round: %zu pairs\n", outcomes.size());
  const Check dr = checkAgainstTruth(outcomes, survey);
  // Lines 0-1, 1-2 (anti-parallel) and 0-2 (parallel) each overlap in their full subframes.
  EXPECT_GE(dr.accepted, 3);
  // The matcher's acceptance: within 0.3 m for full subframe pairs. A line's 50-99 ping tail constrains heading,
  // and through it the along-track lever, less: up to ~1 m, which its covariance says (every
  // closure within the chi-square 2-dof 99.9 % bound, 13.8).
  EXPECT_LT(dr.max_horizontal_error_m, 0.3);
  EXPECT_LT(dr.max_nees, 13.8);
  EXPECT_EQ(engine.counters().closures_accepted, static_cast<uint64_t>(dr.accepted));

  // The optimiser's answer, here the truth: every pair moved by the DR error is re-matched once.
  std::vector<TrajectoryNode> nodes;
  for (const auto& s : survey.subframes) {
    nodes.push_back({s.id, s.centre().utime_us, sss::sim::truePoses(*survey.mission, s)[s.centre_ping_index]});
  }
  const std::vector<PairOutcome> round1 = engine.updateTrajectory(nodes);
  std::printf("round 1: %zu pairs\n", round1.size());
  const Check reassociated = checkAgainstTruth(round1, survey);
  // Pairs between lines that moved relative to each other (all but none: every line moved).
  EXPECT_GE(reassociated.accepted, dr.accepted - 1);
  for (const auto& o : round1) EXPECT_EQ(o.association_round, 1);
  EXPECT_LT(reassociated.max_horizontal_error_m, 0.3);
  EXPECT_LT(reassociated.max_nees, 13.8);
  // The same poses again: nothing moved, nothing re-matched.
  EXPECT_TRUE(engine.updateTrajectory(nodes).empty());

  const int total = dr.accepted + reassociated.accepted;
  const double mean_nees = (dr.nees_sum + reassociated.nees_sum) / std::max(total, 1);
  std::printf("mean horizontal NEES %.2f over %d closures (2 for a consistent covariance)\n", mean_nees, total);
  // Consistent within the spread of a batch of ~16 closures (chi-square 2 dof: mean 2).
  EXPECT_LT(mean_nees, 6.0);
  EXPECT_GT(mean_nees, 0.3);
}

TEST(MatcherEngine, StoredSubframesAreBoundedAndMalformedOnesRejected) {
  const auto& survey = test::threeLineSurvey();
  MatcherEngineOptions options;
  options.max_stored_subframes = 2;
  options.overlap.min_overlap_fraction = 0.99;  // no matching: this test is about storage
  MatcherEngine engine(options);
  for (const auto& s : survey.subframes) engine.addSubframe(s);
  EXPECT_EQ(engine.storedSubframes(), 2u);
  EXPECT_EQ(engine.counters().subframes_evicted, survey.subframes.size() - 2);
  EXPECT_LT(engine.memoryBytes(), 2u * 3u * 1024u * 1024u);
  sss::core::Subframe broken = survey.subframes.front();
  broken.id = 1000;
  broken.mask.pop_back();
  EXPECT_TRUE(engine.addSubframe(broken).empty());
  EXPECT_TRUE(engine.addSubframe(survey.subframes.back()).empty());  // a duplicate id
  EXPECT_EQ(engine.counters().subframes_rejected, 2u);
}

TEST(MatcherEngine, StoredSubframesAreBoundedByMemoryWhateverTheirCount) {
  const auto& survey = test::threeLineSurvey();
  ASSERT_GE(survey.subframes.size(), 5u);
  const auto mib = [](size_t bytes) { return static_cast<double>(bytes) / (1024.0 * 1024.0); };
  MatcherEngineOptions options;
  options.overlap.min_overlap_fraction = 0.99;  // no matching: this test is about storage
  // What the whole survey takes when nothing bounds it, and the largest subframe (a full one).
  MatcherEngine unbounded(options);
  for (const auto& s : survey.subframes) unbounded.addSubframe(s);
  ASSERT_EQ(unbounded.storedSubframes(), survey.subframes.size());
  MatcherEngine one(options);
  one.addSubframe(survey.subframes.front());
  ASSERT_EQ(survey.subframes.front().rows(), 200);
  const double largest_mib = mib(one.memoryBytes());

  // Half the survey's memory: the count would allow them all, the memory does not.
  options.max_stored_subframes = 1000;
  options.max_stored_mib = 0.5 * mib(unbounded.memoryBytes());
  MatcherEngine engine(options);
  for (const auto& s : survey.subframes) engine.addSubframe(s);
  EXPECT_LT(engine.storedSubframes(), survey.subframes.size());
  EXPECT_EQ(engine.counters().subframes_evicted, survey.subframes.size() - engine.storedSubframes());
  EXPECT_LE(mib(engine.memoryBytes()), options.max_stored_mib);
  // Only what had to go went: one more subframe would not have fitted.
  EXPECT_GT(mib(engine.memoryBytes()) + largest_mib, options.max_stored_mib);

  // A budget below two subframes still keeps two (a pair needs them).
  options.max_stored_mib = 0.5 * largest_mib;
  MatcherEngine tight(options);
  for (const auto& s : survey.subframes) tight.addSubframe(s);
  EXPECT_EQ(tight.storedSubframes(), 2u);

  options.max_stored_mib = 0.0;
  EXPECT_THROW(MatcherEngine{options}, std::invalid_argument);
}

// ---- restarts ---------------------------------------------------------------------------------

namespace fs = std::filesystem;
using PairIds = std::set<std::pair<int64_t, int64_t>>;

using test::surveySubframe;  // line k off by k * (2 m north, 1.5 m east), as above

std::vector<TrajectoryNode> trueNodes(const std::vector<int64_t>& ids) {
  const auto& survey = test::threeLineSurvey();
  std::vector<TrajectoryNode> nodes;
  for (const auto& s : survey.subframes) {
    if (std::find(ids.begin(), ids.end(), s.id) == ids.end()) continue;
    nodes.push_back({s.id, s.centre().utime_us, sss::sim::truePoses(*survey.mission, s)[s.centre_ping_index]});
  }
  return nodes;
}

PairIds pairIds(const std::vector<PairOutcome>& outcomes) {
  PairIds ids;
  for (const auto& o : outcomes) ids.insert({o.subframe_id_a, o.subframe_id_b});
  return ids;
}

std::vector<int64_t> storedIds(const MatcherEngine& engine) {
  std::vector<int64_t> ids;
  for (const auto& c : engine.state().corrections) ids.push_back(c.subframe_id);
  return ids;
}

void expectSameState(const MatcherState& a, const MatcherState& b) {
  ASSERT_EQ(a.corrections.size(), b.corrections.size());
  for (size_t i = 0; i < a.corrections.size(); ++i) {
    EXPECT_EQ(a.corrections[i].subframe_id, b.corrections[i].subframe_id);
    EXPECT_EQ(a.corrections[i].correction.translation, b.corrections[i].correction.translation);
    EXPECT_EQ(a.corrections[i].correction.rotation.coeffs(), b.corrections[i].correction.rotation.coeffs());
  }
  ASSERT_EQ(a.pairs.size(), b.pairs.size());
  for (size_t i = 0; i < a.pairs.size(); ++i) {
    EXPECT_EQ(a.pairs[i].subframe_id_a, b.pairs[i].subframe_id_a);
    EXPECT_EQ(a.pairs[i].subframe_id_b, b.pairs[i].subframe_id_b);
    EXPECT_EQ(a.pairs[i].rounds_done, b.pairs[i].rounds_done);
    EXPECT_EQ(a.pairs[i].relative_at_match.translation, b.pairs[i].relative_at_match.translation);
  }
}

class MatcherEngineRestartTest : public ::testing::Test {
 protected:
  void TearDown() override { fs::remove_all(dir_); }
  const std::string dir_ =
      (fs::temp_directory_path() / ("sss_matcher_engine_test_" + std::to_string(getpid()))).string();
};

TEST_F(MatcherEngineRestartTest, RestoredEngineKeepsSubframesCorrectionsAndDonePairsAndMatchesNewOnes) {
  const std::vector<TrajectoryNode> nodes = trueNodes({0, 1, 2, 3});
  MatcherState before;
  size_t memory_before = 0;
  {
    MatcherStateStore store(dir_);
    MatcherEngine engine{MatcherEngineOptions{}};
    EXPECT_EQ(engine.restore(store).subframes, 0u);
    std::vector<PairOutcome> outcomes;
    for (int64_t id : {0, 1, 2, 3})
      for (auto& o : engine.addSubframe(surveySubframe(id))) outcomes.push_back(std::move(o));
    EXPECT_EQ(pairIds(outcomes), (PairIds{{0, 2}, {0, 3}, {1, 2}}));  // lines 0-1 (1-3 barely touch)
    // Optimised poses: corrections away from identity, pairs re-matched in round 1 (rounds_done 2).
    EXPECT_EQ(pairIds(engine.updateTrajectory(nodes)), (PairIds{{0, 2}, {0, 3}, {1, 2}}));
    EXPECT_EQ(engine.counters().pairs_attempted, 6u);
    EXPECT_EQ(engine.counters().state_write_errors, 0u);
    before = engine.state();
    memory_before = engine.memoryBytes();
  }  // the "kill": nothing is written at destruction

  MatcherStateStore store(dir_);
  MatcherEngine engine{MatcherEngineOptions{}};
  const RestoreReport report = engine.restore(store);
  EXPECT_TRUE(report.problems.empty());
  EXPECT_TRUE(report.state_file_found);
  EXPECT_EQ(report.subframes, 4u);
  EXPECT_EQ(report.pairs, 3u);
  EXPECT_EQ(report.subframes_without_state, 0u);
  EXPECT_TRUE(report.outcomes.empty());
  EXPECT_EQ(engine.counters().subframes_restored, 4u);
  EXPECT_EQ(engine.counters().pairs_restored, 3u);
  EXPECT_EQ(storedIds(engine), (std::vector<int64_t>{0, 1, 2, 3}));
  expectSameState(engine.state(), before);
  EXPECT_LE(engine.memoryBytes(), memory_before);
  EXPECT_NE(before.corrections[2].correction.translation, Eigen::Vector3d::Zero());
  // The same poses again: nothing moved since the matches before the restart, nothing re-matched.
  EXPECT_TRUE(engine.updateTrajectory(nodes).empty());
  EXPECT_EQ(engine.counters().pairs_attempted, 0u);

  // A new line is matched against the subframes from before the restart.
  const std::vector<PairOutcome> outcomes = engine.addSubframe(surveySubframe(4));
  const PairIds ids = pairIds(outcomes);
  EXPECT_TRUE(ids.count({0, 4}) && ids.count({2, 4})) << outcomes.size() << " pairs";
  int accepted_against_old = 0;
  std::string reasons;
  for (const PairOutcome& o : outcomes) {
    EXPECT_EQ(o.subframe_id_b, 4);
    EXPECT_EQ(o.association_round, 0);
    if (o.accepted && o.subframe_id_a <= 3) ++accepted_against_old;
    if (!o.accepted) reasons += std::to_string(o.subframe_id_a) + "-4: " + o.reason + "; ";
  }
  EXPECT_GE(accepted_against_old, 2) << reasons;
  EXPECT_EQ(engine.counters().pairs_attempted, outcomes.size());
  EXPECT_TRUE(fs::exists(store.subframePath(4)));
}

TEST_F(MatcherEngineRestartTest, PairsOfASubframeTheKillInterruptedAreMatchedAtRestoreOnce) {
  std::vector<PairOutcome> before_kill;
  {
    MatcherStateStore store(dir_);
    MatcherEngine engine{MatcherEngineOptions{}};
    engine.restore(store);
    engine.addSubframe(surveySubframe(0));
    engine.addSubframe(surveySubframe(1));  // same line: no pairs
    EXPECT_EQ(engine.counters().pairs_attempted, 0u);
    // Killed while matching subframe 2: its file is written first, the state file after its
    // pairs; the state file as it was before subframe 2 stands for the kill.
    const std::string state_before = store.statePath() + ".before";
    fs::copy_file(store.statePath(), state_before);
    before_kill = engine.addSubframe(surveySubframe(2));
    fs::rename(state_before, store.statePath());
  }
  ASSERT_EQ(pairIds(before_kill), (PairIds{{0, 2}, {1, 2}}));

  MatcherStateStore store(dir_);
  MatcherEngine engine{MatcherEngineOptions{}};
  const RestoreReport report = engine.restore(store);
  EXPECT_TRUE(report.problems.empty());
  EXPECT_EQ(report.subframes, 3u);
  EXPECT_EQ(report.pairs, 0u);
  EXPECT_EQ(report.subframes_without_state, 1u);
  EXPECT_EQ(pairIds(report.outcomes), (PairIds{{0, 2}, {1, 2}}));
  for (size_t i = 0; i < report.outcomes.size(); ++i) {
    EXPECT_EQ(report.outcomes[i].accepted, before_kill[i].accepted) << i;
    EXPECT_EQ(report.outcomes[i].association_round, 0);
  }
  EXPECT_EQ(engine.counters().pairs_attempted, 2u);

  // Restored again: now done, not matched (nor sent) a second time.
  MatcherStateStore again_store(dir_);
  MatcherEngine again{MatcherEngineOptions{}};
  const RestoreReport again_report = again.restore(again_store);
  EXPECT_EQ(again_report.pairs, 2u);
  EXPECT_EQ(again_report.subframes_without_state, 0u);
  EXPECT_TRUE(again_report.outcomes.empty());
  EXPECT_EQ(again.counters().pairs_attempted, 0u);
}

// Storage only from here: no pair overlaps enough to be matched.
MatcherEngineOptions storageOnlyOptions() {
  MatcherEngineOptions options;
  options.overlap.min_overlap_fraction = 0.99;
  return options;
}

TEST_F(MatcherEngineRestartTest, EvictionDeletesTheSubframeFile) {
  MatcherEngineOptions options = storageOnlyOptions();
  options.max_stored_subframes = 3;
  {
    MatcherStateStore store(dir_);
    MatcherEngine engine(options);
    engine.restore(store);
    for (int64_t id : {0, 1, 2, 3}) engine.addSubframe(surveySubframe(id));
    EXPECT_EQ(engine.counters().subframes_evicted, 1u);
    EXPECT_FALSE(fs::exists(store.subframePath(0)));
    EXPECT_EQ(store.subframeIds(), (std::vector<int64_t>{1, 2, 3}));
    const auto read = store.readState();
    ASSERT_OK(read);
    ASSERT_TRUE(read->has_value());
    const MatcherState& saved = **read;
    ASSERT_EQ(saved.corrections.size(), 3u);
    EXPECT_EQ(saved.corrections[0].subframe_id, 1);
  }
  // Restarted with a smaller store: the oldest is evicted at restore, its file deleted.
  options.max_stored_subframes = 2;
  MatcherStateStore store(dir_);
  MatcherEngine engine(options);
  EXPECT_EQ(engine.restore(store).subframes, 2u);
  EXPECT_EQ(engine.counters().subframes_evicted, 1u);
  EXPECT_EQ(storedIds(engine), (std::vector<int64_t>{2, 3}));
  EXPECT_EQ(store.subframeIds(), (std::vector<int64_t>{2, 3}));
}

TEST_F(MatcherEngineRestartTest, CorruptFilesAreCountedAndSkippedAndTheRestRestored) {
  MatcherState before;
  {
    MatcherStateStore store(dir_);
    MatcherEngine engine(storageOnlyOptions());
    engine.restore(store);
    for (int64_t id : {0, 1, 2, 3, 4, 5}) engine.addSubframe(surveySubframe(id));
    engine.updateTrajectory(trueNodes({0, 1, 2, 3, 4, 5}));
    before = engine.state();
  }
  MatcherStateStore store(dir_);
  {  // one flipped byte in subframe 1's image, subframe 3 cut in half
    std::fstream file(store.subframePath(1), std::ios::binary | std::ios::in | std::ios::out);
    file.seekg(200000);
    const char byte = static_cast<char>(file.peek());
    file.seekp(200000);
    file.put(static_cast<char>(byte ^ 0x04));
  }
  fs::resize_file(store.subframePath(3), fs::file_size(store.subframePath(3)) / 2);

  MatcherEngine engine(storageOnlyOptions());
  const RestoreReport report = engine.restore(store);
  EXPECT_EQ(engine.counters().state_files_corrupt, 2u);
  ASSERT_EQ(report.problems.size(), 2u);
  EXPECT_NE(report.problems[0].find(store.subframePath(1)), std::string::npos) << report.problems[0];
  EXPECT_NE(report.problems[0].find("checksum"), std::string::npos) << report.problems[0];
  EXPECT_NE(report.problems[1].find(store.subframePath(3)), std::string::npos) << report.problems[1];
  EXPECT_EQ(storedIds(engine), (std::vector<int64_t>{0, 2, 4, 5}));
  EXPECT_EQ(store.subframeIds(), (std::vector<int64_t>{0, 2, 4, 5}));  // unusable: removed
  for (const auto& c : engine.state().corrections) {
    for (const auto& b : before.corrections) {
      if (b.subframe_id == c.subframe_id) {
        EXPECT_EQ(c.correction.translation, b.correction.translation);
      }
    }
  }

  // A corrupt state file: the subframes are restored without it, with identity corrections (as
  // before any trajectory), their pairs to be matched (none here).
  {
    std::fstream file(store.statePath(), std::ios::binary | std::ios::in | std::ios::out);
    file.seekp(40);
    file.put('#');
  }
  MatcherStateStore again_store(dir_);
  MatcherEngine again(storageOnlyOptions());
  const RestoreReport again_report = again.restore(again_store);
  EXPECT_EQ(again.counters().state_files_corrupt, 1u);
  ASSERT_EQ(again_report.problems.size(), 1u);
  EXPECT_NE(again_report.problems[0].find(again_store.statePath()), std::string::npos) << again_report.problems[0];
  EXPECT_FALSE(again_report.state_file_found);
  EXPECT_EQ(again_report.subframes_without_state, 4u);
  EXPECT_EQ(storedIds(again), (std::vector<int64_t>{0, 2, 4, 5}));
  for (const auto& c : again.state().corrections) EXPECT_EQ(c.correction.translation, Eigen::Vector3d::Zero());
  // The state file is whole again for the next start.
  const auto saved = again_store.readState();
  EXPECT_TRUE(saved.ok() && saved->has_value()) << saved.message();
}

}  // namespace
}  // namespace sss::matcher
