// Helpers shared by the pose-graph tests: the test lawnmower (5 lines of 400 m, 100 m subframes),
// feeding it node by node to a graph, noisy absolute fixes of its nodes, and the trajectory errors of a run.
#pragma once

#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "pipeline/optimiser/pose_graph.hpp"
#include "tools/fixtures/synthetic_mission.hpp"

namespace sss::optimiser::test_helpers {

using sss::core::Pose;

// The test mission: the defaults of synthetic::MissionOptions give 20 nodes, 16 closures and a DR
// error of several metres at the end (steaming error 0.2 deg, 0.2 % scale, velocity noise).
inline synthetic::MissionOptions missionOptions(uint64_t seed, double false_fraction = 0.0) {
  synthetic::MissionOptions o;
  o.seed = seed;
  o.false_fraction = false_fraction;
  return o;
}

// A good INS: drifting about 0.1 % while the graph's odometry model says 0.5 %, so what DR says
// about the lines' separation is worth comparing the closures against.
inline synthetic::MissionOptions goodInsMissionOptions(uint64_t seed) {
  synthetic::MissionOptions o = missionOptions(seed);
  o.heading_bias_rad = 0.0005;
  o.heading_noise_sigma_rad = 0.0005;
  o.velocity_scale_error = 0.001;
  o.position_random_walk_m_per_sqrt_m = 0.005;
  return o;
}

inline PoseGraphOptions graphOptions(int window_size = 8) {
  PoseGraphOptions o;
  o.window_size = window_size;  // two lines of four nodes: most adjacent-line closures stay inside
  return o;
}

// An absolute fix of the node's true position with noise of sigma_m per axis, tied through its DR.
inline AbsoluteFix fixAt(const synthetic::Node& node, double sigma_m, std::mt19937_64& random,
                         const char* source = "gnss") {
  std::normal_distribution<double> gauss(0.0, sigma_m);
  AbsoluteFix fix;
  fix.utime_us = node.utime_us;
  fix.position_ne_m = node.truth.translation.head<2>() + Eigen::Vector2d(gauss(random), gauss(random));
  fix.covariance_m2 = sigma_m * sigma_m * Eigen::Matrix2d::Identity();
  fix.dr_position_m = node.dr.translation;
  fix.dr_distance_m = node.distance_m;
  fix.source = source;
  return fix;
}

// Every node's closures and, with fixes, a USBL fix (1 m, drawn from `seed`) at every other node,
// one update per node, then full smoothing.
inline SlidingWindowPoseGraph solvedWithUsbl(const synthetic::Mission& mission, const PoseGraphOptions& options,
                                             bool fixes, uint64_t seed) {
  std::mt19937_64 random(seed);
  SlidingWindowPoseGraph graph(options);
  for (size_t i = 0; i < mission.nodes.size(); ++i) {
    const synthetic::Node& n = mission.nodes[i];
    EXPECT_TRUE(graph.addNode(n.subframe_id, n.utime_us, n.dr, n.distance_m).ok);
    for (const synthetic::Closure& c : mission.closures) {
      if (c.newer_node == static_cast<int>(i)) {
        EXPECT_TRUE(graph.addLoopClosure(c.closure).ok);
      }
    }
    if (fixes && i % 2 == 0) {
      EXPECT_TRUE(graph.addFix(fixAt(n, 1.0, random, "usbl")).ok);
    }
    EXPECT_TRUE(graph.optimize().ok);
  }
  EXPECT_TRUE(graph.fullSmoothing().ok);
  return graph;
}

inline std::vector<Pose> estimates(const SlidingWindowPoseGraph& graph) {
  std::vector<Pose> out;
  for (const NodeState& n : graph.nodes()) out.push_back(n.T_world_body);
  return out;
}

// Feeds nodes [begin, end) and the closures that become available with them, one update per node.
inline void feed(SlidingWindowPoseGraph& graph, const synthetic::Mission& mission, size_t begin, size_t end) {
  for (size_t i = begin; i < end; ++i) {
    const synthetic::Node& n = mission.nodes[i];
    ASSERT_TRUE(graph.addNode(n.subframe_id, n.utime_us, n.dr, n.distance_m).ok);
    for (const synthetic::Closure& c : mission.closures) {
      if (c.newer_node == static_cast<int>(i)) {
        ASSERT_TRUE(graph.addLoopClosure(c.closure).ok);
      }
    }
    const UpdateReport report = graph.optimize();
    ASSERT_TRUE(report.ok) << report.message;
  }
}

struct MissionRun {
  double ate_dr_m = 0.0;
  double ate_window_m = 0.0;  // each node's estimate at the end of the online run
  double ate_full_m = 0.0;    // after fullSmoothing()
  int false_accepted = 0;
  int true_accepted = 0;
};

inline MissionRun run(const synthetic::Mission& mission, const PoseGraphOptions& options) {
  SlidingWindowPoseGraph graph(options);
  feed(graph, mission, 0, mission.nodes.size());
  MissionRun r;
  r.ate_dr_m = synthetic::translationRmse(synthetic::drPoses(mission), mission.nodes);
  r.ate_window_m = synthetic::translationRmse(estimates(graph), mission.nodes);
  const std::vector<ClosureRecord> records = graph.closures();
  for (size_t c = 0; c < records.size(); ++c) {
    if (records[c].status != ClosureStatus::kAccepted) continue;
    (mission.closures[c].is_false ? r.false_accepted : r.true_accepted) += 1;
  }
  EXPECT_TRUE(graph.fullSmoothing().ok);
  r.ate_full_m = synthetic::translationRmse(estimates(graph), mission.nodes);
  return r;
}

}  // namespace sss::optimiser::test_helpers
