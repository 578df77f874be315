// Sliding-window pose graph behaviour on the small synthetic lawnmower: DR without closures, old-node
// closures, checkpoints, corrections, input and option checks. Accuracy over many seeds and long
// missions: pose_graph_mission_test.cpp (integration; Ceres autodiff is ~100x slower under ASan).
#include "pipeline/optimiser/pose_graph.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <optional>
#include <sstream>
#include <string>
#include <unistd.h>

#include "tools/fixtures/synthetic_mission.hpp"
#include "tests/optimiser/pose_graph_test_helpers.hpp"

namespace sss::optimiser {
namespace {

using sss::core::Matrix6d;
using sss::core::Pose;
using namespace test_helpers;

TEST(PoseGraphOdometryModel, GrowsWithDistanceInTheHorizontalAndHeadingOnly) {
  const PoseGraphOptions o;
  const Matrix6d c100 = SlidingWindowPoseGraph::odometryCovariance(o, 100.0);
  const Matrix6d c400 = SlidingWindowPoseGraph::odometryCovariance(o, 400.0);
  // 100 m: sqrt(0.02^2 * 100 + (0.005 * 100)^2 + 0.05^2) = 0.54 m horizontal, 1 sigma.
  EXPECT_NEAR(std::sqrt(c100(0, 0)), 0.541, 0.002);
  EXPECT_DOUBLE_EQ(c100(0, 0), c100(1, 1));
  EXPECT_GT(c400(0, 0), 4.0 * c100(0, 0));  // the drift fraction makes it grow faster than d
  EXPECT_DOUBLE_EQ(c100(2, 2), c400(2, 2));  // depth: absolute sensor
  EXPECT_DOUBLE_EQ(c100(3, 3), c400(3, 3));  // roll and pitch: absolute against gravity
  EXPECT_NEAR(c400(5, 5) / c100(5, 5), 4.0, 0.01);  // heading random walk
  EXPECT_TRUE(c100.isDiagonal());
}

// The drift fraction set on a graph that already holds its nodes (the INS's reported drift arrives
// after the first few hundred metres) rebuilds every edge: the same estimates as a graph
// configured with it from the start. And it is what decides how far closures bend DR: the same
// closures, 2 m off across track, move the nodes less against a DR of 0.05 % than of 0.2 %.
TEST(PoseGraphOdometryModel, DriftFractionSetLaterRebuildsTheEdgesAndWeighsDrAgainstClosures) {
  const synthetic::Mission mission = synthetic::makeLawnmowerMission(missionOptions(2));
  auto solve = [&](double configured, std::optional<double> later) {
    PoseGraphOptions options = graphOptions(40);  // the whole mission in the window
    options.odometry_drift_fraction = configured;
    options.odometry_random_walk_m_per_sqrt_m = 0.002;  // the drift fraction dominates the turns' edges
    SlidingWindowPoseGraph graph(options);
    for (const synthetic::Node& n : mission.nodes)
      EXPECT_TRUE(graph.addNode(n.subframe_id, n.utime_us, n.dr, n.distance_m).ok);
    if (later) {
      EXPECT_TRUE(graph.setOdometryDriftFraction(*later).ok);
      EXPECT_DOUBLE_EQ(graph.odometryDriftFraction(), *later);
    }
    for (const synthetic::Closure& c : mission.closures) {
      LoopClosure closure = c.closure;
      // DR's own relative pose, shifted 2 m across track: a closure set that disagrees with DR.
      auto node = [&](int64_t id) {
        return *std::find_if(mission.nodes.begin(), mission.nodes.end(),
                             [&](const synthetic::Node& n) { return n.subframe_id == id; });
      };
      const synthetic::Node a = node(closure.subframe_id_a);
      const synthetic::Node b = node(closure.subframe_id_b);
      closure.T_a_b = sss::core::between(a.dr, b.dr);
      closure.T_a_b.translation.y() += 2.0;
      closure.covariance = Matrix6d::Identity();
      closure.covariance.bottomRightCorner<3, 3>() = 1e-4 * Eigen::Matrix3d::Identity();
      EXPECT_TRUE(graph.addLoopClosure(closure).ok);
    }
    EXPECT_TRUE(graph.optimize().ok);
    double moved_m = 0.0;
    for (size_t i = 0; i < mission.nodes.size(); ++i)
      moved_m = std::max(moved_m, (graph.nodes()[i].T_world_body.translation - mission.nodes[i].dr.translation).norm());
    return std::make_pair(estimates(graph), moved_m);
  };
  const auto [set_later, moved_tight] = solve(0.002, 0.0005);
  const auto [configured, moved_configured] = solve(0.0005, std::nullopt);
  ASSERT_EQ(set_later.size(), configured.size());
  for (size_t i = 0; i < set_later.size(); ++i)
    EXPECT_NEAR((set_later[i].translation - configured[i].translation).norm(), 0.0, 1e-6) << i;
  const auto [unused, moved_loose] = solve(0.002, std::nullopt);
  std::printf("largest move of a node from DR under closures 2 m off: %.2f m (drift 0.05 %%), %.2f m (0.2 %%)\n",
              moved_tight, moved_loose);
  EXPECT_LT(moved_tight, 0.6 * moved_loose);
  SlidingWindowPoseGraph graph(graphOptions());
  EXPECT_FALSE(graph.setOdometryDriftFraction(-0.001).ok);
  EXPECT_FALSE(graph.setOdometryDriftFraction(std::numeric_limits<double>::quiet_NaN()).ok);
}

TEST(PoseGraph, WithoutClosuresTheEstimateIsDr) {
  const synthetic::Mission mission = synthetic::makeLawnmowerMission(missionOptions(2));
  SlidingWindowPoseGraph graph(graphOptions());
  for (const synthetic::Node& n : mission.nodes) {
    ASSERT_TRUE(graph.addNode(n.subframe_id, n.utime_us, n.dr, n.distance_m).ok);
    graph.optimize();
  }
  for (size_t i = 0; i < mission.nodes.size(); ++i) {
    const Pose e = *graph.estimate(mission.nodes[i].subframe_id);
    EXPECT_NEAR((e.translation - mission.nodes[i].dr.translation).norm(), 0.0, 1e-6);
    EXPECT_NEAR(e.rotation.angularDistance(mission.nodes[i].dr.rotation), 0.0, 1e-8);
  }
  EXPECT_EQ(graph.correctionAt(mission.nodes[10].utime_us).status, CorrectionStatus::kDrOnly);
}

// One mission with 20 % false closures (3-10 m, 2-10 deg): none accepted, ATE far below DR. The
// multi-seed statistics are in pose_graph_mission_test.cpp.
TEST(PoseGraph, RejectsFalseClosuresOnOneMission) {
  const synthetic::Mission mission = synthetic::makeLawnmowerMission(missionOptions(1, 0.2));
  const MissionRun r = run(mission, graphOptions());
  EXPECT_EQ(r.false_accepted, 0);
  EXPECT_GE(r.true_accepted, 12);  // of 13 true closures
  EXPECT_LT(r.ate_window_m, 0.4 * r.ate_dr_m);
}

// A closure to a node that left the window long ago still corrects the newest node.
TEST(PoseGraph, ClosureToAMarginalisedNodeIsApplied) {
  const synthetic::Mission mission = synthetic::makeLawnmowerMission(missionOptions(4));
  PoseGraphOptions options = graphOptions(4);
  SlidingWindowPoseGraph graph(options);
  for (const synthetic::Node& n : mission.nodes) {
    ASSERT_TRUE(graph.addNode(n.subframe_id, n.utime_us, n.dr, n.distance_m).ok);
    graph.optimize();
  }
  // The last line's nodes against the first line's (marginalised) nodes, side by side 400 m apart:
  // true relative poses, so the newest nodes must move toward the truth.
  const size_t last = mission.nodes.size() - 1;
  const double error_before = (graph.estimate(mission.nodes[last].subframe_id)->translation -
                               mission.nodes[last].truth.translation).norm();
  int added = 0;
  for (size_t j = last - 1; j <= last; ++j) {
    for (size_t i = 0; i < 4; ++i) {
      if (std::abs(mission.nodes[i].truth.translation.x() - mission.nodes[j].truth.translation.x()) > 1.0) continue;
      LoopClosure c;
      c.subframe_id_a = mission.nodes[i].subframe_id;
      c.subframe_id_b = mission.nodes[j].subframe_id;
      c.T_a_b = sss::core::between(mission.nodes[i].truth, mission.nodes[j].truth);
      c.covariance = mission.closures.front().closure.covariance;
      ASSERT_TRUE(graph.addLoopClosure(c).ok);
      ++added;
    }
  }
  ASSERT_EQ(added, 2);
  for (const NodeState& n : graph.nodes()) {
    if (n.subframe_id <= mission.nodes[3].subframe_id) {
      ASSERT_TRUE(n.marginalised);
    }
  }
  graph.optimize();
  EXPECT_EQ(graph.counters().closures_accepted, 2u);
  const double error_after = (graph.estimate(mission.nodes[last].subframe_id)->translation -
                              mission.nodes[last].truth.translation).norm();
  std::printf("newest node error: %.2f m before, %.2f m after the old-node closures\n", error_before, error_after);
  EXPECT_GT(error_before, 3.0);
  EXPECT_LT(error_after, 0.5 * error_before);
  EXPECT_EQ(graph.windowStats().constant_blocks, 2);
}

// The end-of-mission pass can also run mid-mission: it re-derives the marginalisation prior at the
// smoothed estimate, so the window goes on as if it had been online all along (within a few cm).
TEST(PoseGraph, WindowContinuesAfterFullSmoothing) {
  const synthetic::Mission mission = synthetic::makeLawnmowerMission(missionOptions(2));
  SlidingWindowPoseGraph smoothed(graphOptions()), online(graphOptions());
  feed(smoothed, mission, 0, 12);
  feed(online, mission, 0, 12);
  const UpdateReport report = smoothed.fullSmoothing();
  ASSERT_TRUE(report.ok) << report.message;
  EXPECT_EQ(smoothed.counters().full_smoothings, 1u);
  EXPECT_EQ(smoothed.windowStats().prior_nodes, online.windowStats().prior_nodes);
  feed(smoothed, mission, 12, mission.nodes.size());
  feed(online, mission, 12, mission.nodes.size());
  const std::vector<NodeState> a = smoothed.nodes(), b = online.nodes();
  double max_difference = 0.0;
  for (size_t i = 0; i < a.size(); ++i)
    if (!a[i].marginalised)
      max_difference = std::max(max_difference, (a[i].T_world_body.translation - b[i].T_world_body.translation).norm());
  std::printf("window after a mid-mission full smoothing vs online only: max %.3f m\n", max_difference);
  EXPECT_LT(max_difference, 0.1);
  const double ate_dr = synthetic::translationRmse(synthetic::drPoses(mission), mission.nodes);
  EXPECT_LT(synthetic::translationRmse(estimates(smoothed), mission.nodes), 0.4 * ate_dr);
}

std::string temporaryPath(const std::string& name) {
  return ::testing::TempDir() + "sss_optimiser_" + std::to_string(::getpid()) + "_" + name;
}

TEST(PoseGraphCheckpoint, RestoredGraphGivesIdenticalEstimatesAfterTheSameInput) {
  const synthetic::Mission mission = synthetic::makeLawnmowerMission(missionOptions(5, 0.2));
  SlidingWindowPoseGraph original(graphOptions(6));
  const size_t half = 11;
  feed(original, mission, 0, half);
  // A closure queued but not yet decided is part of the state too.
  const synthetic::Node& n = mission.nodes[half];
  ASSERT_TRUE(original.addNode(n.subframe_id, n.utime_us, n.dr, n.distance_m).ok);
  for (const synthetic::Closure& c : mission.closures) {
    if (c.newer_node == static_cast<int>(half)) {
        ASSERT_TRUE(original.addLoopClosure(c.closure).ok);
      }
  }
  const std::string path = temporaryPath("roundtrip.ckpt");
  ASSERT_TRUE(original.saveCheckpoint(path).ok);
  SlidingWindowPoseGraph restored(graphOptions(6));
  const Status loaded = restored.loadCheckpoint(path);
  ASSERT_TRUE(loaded.ok) << loaded.message;
  EXPECT_EQ(restored.numNodes(), original.numNodes());

  original.optimize();
  restored.optimize();
  feed(original, mission, half + 1, mission.nodes.size());
  feed(restored, mission, half + 1, mission.nodes.size());
  const std::vector<NodeState> a = original.nodes(), b = restored.nodes();
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].T_world_body.translation, b[i].T_world_body.translation) << i;
    EXPECT_EQ(a[i].T_world_body.rotation.coeffs(), b[i].T_world_body.rotation.coeffs()) << i;
    EXPECT_EQ(a[i].marginalised, b[i].marginalised);
  }
  EXPECT_EQ(original.counters().closures_accepted, restored.counters().closures_accepted);
  EXPECT_EQ(original.counters().closures_rejected_inconsistent, restored.counters().closures_rejected_inconsistent);
  EXPECT_EQ(original.counters().updates, restored.counters().updates);
  EXPECT_EQ(*original.covariance(mission.nodes.back().subframe_id), *restored.covariance(mission.nodes.back().subframe_id));
  std::remove(path.c_str());
}

