// The optimiser engine on the small synthetic lawnmower with per-ping subframes and closures with
// seabed correspondences: a checkpoint mid-mission gives the products of an uninterrupted run,
// bad checkpoints are refused, and an INS odometer reset loses no subframe.
#include "pipeline/optimiser/optimiser_engine.hpp"

#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "pipeline/optimiser/checkpoint_io.hpp"
#include "tools/fixtures/synthetic_subframes.hpp"
#include "tests/optimiser/pose_graph_test_helpers.hpp"

namespace sss::optimiser {
namespace {

using sss::core::Pose;
using test_helpers::graphOptions;
using test_helpers::missionOptions;

std::string temporaryPath(const std::string& name) {
  return ::testing::TempDir() + "sss_engine_" + std::to_string(::getpid()) + "_" + name;
}

void removeCheckpoint(const std::string& path) {
  std::remove(path.c_str());
  std::remove((path + ".journal").c_str());
}

std::string readBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

void writeBytes(const std::string& path, const std::string& bytes) { std::ofstream(path, std::ios::binary) << bytes; }

OptimiserEngineOptions engineOptions() {
  OptimiserEngineOptions o;
  o.graph = graphOptions(8);
  o.bathymetry.max_points_per_closure = 150;  // of 200 sent: the thinning is part of the state
  return o;
}

// The lawnmower (5 lines of 4 subframes of 200 pings, 16 closures with 200 correspondences each)
// as the optimiser receives it. Step i: subframe i, its round-0 closures, round-1 closures of the
// pairs completed two subframes earlier (re-association), then an update. The closures of subframe
// `early` arrive one step before it (SSS_LOOP overtaking SSS_SUBFRAME): they wait in the engine.
struct Scenario {
  synthetic::Mission mission;
  synthetic::SubframeOptions subframe_options;
  std::vector<sss::core::Subframe> subframes;
  std::vector<std::vector<sss::core::LoopClosure>> closures_at;  // per step, after the subframe
};

Scenario makeScenario(int early) {
  Scenario s;
  s.mission = synthetic::makeLawnmowerMission(missionOptions(3));
  s.subframe_options.correspondences_per_closure = 200;
  std::vector<std::vector<Pose>> truth;
  s.subframes = synthetic::makeSubframes(s.mission, s.subframe_options, &truth);
  s.closures_at.resize(s.subframes.size());
  for (size_t c = 0; c < s.mission.closures.size(); ++c) {
    const int newer = s.mission.closures[c].newer_node;
    const int step = newer == early ? newer - 1 : newer;
    s.closures_at[step].push_back(synthetic::makeMatcherClosure(s.mission, c, truth, s.subframe_options, 0));
    if (newer + 2 < static_cast<int>(s.subframes.size()))
      s.closures_at[newer + 2].push_back(synthetic::makeMatcherClosure(s.mission, c, truth, s.subframe_options, 1));
  }
  return s;
}

void runSteps(OptimiserEngine& engine, const Scenario& s, size_t begin, size_t end) {
  for (size_t i = begin; i < end; ++i) {
    const Status added = engine.addSubframe(s.subframes[i]);
    ASSERT_TRUE(added.ok) << added.message;
    // A later round of a pair whose first is marginalised is refused, as live; counted by the engine.
    for (const sss::core::LoopClosure& c : s.closures_at[i]) static_cast<void>(engine.addLoopClosure(c));
    ASSERT_TRUE(engine.update().ok);
  }
}

struct Products {
  std::vector<StampedPose> pings;
  std::vector<SeabedPoint> points;
  HeightmapGrid heightmap;
  OptimiserEngineCounters counters;
  std::vector<ClosureSummary> closures;
};

Products productsOf(OptimiserEngine& engine) {
  EXPECT_TRUE(engine.finish().ok);
  Products p;
  p.pings = engine.pingTrajectory(true);
  p.points = engine.seabedPoints(false);
  p.heightmap = gridSeabedPoints(p.points, engine.options().bathymetry);
  p.counters = engine.counters();
  p.closures = engine.closureSummaries();
  return p;
}

// Deterministic maths on the same state: the restored run must match to rounding, far below the
// centimetres that matter for a trajectory or a heightmap.
void expectSameProducts(const Products& a, const Products& b) {
  constexpr double kToleranceM = 1e-9;
  ASSERT_EQ(a.pings.size(), b.pings.size());
  for (size_t i = 0; i < a.pings.size(); ++i) {
    ASSERT_EQ(a.pings[i].utime_us, b.pings[i].utime_us) << i;
    EXPECT_NEAR((a.pings[i].T_world_body.translation - b.pings[i].T_world_body.translation).norm(), 0.0, kToleranceM)
        << "ping " << i;
    EXPECT_NEAR(a.pings[i].T_world_body.rotation.angularDistance(b.pings[i].T_world_body.rotation), 0.0, 1e-9) << i;
  }
  ASSERT_EQ(a.points.size(), b.points.size());
  for (size_t i = 0; i < a.points.size(); ++i) {
    EXPECT_NEAR((a.points[i].position_ned_m - b.points[i].position_ned_m).norm(), 0.0, kToleranceM) << "point " << i;
    EXPECT_EQ(a.points[i].subframe_id_a, b.points[i].subframe_id_a);
    EXPECT_EQ(a.points[i].subframe_id_b, b.points[i].subframe_id_b);
  }
  ASSERT_EQ(a.heightmap.rows, b.heightmap.rows);
  ASSERT_EQ(a.heightmap.cols, b.heightmap.cols);
  EXPECT_EQ(a.heightmap.points, b.heightmap.points);
  ASSERT_EQ(a.heightmap.depth_m.size(), b.heightmap.depth_m.size());
  for (size_t i = 0; i < a.heightmap.depth_m.size(); ++i) {
    const float da = a.heightmap.depth_m[i], db = b.heightmap.depth_m[i];
    EXPECT_TRUE((std::isnan(da) && std::isnan(db)) || std::abs(da - db) < 1e-5f) << "cell " << i;
  }
  ASSERT_EQ(a.closures.size(), b.closures.size());
  for (size_t i = 0; i < a.closures.size(); ++i) {
    EXPECT_EQ(a.closures[i].record.status, b.closures[i].record.status) << i;
    EXPECT_EQ(a.closures[i].mean_zncc, b.closures[i].mean_zncc) << i;
  }
  EXPECT_EQ(a.counters.subframes_in, b.counters.subframes_in);
  EXPECT_EQ(a.counters.closures_in, b.counters.closures_in);
  EXPECT_EQ(a.counters.closures_refused, b.counters.closures_refused);
  EXPECT_EQ(a.counters.odometer_resets, b.counters.odometer_resets);
}

// ---- checkpoint round trip ------------------------------------------------------------------------

TEST(OptimiserEngineCheckpoint, KilledTwiceMidMissionGivesTheProductsOfAnUninterruptedRun) {
  const int early = 7;
  const Scenario s = makeScenario(early);
  const size_t n = s.subframes.size();
  ASSERT_EQ(n, 20u);

  OptimiserEngine uninterrupted(engineOptions());
  runSteps(uninterrupted, s, 0, n);
  const Products expected = productsOf(uninterrupted);
  // Every ping of every subframe, and a seabed worth comparing.
  EXPECT_EQ(expected.pings.size(), n * static_cast<size_t>(s.subframe_options.pings_per_subframe));
  EXPECT_GT(expected.points.size(), 1000u);
  int cells = 0;
  for (uint16_t count : expected.heightmap.points) cells += count > 0 ? 1 : 0;
  EXPECT_GT(cells, 100);
  std::printf("products: %zu ping poses, %zu seabed points, %d heightmap cells\n", expected.pings.size(),
              expected.points.size(), cells);

  // Saved after step 6 (a closure of subframe 7 waiting) and after step 13 (appending to the
  // journal the first engine wrote); each time a new engine loads and carries on.
  const std::string path = temporaryPath("roundtrip.checkpoint");
  auto engine = std::make_unique<OptimiserEngine>(engineOptions());
  size_t done = 0;
  for (size_t stop : {static_cast<size_t>(early), size_t{14}}) {
    runSteps(*engine, s, done, stop);
    done = stop;
    if (stop == static_cast<size_t>(early)) {
      ASSERT_GE(engine->counters().closures_waiting, 1u);
    }
    const Status saved = engine->saveCheckpoint(path);
    ASSERT_TRUE(saved.ok) << saved.message;
    engine = std::make_unique<OptimiserEngine>(engineOptions());  // the process was killed
    const Status loaded = engine->loadCheckpoint(path);
    ASSERT_TRUE(loaded.ok) << loaded.message;
    EXPECT_EQ(engine->storedSubframes(), stop);
  }
  runSteps(*engine, s, done, n);
  expectSameProducts(expected, productsOf(*engine));
  removeCheckpoint(path);
}

TEST(OptimiserEngineCheckpoint, JournalBytesOfASaveThatCrashedBeforeItsRenameAreIgnored) {
  const Scenario s = makeScenario(-1);
  const size_t n = s.subframes.size();
  OptimiserEngine uninterrupted(engineOptions());
  runSteps(uninterrupted, s, 0, n);
  const Products expected = productsOf(uninterrupted);

  const std::string path = temporaryPath("crash.checkpoint");
  OptimiserEngine first(engineOptions());
  runSteps(first, s, 0, 9);
  ASSERT_TRUE(first.saveCheckpoint(path).ok);
  const std::string committed = readBytes(path);
  const size_t committed_journal = readBytes(path + ".journal").size();
  runSteps(first, s, 9, 11);
  ASSERT_TRUE(first.saveCheckpoint(path).ok);
  ASSERT_GT(readBytes(path + ".journal").size(), committed_journal);
  writeBytes(path, committed);  // killed after the journal append, before the rename

  OptimiserEngine second(engineOptions());
  const Status loaded = second.loadCheckpoint(path);
  ASSERT_TRUE(loaded.ok) << loaded.message;
  EXPECT_EQ(second.storedSubframes(), 9u);
  runSteps(second, s, 9, 12);
  ASSERT_TRUE(second.saveCheckpoint(path).ok);  // cuts the stale tail off, then appends
  OptimiserEngine third(engineOptions());
  ASSERT_TRUE(third.loadCheckpoint(path).ok);
  runSteps(third, s, 12, n);
  expectSameProducts(expected, productsOf(third));
  removeCheckpoint(path);
}

// ---- refused checkpoints --------------------------------------------------------------------------

TEST(OptimiserEngineCheckpoint, OldVersionTruncatedOrCorruptCheckpointsAreRefusedAndChangeNothing) {
  const Scenario s = makeScenario(-1);
  const std::string path = temporaryPath("good.checkpoint");
  {
    OptimiserEngine source(engineOptions());
    runSteps(source, s, 0, 12);
    ASSERT_TRUE(source.saveCheckpoint(path).ok);
  }
  const std::string good = readBytes(path), good_journal = readBytes(path + ".journal");
  ASSERT_GT(good_journal.size(), 100000u);

  OptimiserEngine target(engineOptions());
  runSteps(target, s, 0, 3);
  const size_t pings_before = target.pingTrajectory(false).size();
  const std::string bad = temporaryPath("bad.checkpoint");
  auto tryLoad = [&](const std::string& file, const std::string& journal) {
    removeCheckpoint(bad);
    writeBytes(bad, file);
    if (!journal.empty()) writeBytes(bad + ".journal", journal);
    return target.loadCheckpoint(bad);
  };
  auto expectRefused = [&](const Status& status, const std::string& reason) {
    EXPECT_FALSE(status.ok) << reason;
    EXPECT_NE(status.message.find(reason), std::string::npos) << status.message;
  };

  // The previous format: the pose graph's checkpoint alone.
  SlidingWindowPoseGraph graph_only(engineOptions().graph);
  ASSERT_TRUE(graph_only.addNode(1, 1000, Pose::identity(), 0.0).ok);
  ASSERT_TRUE(graph_only.saveCheckpoint(bad).ok);
  expectRefused(target.loadCheckpoint(bad), "format version 1");
  // A newer version with a sound checksum.
  std::string v4 = good.substr(0, good.rfind("checksum "));
  v4.replace(v4.find(" 3\n"), 3, " 4\n");
  checkpoint::appendChecksum(v4);
  expectRefused(tryLoad(v4, good_journal), "format version 4 not supported");
  // A negative sigma in the INS drift record (ins_drift started distance sigma ...).
  std::string negative = good.substr(0, good.rfind("checksum "));
  const size_t line_at = negative.find("\nins_drift ") + 1, line_end = negative.find('\n', line_at);
  ASSERT_NE(line_at, std::string::npos + 1);
  std::istringstream fields(negative.substr(line_at, line_end - line_at));
  std::vector<std::string> record{std::istream_iterator<std::string>(fields), {}};
  ASSERT_EQ(record.size(), 9u);
  record[3] = "-1";
  std::string line;
  for (const std::string& field : record) line += (line.empty() ? "" : " ") + field;
  negative.replace(line_at, line_end - line_at, line);
  checkpoint::appendChecksum(negative);
  expectRefused(tryLoad(negative, good_journal), "ins_drift");
  // The rewritten file truncated or with a bit flipped.
  expectRefused(tryLoad(good.substr(0, good.size() / 2), good_journal), "checksum");
  std::string flipped = good;
  flipped[good.size() / 3] ^= 0x04;
  expectRefused(tryLoad(flipped, good_journal), "checksum mismatch");
  // The journal missing, truncated, with a bit flipped, or another checkpoint's.
  expectRefused(tryLoad(good, ""), "journal");
  expectRefused(tryLoad(good, good_journal.substr(0, good_journal.size() - 100)), "truncated");
  std::string flipped_journal = good_journal;
  flipped_journal[good_journal.size() / 2] ^= 0x10;
  expectRefused(tryLoad(good, flipped_journal), "checksum mismatch");
  std::string other_journal = good_journal;
  other_journal[20] ^= 0x01;  // the journal id
  expectRefused(tryLoad(good, other_journal), "another checkpoint");
  // Every prefix of the rewritten file re-checksummed: refused, never a crash.
  const std::string payload = good.substr(0, good.rfind("checksum "));
  for (size_t cut = payload.find('\n'); cut != std::string::npos; cut = payload.find('\n', cut + 1)) {
    if (cut + 1 == payload.size()) break;
    std::string prefix = payload.substr(0, cut + 1);
    checkpoint::appendChecksum(prefix);
    EXPECT_FALSE(tryLoad(prefix, good_journal).ok) << cut;
  }

  // Nothing changed, and the good pair still loads.
  EXPECT_EQ(target.pingTrajectory(false).size(), pings_before);
  EXPECT_EQ(target.graph().numNodes(), 3u);
  const Status loaded = tryLoad(good, good_journal);
  ASSERT_TRUE(loaded.ok) << loaded.message;
  EXPECT_EQ(target.pingTrajectory(false).size(), 12u * 200u);
  removeCheckpoint(path);
  removeCheckpoint(bad);
}

// ---- odometer resets ------------------------------------------------------------------------------

// The INS bridge restarts when the odometer reads ~350 m: from subframe 4 (first of line 1, after
// the turn) it reads 50 m and grows again.
constexpr size_t kResetNode = 4;

Scenario withOdometerReset(const Scenario& base) {
  Scenario s = base;
  const double drop_m = s.subframes[kResetNode].centre().distance_travelled_m - 50.0;
  for (size_t i = kResetNode; i < s.subframes.size(); ++i)
    for (sss::core::SubframePing& ping : s.subframes[i].pings) ping.distance_travelled_m -= drop_m;
  return s;
}

double centreAte(const OptimiserEngine& engine, const Scenario& s) {
  std::vector<Pose> estimates;
  for (const sss::core::Subframe& subframe : s.subframes) estimates.push_back(*engine.graph().estimate(subframe.id));
  return synthetic::translationRmse(estimates, s.mission.nodes);
}

TEST(OptimiserEngineOdometer, ResetIsAcceptedWithTheStraightLineDistanceAndClosuresStillCorrect) {
  const Scenario base = makeScenario(-1);
  const Scenario s = withOdometerReset(base);
  ASSERT_GT(s.subframes[kResetNode - 1].centre().distance_travelled_m, 300.0);
  ASSERT_NEAR(s.subframes[kResetNode].centre().distance_travelled_m, 50.0, 1e-9);

  OptimiserEngine engine(engineOptions());
  for (size_t i = 0; i < s.subframes.size(); ++i) {
    const Status added = engine.addSubframe(s.subframes[i]);
    ASSERT_TRUE(added.ok) << added.message;
    if (i == kResetNode) {
      // Logged once, with both odometer values.
      EXPECT_NE(added.message.find("odometer reset"), std::string::npos) << added.message;
      char values[64];
      std::snprintf(values, sizeof(values), "from %.3f m to 50.000 m",
                    s.subframes[kResetNode - 1].centre().distance_travelled_m);
      EXPECT_NE(added.message.find(values), std::string::npos) << added.message;
    } else {
      EXPECT_TRUE(added.message.empty()) << added.message;
    }
    // A later round of a pair whose first is marginalised is refused, as live; counted by the engine.
    for (const sss::core::LoopClosure& c : s.closures_at[i]) static_cast<void>(engine.addLoopClosure(c));
    ASSERT_TRUE(engine.update().ok);
  }
  EXPECT_EQ(engine.counters().odometer_resets, 1u);
  EXPECT_EQ(engine.counters().subframes_refused, 0u);
  const std::vector<NodeState> nodes = engine.graph().nodes();
  ASSERT_EQ(nodes.size(), s.subframes.size());
  for (size_t i = 1; i < nodes.size(); ++i) {
    const double graph_step_m = nodes[i].distance_travelled_m - nodes[i - 1].distance_travelled_m;
    if (i == kResetNode) {
      // The odometry sigma of this edge comes from the horizontal straight line between the DR
      // centres (~100 m across the turn), not the ~257 m travelled nor the odometer's -300 m.
      const double straight_m =
          (nodes[i].T_world_body_dr.translation - nodes[i - 1].T_world_body_dr.translation).head<2>().norm();
      EXPECT_NEAR(graph_step_m, straight_m, 1e-9);
      EXPECT_LT(straight_m, 150.0);
    } else {
      const double input_step_m =
          s.subframes[i].centre().distance_travelled_m - s.subframes[i - 1].centre().distance_travelled_m;
      EXPECT_NEAR(graph_step_m, input_step_m, 1e-9) << i;
    }
  }
  // Corrected by the closures as without the reset (only one odometry edge differs).
  OptimiserEngine reference(engineOptions());
  runSteps(reference, base, 0, base.subframes.size());
  const double ate_dr_m = synthetic::translationRmse(synthetic::drPoses(s.mission), s.mission.nodes);
  const double ate_m = centreAte(engine, s);
  const double ate_reference_m = centreAte(reference, base);
  std::printf("centre ATE: DR %.3f m, with the odometer reset %.3f m, without %.3f m\n", ate_dr_m, ate_m,
              ate_reference_m);
  EXPECT_LT(ate_m, 0.5 * ate_dr_m);
  EXPECT_LT(ate_m, ate_reference_m + 0.1);
  EXPECT_EQ(engine.graph().counters().closures_accepted, reference.graph().counters().closures_accepted);

  // A decrease within the tolerance is jitter: accepted, no distance, no reset.
  sss::core::Subframe jitter = s.subframes.back();
  jitter.id += 100;
  for (auto& ping : jitter.pings) {
    ping.utime_us += 60'000'000;
    ping.distance_travelled_m = s.subframes.back().centre().distance_travelled_m - 0.5;
  }
  ASSERT_TRUE(engine.addSubframe(jitter).ok);
  EXPECT_EQ(engine.counters().odometer_resets, 1u);
  EXPECT_EQ(engine.graph().newestNode()->distance_travelled_m, nodes.back().distance_travelled_m);
  // Non-finite is still refused.
  sss::core::Subframe broken = jitter;
  broken.id += 1;
  for (auto& ping : broken.pings) {
    ping.utime_us += 60'000'000;
    ping.distance_travelled_m = std::nan("");
  }
  EXPECT_FALSE(engine.addSubframe(broken).ok);
  EXPECT_EQ(engine.counters().subframes_refused, 1u);
  EXPECT_EQ(engine.counters().odometer_resets, 1u);
}

// The optimiser restarts from a checkpoint taken after the reset (the offset must carry on, not be
// taken for a second reset) or before it (the reset happens while it is down).
TEST(OptimiserEngineOdometer, RestartFromACheckpointKeepsTheOffset) {
  const Scenario s = withOdometerReset(makeScenario(-1));
  OptimiserEngine uninterrupted(engineOptions());
  runSteps(uninterrupted, s, 0, s.subframes.size());
  const std::vector<NodeState> expected = uninterrupted.graph().nodes();
  for (size_t stop : {kResetNode + 2, kResetNode}) {
    const std::string path = temporaryPath("odometer.checkpoint");
    OptimiserEngine before(engineOptions());
    runSteps(before, s, 0, stop);
    ASSERT_TRUE(before.saveCheckpoint(path).ok);
    OptimiserEngine after(engineOptions());
    ASSERT_TRUE(after.loadCheckpoint(path).ok);
    runSteps(after, s, stop, s.subframes.size());
    EXPECT_EQ(after.counters().odometer_resets, 1u) << "restart after subframe " << stop;
    const std::vector<NodeState> nodes = after.graph().nodes();
    ASSERT_EQ(nodes.size(), expected.size());
    for (size_t i = 0; i < nodes.size(); ++i) {
      EXPECT_EQ(nodes[i].distance_travelled_m, expected[i].distance_travelled_m) << i;
      EXPECT_NEAR((nodes[i].T_world_body.translation - expected[i].T_world_body.translation).norm(), 0.0, 1e-9) << i;
    }
    removeCheckpoint(path);
  }
}

// ---- the first node's anchor from the INS's reported accuracy ------------------------------------

// Nav reports the INS's accuracy before and after the first subframe's centre ping (as it does:
// nav runs ahead of the subframes): the one nearest the centre sets the anchor; reports without a
// value, and a report more than 30 s away from the centre, do not.
TEST(OptimiserEngineAnchor, TheInsAccuracyNearestTheFirstNodeWidensItsAnchor) {
  const Scenario s = makeScenario(-1);
  const int64_t centre_us = s.subframes[0].pings[s.subframes[0].centre_ping_index].utime_us;
  {
    OptimiserEngine engine(engineOptions());
    engine.addNavAccuracy({centre_us - 20'000'000, 1.0, 1.0});
    engine.addNavAccuracy({centre_us - 2'000'000, 2.5, 1.5});  // nearest
    engine.addNavAccuracy({centre_us - 1'500'000, 9.0, 9.0});  // within a second of the last: not kept
    engine.addNavAccuracy({centre_us + 5'000'000, 3.0, 3.0});
    engine.addNavAccuracy({centre_us + 7'000'000, 0.0, 0.0});  // not reported
    EXPECT_FALSE(engine.anchorDecided());
    ASSERT_TRUE(engine.addSubframe(s.subframes[0]).ok);
    EXPECT_TRUE(engine.anchorDecided());
    EXPECT_EQ(engine.graph().firstNodeInsSigma(), Eigen::Vector2d(2.5, 1.5));
    engine.addNavAccuracy({centre_us + 9'000'000, 6.0, 6.0});  // decided: ignored
    EXPECT_EQ(engine.graph().firstNodeInsSigma(), Eigen::Vector2d(2.5, 1.5));
  }
  {
    // Only a report after the centre, arriving after the subframe: used when it comes.
    OptimiserEngine engine(engineOptions());
    ASSERT_TRUE(engine.addSubframe(s.subframes[0]).ok);
    EXPECT_FALSE(engine.anchorDecided());
    engine.addNavAccuracy({centre_us + 1'000'000, 0.8, 0.7});
    EXPECT_TRUE(engine.anchorDecided());
    EXPECT_EQ(engine.graph().firstNodeInsSigma(), Eigen::Vector2d(0.8, 0.7));
  }
  {
    // Too far from the centre (an INS that stopped reporting long before): first_node_sigma_m stays.
    OptimiserEngine engine(engineOptions());
    engine.addNavAccuracy({centre_us - 60'000'000, 5.0, 5.0});
    engine.addNavAccuracy({centre_us + 45'000'000, 5.0, 5.0});
    ASSERT_TRUE(engine.addSubframe(s.subframes[0]).ok);
    EXPECT_TRUE(engine.anchorDecided());
    EXPECT_EQ(engine.graph().firstNodeInsSigma(), Eigen::Vector2d::Zero());
  }
}

// ---- the odometry's drift from the INS's reported accuracy ----------------------------------------

// An INS whose reported sigma grows by 0.08 % of the distance (a better one than the configured
// 0.5 %): the graph's odometry takes its rate once 300 m are behind it, and holds it while the
// rate stays within 10 %; a jittery report that moves it by less is not an update. Off, or with
// reports that carry no distance, the configured fraction stays.
TEST(OptimiserEngineInsDrift, TheOdometryTakesTheDriftTheInsReports) {
  const double configured = engineOptions().graph.odometry_drift_fraction;
  {
    OptimiserEngine engine(engineOptions());
    int64_t t_us = 1'000'000'000'000;
    for (double d = 0.0; d <= 250.0; d += 2.0, t_us += 1'000'000)
      engine.addNavAccuracy({t_us, 0.5 + 0.0008 * d, 0.5 + 0.0008 * d, d});
    EXPECT_DOUBLE_EQ(engine.odometryDriftFraction(), configured);
    EXPECT_FALSE(engine.odometryDriftFromIns());
    for (double d = 252.0; d <= 1200.0; d += 2.0, t_us += 1'000'000) {
      const double jitter_m = (static_cast<int>(d) % 4 == 0 ? 0.01 : -0.01);
      engine.addNavAccuracy({t_us, 0.5 + 0.0008 * d + jitter_m, 0.5 + 0.0008 * d + jitter_m, d});
    }
    EXPECT_TRUE(engine.odometryDriftFromIns());
    EXPECT_NEAR(engine.odometryDriftFraction(), 0.0008, 0.0001);
    EXPECT_EQ(engine.counters().odometry_drift_updates, 1u);
    EXPECT_DOUBLE_EQ(engine.counters().odometry_drift_fraction, engine.odometryDriftFraction());
  }
  {
    OptimiserEngineOptions options = engineOptions();
    options.graph.odometry_drift_from_ins = false;
    OptimiserEngine engine(options);
    OptimiserEngine without_distance(engineOptions());
    int64_t t_us = 1'000'000'000'000;
    for (double d = 0.0; d <= 1200.0; d += 2.0, t_us += 1'000'000) {
      engine.addNavAccuracy({t_us, 0.5 + 0.0008 * d, 0.5 + 0.0008 * d, d});
      without_distance.addNavAccuracy({t_us, 0.5 + 0.0008 * d, 0.5 + 0.0008 * d});
    }
    EXPECT_DOUBLE_EQ(engine.odometryDriftFraction(), configured);
    EXPECT_DOUBLE_EQ(without_distance.odometryDriftFraction(), configured);
    EXPECT_FALSE(without_distance.odometryDriftFromIns());
  }
}

// Reports of an INS whose sigma grows by rate x distance from 0.5 m, at every 2 m of odometer
// from from_m to to_m (times far from the scenario's: they do not set its anchor).
void feedInsAccuracy(OptimiserEngine& engine, double from_m, double to_m, double rate) {
  for (double d = from_m; d <= to_m; d += 2.0) {
    const int64_t t_us = 1'000'000'000'000 + static_cast<int64_t>(d * 1e6);
    engine.addNavAccuracy({t_us, 0.5 + rate * d, 0.5 + rate * d, d});
  }
}

// Killed and restarted from a checkpoint, the optimiser keeps the drift it took from the INS (not
// the configured one for the next 300 m) and carries on the same stretch of the INS's drift; a
// version 2 checkpoint, written before the rate was kept, restores with the configured fraction.
TEST(OptimiserEngineInsDrift, ARestartFromACheckpointKeepsTheDriftTheInsReported) {
  const Scenario s = makeScenario(-1);
  const size_t n = s.subframes.size(), stop = 10;
  const double configured = engineOptions().graph.odometry_drift_fraction;
  OptimiserEngine uninterrupted(engineOptions());
  feedInsAccuracy(uninterrupted, 0.0, 1200.0, 0.0008);
  runSteps(uninterrupted, s, 0, stop);
  ASSERT_TRUE(uninterrupted.odometryDriftFromIns());
  ASSERT_NEAR(uninterrupted.odometryDriftFraction(), 0.0008, 1e-9);

  const std::string path = temporaryPath("drift.checkpoint");
  ASSERT_TRUE(uninterrupted.saveCheckpoint(path).ok);
  OptimiserEngine restarted(engineOptions());
  const Status loaded = restarted.loadCheckpoint(path);
  ASSERT_TRUE(loaded.ok) << loaded.message;
  EXPECT_TRUE(restarted.odometryDriftFromIns());
  EXPECT_DOUBLE_EQ(restarted.odometryDriftFraction(), uninterrupted.odometryDriftFraction());
  EXPECT_EQ(restarted.counters().odometry_drift_updates, 1u);

  // The same stretch goes on: the sigma now grows at 0.0024 per metre, so the rate over the whole
  // stretch from 0 m reaches 0.0016 at 2400 m (a new stretch from 1202 m would give 0.0024); the
  // graph takes it whenever it has moved by 10 %.
  for (OptimiserEngine* engine : {&uninterrupted, &restarted}) {
    runSteps(*engine, s, stop, n);
    for (double d = 1202.0; d <= 2400.0; d += 2.0) {
      const double sigma_m = 0.5 + 0.0008 * 1200.0 + 0.0024 * (d - 1200.0);
      engine->addNavAccuracy({1'000'000'000'000 + static_cast<int64_t>(d * 1e6), sigma_m, sigma_m, d});
    }
  }
  EXPECT_NEAR(restarted.odometryDriftFraction(), 0.0016, 0.1 * 0.0016);
  EXPECT_DOUBLE_EQ(restarted.odometryDriftFraction(), uninterrupted.odometryDriftFraction());
  EXPECT_EQ(restarted.counters().odometry_drift_updates, uninterrupted.counters().odometry_drift_updates);
  const std::vector<NodeState> expected = uninterrupted.graph().nodes(), nodes = restarted.graph().nodes();
  ASSERT_EQ(nodes.size(), expected.size());
  for (size_t i = 0; i < nodes.size(); ++i)
    EXPECT_NEAR((nodes[i].T_world_body.translation - expected[i].T_world_body.translation).norm(), 0.0, 1e-9) << i;

  // Version 2: no ins_drift record.
  std::string text = readBytes(path);
  text = text.substr(0, text.rfind("checksum "));
  text.replace(text.find(" 3\n"), 3, " 2\n");
  const size_t drift_at = text.find("ins_drift ");
  ASSERT_NE(drift_at, std::string::npos);
  text.erase(drift_at, text.find('\n', drift_at) + 1 - drift_at);
  checkpoint::appendChecksum(text);
  writeBytes(path, text);
  OptimiserEngine from_version_2(engineOptions());
  const Status loaded_v2 = from_version_2.loadCheckpoint(path);
  ASSERT_TRUE(loaded_v2.ok) << loaded_v2.message;
  EXPECT_FALSE(from_version_2.odometryDriftFromIns());
  EXPECT_DOUBLE_EQ(from_version_2.odometryDriftFraction(), configured);
  removeCheckpoint(path);
}

}  // namespace
}  // namespace sss::optimiser