TEST(PoseGraphCheckpoint, CorruptTruncatedOrForeignFilesAreRejected) {
  const synthetic::Mission mission = synthetic::makeLawnmowerMission(missionOptions(6));
  SlidingWindowPoseGraph graph(graphOptions(6));
  feed(graph, mission, 0, 12);
  const std::string path = temporaryPath("good.ckpt");
  ASSERT_TRUE(graph.saveCheckpoint(path).ok);
  std::ifstream in(path, std::ios::binary);
  const std::string good((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_GT(good.size(), 1000u);

  SlidingWindowPoseGraph target(graphOptions(6));
  feed(target, mission, 0, 3);
  const Pose before = *target.estimate(mission.nodes[2].subframe_id);
  auto tryLoad = [&](const std::string& bytes, const std::string& name) {
    const std::string bad = temporaryPath(name);
    std::ofstream(bad, std::ios::binary) << bytes;
    const Status s = target.loadCheckpoint(bad);
    std::remove(bad.c_str());
    return s;
  };
  const Status truncated = tryLoad(good.substr(0, good.size() / 2), "truncated.ckpt");
  EXPECT_FALSE(truncated.ok);
  EXPECT_NE(truncated.message.find("checksum"), std::string::npos) << truncated.message;
  EXPECT_FALSE(tryLoad(good.substr(0, good.size() - 5), "cut_checksum.ckpt").ok);
  std::string flipped = good;
  flipped[good.size() / 3] = flipped[good.size() / 3] == '1' ? '2' : '1';
  const Status corrupt = tryLoad(flipped, "flipped.ckpt");
  EXPECT_FALSE(corrupt.ok);
  EXPECT_NE(corrupt.message.find("checksum mismatch"), std::string::npos) << corrupt.message;
  EXPECT_FALSE(tryLoad("", "empty.ckpt").ok);
  EXPECT_FALSE(tryLoad(std::string(5000, '\0'), "zeros.ckpt").ok);
  EXPECT_FALSE(target.loadCheckpoint(temporaryPath("does_not_exist.ckpt")).ok);
  // A well-formed checksum over a wrong version or nonsense counts must still be refused.
  auto withChecksum = [](std::string payload) {
    uint64_t hash = 1469598103934665603ull;
    for (unsigned char ch : payload) {
      hash ^= ch;
      hash *= 1099511628211ull;
    }
    char line[40];
    std::snprintf(line, sizeof(line), "checksum %016llx\n", static_cast<unsigned long long>(hash));
    return payload + line;
  };
  const Status version = tryLoad(withChecksum("sss-pose-graph-checkpoint 99\n"), "version.ckpt");
  EXPECT_FALSE(version.ok);
  EXPECT_NE(version.message.find("version 99"), std::string::npos) << version.message;
  EXPECT_FALSE(tryLoad(withChecksum("sss-pose-graph-checkpoint 1\nstate 999999999999 0 0 0 0 -1 -1\n"), "huge.ckpt").ok);
  const size_t node_line = good.find("\nnode ");
  EXPECT_FALSE(tryLoad(withChecksum(good.substr(0, node_line + 1)), "no_nodes.ckpt").ok);
  // Every prefix cut at a line boundary and re-checksummed: refused, never a crash.
  for (size_t cut = good.find('\n'); cut != std::string::npos && cut + 1 < good.rfind("checksum");
       cut = good.find('\n', cut + 1))
    EXPECT_FALSE(tryLoad(withChecksum(good.substr(0, cut + 1)), "prefix.ckpt").ok) << cut;

  // The graph is unchanged by the failed loads and a good file still loads.
  EXPECT_EQ(target.numNodes(), 3u);
  EXPECT_EQ(target.estimate(mission.nodes[2].subframe_id)->translation, before.translation);
  EXPECT_TRUE(target.loadCheckpoint(path).ok);
  EXPECT_EQ(target.numNodes(), 12u);
  std::remove(path.c_str());
}

TEST(PoseGraphCheckpoint, WriteIsAtomicAndReportsUnwritablePaths) {
  SlidingWindowPoseGraph graph(graphOptions());
  ASSERT_TRUE(graph.addNode(1, 1000, Pose::identity(), 0.0).ok);
  const Status s = graph.saveCheckpoint("/nonexistent_dir_for_sss_test/graph.ckpt");
  EXPECT_FALSE(s.ok);
  EXPECT_NE(s.message.find("cannot open"), std::string::npos) << s.message;
  const std::string path = temporaryPath("atomic.ckpt");
  ASSERT_TRUE(graph.saveCheckpoint(path).ok);
  EXPECT_FALSE(std::ifstream(path + ".tmp").good());  // renamed into place
  std::remove(path.c_str());
}

TEST(PoseGraphCorrection, IsExactAtNodesInterpolatedBetweenAndHeldOutside) {
  const synthetic::Mission mission = synthetic::makeLawnmowerMission(missionOptions(3));
  PoseGraphOptions options = graphOptions();
  options.degraded_after_s = 600.0;
  SlidingWindowPoseGraph graph(options);
  feed(graph, mission, 0, mission.nodes.size());
  for (const NodeState& n : graph.nodes()) {
    const Correction c = graph.correctionAt(n.utime_us);
    const Pose corrected = c.T_corrected_dr * n.T_world_body_dr;
    EXPECT_NEAR((corrected.translation - n.T_world_body.translation).norm(), 0.0, 1e-9);
    EXPECT_NEAR(corrected.rotation.angularDistance(n.T_world_body.rotation), 0.0, 1e-9);
  }
  const std::vector<NodeState> nodes = graph.nodes();
  const NodeState& n0 = nodes[5];
  const NodeState& n1 = nodes[6];
  const Pose c0 = n0.T_world_body * n0.T_world_body_dr.inverse();
  const Pose c1 = n1.T_world_body * n1.T_world_body_dr.inverse();
  const int64_t quarter = n0.utime_us + (n1.utime_us - n0.utime_us) / 4;
  const double alpha = static_cast<double>(quarter - n0.utime_us) / static_cast<double>(n1.utime_us - n0.utime_us);
  const Pose expected = sss::core::interpolate(c0, c1, alpha);
  const Correction mid = graph.correctionAt(quarter);
  EXPECT_NEAR((mid.T_corrected_dr.translation - expected.translation).norm(), 0.0, 1e-9);
  // Held before the first and after the last node; the covariance grows with the DR distance.
  const Correction early = graph.correctionAt(nodes.front().utime_us - 10000000);
  EXPECT_NEAR((early.T_corrected_dr.translation -
               (nodes.front().T_world_body * nodes.front().T_world_body_dr.inverse()).translation).norm(), 0.0, 1e-12);
  const Correction at_last = graph.correctionAt(nodes.back().utime_us);
  const Correction later = graph.correctionAt(nodes.back().utime_us + 100000000);
  EXPECT_NEAR((later.T_corrected_dr.translation - at_last.T_corrected_dr.translation).norm(), 0.0, 1e-12);
  EXPECT_GT(later.covariance(0, 0), at_last.covariance(0, 0));
  EXPECT_EQ(at_last.status, CorrectionStatus::kCorrected);
  EXPECT_EQ(at_last.update_utime_us, nodes.back().utime_us);
  EXPECT_EQ(at_last.accepted_closures, static_cast<int>(mission.closures.size()));
  // The newest closure involves the last node: degraded only degraded_after_s later.
  EXPECT_EQ(graph.correctionAt(nodes.back().utime_us + 599000000).status, CorrectionStatus::kCorrected);
  EXPECT_EQ(graph.correctionAt(nodes.back().utime_us + 601000000).status, CorrectionStatus::kDegraded);
  // Covariance: symmetric positive definite, as the node's at the node.
  const Eigen::LLT<Matrix6d> llt(at_last.covariance);
  EXPECT_EQ(llt.info(), Eigen::Success);
  EXPECT_NEAR((at_last.covariance - *graph.covariance(nodes.back().subframe_id) -
               SlidingWindowPoseGraph::odometryCovariance(options, 0.0)).norm(), 0.0, 1e-9);
}

// Two lines 50 m apart (ids 1-10 east, 11-20 back west, DR exact). Subframe 15 is matched 3 m
// off along track to its two neighbours 5 and 7 on the first line: both closures carry that one
// error, so their cycle with DR closes and PCM finds them consistent. Counted by independent
// subframes they are one piece of evidence and wait; two right closures of other subframes then
// win over them. Counting closures, the pair is accepted at once and, once accepted, keeps the tie
// against the two right ones.
TEST(PoseGraph, ClosuresSharingOneSubframeCountOnce) {
  auto nodePose = [](int id) {
    const bool east = id <= 10;
    const double x_m = east ? 20.0 * (id - 1) : 180.0 - 20.0 * (id - 11);
    const Eigen::Quaterniond q(Eigen::AngleAxisd(east ? 0.0 : M_PI, Eigen::Vector3d::UnitZ()));
    return Pose(q, Eigen::Vector3d(x_m, east ? 0.0 : 50.0, 20.0));
  };
  auto closure = [&](int a, int b, double along_error_m) {
    LoopClosure c;
    c.subframe_id_a = a;
    c.subframe_id_b = b;
    const Pose error(Eigen::Quaterniond::Identity(), Eigen::Vector3d(along_error_m, 0.0, 0.0));
    c.T_a_b = nodePose(a).inverse() * (nodePose(b) * error);
    c.covariance = 0.01 * Matrix6d::Identity();
    return c;
  };
  auto addBothAndOptimise = [&](SlidingWindowPoseGraph& graph, std::pair<int, int> first, std::pair<int, int> second,
                                double along_error_m) {
    ASSERT_TRUE(graph.addLoopClosure(closure(first.first, first.second, along_error_m)).ok);
    ASSERT_TRUE(graph.addLoopClosure(closure(second.first, second.second, along_error_m)).ok);
    graph.optimize();
  };
  auto statusOf = [](const SlidingWindowPoseGraph& graph, int a, int b) {
    for (const ClosureRecord& r : graph.closures())
      if (r.closure.subframe_id_a == a && r.closure.subframe_id_b == b) return r.status;
    return ClosureStatus::kSuperseded;
  };
  for (const bool count_independent : {true, false}) {
    SCOPED_TRACE(count_independent ? "independent subframes" : "every closure");
    PoseGraphOptions options = graphOptions();
    options.pcm_count_independent_subframes = count_independent;
    SlidingWindowPoseGraph graph(options);
    double distance_m = 0.0;
    for (int id = 1; id <= 20; ++id) {
      if (id > 1) distance_m += (nodePose(id).translation - nodePose(id - 1).translation).norm();
      ASSERT_TRUE(graph.addNode(id, 1000000LL * id * 10, nodePose(id), distance_m).ok);
      graph.optimize();
    }
    addBothAndOptimise(graph, {5, 15}, {7, 15}, 3.0);
    if (HasFatalFailure()) return;
    const ClosureStatus shared = count_independent ? ClosureStatus::kPending : ClosureStatus::kAccepted;
    EXPECT_EQ(statusOf(graph, 5, 15), shared);
    EXPECT_EQ(statusOf(graph, 7, 15), shared);

    addBothAndOptimise(graph, {3, 18}, {9, 12}, 0.0);
    if (HasFatalFailure()) return;
    const ClosureStatus right = count_independent ? ClosureStatus::kAccepted : ClosureStatus::kRejected;
    EXPECT_EQ(statusOf(graph, 3, 18), right);
    EXPECT_EQ(statusOf(graph, 9, 12), right);
    const ClosureStatus wrong = count_independent ? ClosureStatus::kRejected : ClosureStatus::kAccepted;
    EXPECT_EQ(statusOf(graph, 5, 15), wrong);
    EXPECT_EQ(statusOf(graph, 7, 15), wrong);
    if (count_independent) {
      const Pose estimate = *graph.estimate(15);
      EXPECT_LT((estimate.translation - nodePose(15).translation).norm(), 0.05);
    }
  }
}

TEST(PoseGraphInput, RefusesBadNodesAndClosuresWithAReason) {
  SlidingWindowPoseGraph graph(graphOptions());
  ASSERT_TRUE(graph.addNode(10, 1000000, Pose::identity(), 0.0).ok);
  const Pose ahead(Eigen::Quaterniond::Identity(), Eigen::Vector3d(100.0, 0.0, 0.0));
  ASSERT_TRUE(graph.addNode(11, 51000000, ahead, 100.0).ok);
  EXPECT_FALSE(graph.addNode(11, 99000000, ahead, 150.0).ok);  // duplicate id
  const Status late = graph.addNode(12, 51000000, ahead, 150.0);
  EXPECT_FALSE(late.ok);
  EXPECT_NE(late.message.find("time order"), std::string::npos) << late.message;
  Pose nan_pose = ahead;
  nan_pose.translation.x() = std::nan("");
  EXPECT_FALSE(graph.addNode(13, 99000000, nan_pose, 150.0).ok);
  EXPECT_FALSE(graph.addNode(14, 99000000, ahead, 50.0).ok);  // distance went backwards
  EXPECT_EQ(graph.counters().nodes_refused, 4u);

  LoopClosure c;
  c.subframe_id_a = 10;
  c.subframe_id_b = 99;
  c.covariance = 0.01 * Matrix6d::Identity();
  const Status unknown = graph.addLoopClosure(c);
  EXPECT_FALSE(unknown.ok);
  EXPECT_NE(unknown.message.find("subframe id 99 is unknown"), std::string::npos) << unknown.message;
  c.subframe_id_b = 10;
  EXPECT_FALSE(graph.addLoopClosure(c).ok);  // self loop
  c.subframe_id_b = 11;
  c.covariance(2, 2) = -1.0;
  const Status not_pd = graph.addLoopClosure(c);
  EXPECT_FALSE(not_pd.ok);
  EXPECT_NE(not_pd.message.find("positive definite"), std::string::npos) << not_pd.message;
  c.covariance = 0.01 * Matrix6d::Identity();
  c.T_a_b.rotation.coeffs() << 0.0, 0.0, 0.0, 2.0;  // not a unit quaternion
  EXPECT_FALSE(graph.addLoopClosure(c).ok);
  EXPECT_EQ(graph.counters().closures_refused, 4u);
  EXPECT_TRUE(graph.closures().empty());
  EXPECT_TRUE(graph.optimize().ok);
}

TEST(PoseGraphInput, NewerAssociationRoundSupersedesTheOlderClosure) {
  SlidingWindowPoseGraph graph(graphOptions());
  ASSERT_TRUE(graph.addNode(1, 1000000, Pose::identity(), 0.0).ok);
  ASSERT_TRUE(graph.addNode(2, 51000000, Pose(Eigen::Quaterniond::Identity(), Eigen::Vector3d(100, 0, 0)), 100.0).ok);
  LoopClosure c;
  c.subframe_id_a = 1;
  c.subframe_id_b = 2;
  c.T_a_b = Pose(Eigen::Quaterniond::Identity(), Eigen::Vector3d(100, 0, 0));
  c.covariance = 0.01 * Matrix6d::Identity();
  c.association_round = 1;
  ASSERT_TRUE(graph.addLoopClosure(c).ok);
  c.association_round = 0;
  EXPECT_FALSE(graph.addLoopClosure(c).ok);  // an older round than the one held
  c.association_round = 2;
  ASSERT_TRUE(graph.addLoopClosure(c).ok);
  ASSERT_EQ(graph.closures().size(), 2u);
  EXPECT_EQ(graph.closures()[0].status, ClosureStatus::kSuperseded);
  EXPECT_EQ(graph.counters().closures_superseded, 1u);
  EXPECT_EQ(graph.counters().closures_pending, 1u);
}

TEST(PoseGraphOptions, ValidationNamesTheField) {
  EXPECT_TRUE(validatePoseGraphOptions(PoseGraphOptions()).empty());
  auto problemsOf = [](auto change) {
    PoseGraphOptions o;
    change(o);
    const std::vector<std::string> p = validatePoseGraphOptions(o);
    return p.empty() ? std::string() : p.front();
  };
  EXPECT_NE(problemsOf([](PoseGraphOptions& o) { o.window_size = 1; }).find("window_size"), std::string::npos);
  EXPECT_NE(problemsOf([](PoseGraphOptions& o) { o.odometry_drift_fraction = -0.1; }).find("odometry_drift_fraction"),
            std::string::npos);
  EXPECT_NE(problemsOf([](PoseGraphOptions& o) { o.robust_loss = "tukey"; }).find("robust_loss"), std::string::npos);
  EXPECT_NE(problemsOf([](PoseGraphOptions& o) { o.pcm_chi2 = 0.0; }).find("pcm_chi2"), std::string::npos);
  EXPECT_NE(problemsOf([](PoseGraphOptions& o) { o.max_iterations = 0; }).find("max_iterations"), std::string::npos);
  EXPECT_NE(problemsOf([](PoseGraphOptions& o) { o.min_consistent_closures = 500; }).find("min_consistent_closures"),
            std::string::npos);
  PoseGraphOptions bad;
  bad.first_node_sigma_m = 0.0;
  EXPECT_THROW(SlidingWindowPoseGraph graph(bad), std::invalid_argument);
}

TEST(PoseGraphOptions, YamlLoaderNamesTheKeyAndValue) {
  sss::core::Config config = sss::core::Config::fromString(
      "optimiser:\n  window_size: 1\n  robust_loss: tukey\n  pcm_chi2: 9.0\n  windwo_size: 5\n");
  sss::core::ConfigSection section = config.section("optimiser");
  PoseGraphOptions options;
  readPoseGraphOptions(section, options);
  section.rejectUnknownKeys();
  const std::string report = config.problemReport();
  EXPECT_NE(report.find("optimiser.window_size"), std::string::npos) << report;
  EXPECT_NE(report.find("tukey"), std::string::npos) << report;
  EXPECT_NE(report.find("optimiser.windwo_size"), std::string::npos) << report;
  EXPECT_DOUBLE_EQ(options.pcm_chi2, 9.0);
  EXPECT_EQ(options.window_size, PoseGraphOptions().window_size);  // the bad value is not taken
}

}  // namespace
}  // namespace sss::optimiser
