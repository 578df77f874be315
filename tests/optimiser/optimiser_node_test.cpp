// sss-optimiser as a process over LCM udpm and DDS on loopback: two anti-parallel survey lines of
// hand-built subframes whose second line's DR is 2 m east of the truth, loop closures carrying
// the true relative poses, and SSS_NAV samples inside the lines. Checks: one SSS_POSE per nav
// sample (DR before the closures, corrected after), SSS_TRAJECTORY, the DDS correction (live and
// to a late joiner), bad input counted in SSS_STATUS, nav -> pose latency, and a SIGKILL restart
// from the checkpoint followed by a SIGTERM that writes the products. Prints the latency figures.
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"  // lcm-gen decode() false positive at -O3
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "navigation_correction.h"
#include "pipeline/core/geodesy.hpp"
#include "pipeline/core/pose.hpp"
#include "pipeline/core/time.hpp"
#include "pipeline/messages/closure_messages.hpp"
#include "pipeline/messages/subframe_messages.hpp"
#include "pipeline/transport/dds.hpp"
#include "pipeline/transport/lcm_bus.hpp"
#include "sss_msgs/nav_t.hpp"
#include "sss_msgs/pose_t.hpp"
#include "sss_msgs/status_t.hpp"
#include "sss_msgs/trajectory_t.hpp"
#include "tools/fixtures/nav_message.hpp"
#include "tools/fixtures/optimiser_node_config.hpp"
#include "tools/fixtures/poll_until.hpp"
#include "tools/fixtures/spawn_process.hpp"

namespace sss::optimiser {
namespace {

namespace fs = std::filesystem;
using sss::core::Pose;
namespace dds = sss::transport::dds;

// ---- the mission -----------------------------------------------------------------------------------
// Line A: north along east 0 from north 0, 2 m/s, one ping per 0.5 s (1 m), DR exact. A 200 m
// excursion (100 s), then line B: south along east 6 from north 120; its DR is kDrErrorM east of the
// truth, the error gathered on the excursion (~2 sigma of the graph's default odometry model over
// 220 m). Six subframes of 20 pings per line; subframe j of A and 5 - j of B share a centre northing.
constexpr int64_t kT0 = 1'700'000'000'000'000;  // us since the epoch
constexpr int64_t kPingPeriodUs = 500'000;
constexpr int64_t kLineBStartUs = kT0 + 160'000'000;
constexpr int kPingsPerSubframe = 20;
constexpr int kCentre = 10;
constexpr int kSubframesPerLine = 6;
constexpr double kSpeed = 2.0;
constexpr double kDepthM = 20.0;
constexpr double kLineBEastM = 6.0;
constexpr double kDrErrorM = 2.0;
// Corrected positions must be this close to the truth (the DR is kDrErrorM off on line B; with
// closures of 0.05 m sigma carrying the true relative poses, the graph gets within millimetres).
constexpr double kCorrectedToleranceM = 0.1;
constexpr double kOriginLat = 58.25;
constexpr double kOriginLon = 11.45;

struct State {
  Pose truth;
  Pose dr;
  double distance_m = 0.0;
};

State stateAt(int64_t utime_us) {
  State s;
  if (utime_us < kLineBStartUs) {
    const double t = 1e-6 * static_cast<double>(utime_us - kT0);
    s.truth = Pose(sss::core::quaternionFromEuler(0.0, 0.0, 0.0), Eigen::Vector3d(kSpeed * t, 0.0, kDepthM));
    s.dr = s.truth;
    s.distance_m = kSpeed * t;
  } else {
    const double t = 1e-6 * static_cast<double>(utime_us - kLineBStartUs);
    const Eigen::Quaterniond q = sss::core::quaternionFromEuler(0.0, 0.0, M_PI);
    s.truth = Pose(q, Eigen::Vector3d(120.0 - kSpeed * t, kLineBEastM, kDepthM));
    s.dr = Pose(q, Eigen::Vector3d(120.0 - kSpeed * t, kLineBEastM + kDrErrorM, kDepthM));
    s.distance_m = 320.0 + kSpeed * t;
  }
  return s;
}

// Ping k of a line (k counts from the line's first ping).
int64_t pingUtime(int line, int k) { return (line == 0 ? kT0 : kLineBStartUs) + k * kPingPeriodUs; }

// Subframe ids: line A 0..5, line B 6..11 (and 12 after the restart).
int64_t subframeId(int line, int j) { return line * kSubframesPerLine + j; }
int64_t centreUtime(int line, int j) { return pingUtime(line, j * kPingsPerSubframe + kCentre); }

sss::core::Subframe makeSubframe(int line, int j) {
  sss::core::Subframe sf;
  sf.id = subframeId(line, j);
  sf.line_id = line;
  sf.centre_ping_index = kCentre;
  sf.geometry.bins_per_side = 8;
  sf.geometry.bin_size_m = 0.5;
  sf.geometry.first_bin_range_m = 1.0;
  for (int r = 0; r < kPingsPerSubframe; ++r) {
    const int k = j * kPingsPerSubframe + r;
    sss::core::SubframePing ping;
    ping.utime_us = pingUtime(line, k);
    ping.ping_number = line * 1000 + k;
    const State s = stateAt(ping.utime_us);
    ping.T_world_body = s.dr;
    ping.altitude_m = 10.0;
    ping.distance_travelled_m = s.distance_m;
    sf.pings.push_back(ping);
  }
  sf.image.assign(static_cast<size_t>(sf.rows() * sf.cols()), 0.0f);
  sf.mask.assign(static_cast<size_t>(sf.rows() * sf.cols()), 0);
  return sf;
}

// The closure of A's subframe j with B's subframe 5 - j: the TRUE relative pose of the centres.
sss::core::LoopClosure makeClosure(int j) {
  sss::core::LoopClosure c;
  c.subframe_id_a = subframeId(0, j);
  c.subframe_id_b = subframeId(1, kSubframesPerLine - 1 - j);
  c.centre_utime_a_us = centreUtime(0, j);
  c.centre_utime_b_us = centreUtime(1, kSubframesPerLine - 1 - j);
  c.T_a_b = stateAt(c.centre_utime_a_us).truth.inverse() * stateAt(c.centre_utime_b_us).truth;
  c.covariance.setZero();
  for (int i = 0; i < 3; ++i) c.covariance(i, i) = 0.05 * 0.05;
  for (int i = 3; i < 6; ++i) c.covariance(i, i) = 0.002 * 0.002;
  c.num_matches = 400;
  c.num_inliers = 150;
  c.total_cost = 1.0;
  c.mean_zncc = 0.8f;
  return c;
}

sss_msgs::nav_t makeNav(int64_t utime_us, const sss::core::LocalTangentPlane& plane) {
  const State s = stateAt(utime_us);
  return sss::test::makeNavMessage(utime_us, s.dr, s.distance_m, 10.0, kSpeed, plane);
}

Eigen::Vector3d positionOf(const sss_msgs::pose_t& p) {
  return Eigen::Vector3d(p.position_ned_m[0], p.position_ned_m[1], p.position_ned_m[2]);
}

double percentileMs(std::vector<double> values_ms, double percent) {
  if (values_ms.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::sort(values_ms.begin(), values_ms.end());
  const size_t rank = static_cast<size_t>(std::ceil(percent / 100.0 * static_cast<double>(values_ms.size())));
  return values_ms[std::min(values_ms.size() - 1, rank == 0 ? 0 : rank - 1)];
}

// Kills the child if a failed assertion leaves the test early.
struct ChildGuard {
  pid_t pid = -1;
  ~ChildGuard() {
    if (pid > 0) {
      ::kill(pid, SIGKILL);
      ::waitpid(pid, nullptr, 0);
    }
  }
};

// Exit code within timeout_s; -1 after a signal; -2 when it had to be killed.
int waitExitWithin(pid_t pid, double timeout_s) {
  const int64_t deadline = sss::core::monotonicUtime() + static_cast<int64_t>(timeout_s * 1e6);
  for (;;) {
    int status = 0;
    const pid_t done = ::waitpid(pid, &status, WNOHANG);
    if (done == pid) return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    if (sss::core::monotonicUtime() > deadline) {
      ::kill(pid, SIGKILL);
      ::waitpid(pid, nullptr, 0);
      return -2;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
}

// Everything the test hears from the process.
struct Observer {
  std::map<int64_t, int> pose_count;                   // utime -> SSS_POSE messages
  std::map<int64_t, sss_msgs::pose_t> poses;           // utime -> newest SSS_POSE
  std::map<int64_t, int64_t> pose_arrival_us;          // utime -> monotonic arrival (first)
  std::vector<std::vector<int64_t>> trajectory_ids;    // per SSS_TRAJECTORY
  std::vector<std::map<int64_t, Eigen::Vector3d>> trajectories;
  std::map<pid_t, std::map<std::string, double>> counters;  // newest SSS_STATUS counters per pid
  std::map<pid_t, int> status_messages;
  std::vector<sss_dds_NavigationCorrection> dds_samples;
};

TEST(OptimiserNode, NavToPoseClosuresCorrectDdsCheckpointRestartAndBadInput) {
  const int64_t test_start_us = sss::core::monotonicUtime();
  const pid_t self = getpid();
  const std::string dir = ::testing::TempDir() + "/optimiser_node_" + std::to_string(self);
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string state_dir = dir + "/state";
  const std::string lcm_url =
      "udpm://239.255.76.67:" + std::to_string(31000 + self % 2000) + "?ttl=0&recv_buf_size=16777216";
  // Disjoint from dds_test's 100..199; the config allows 0..232.
  const uint32_t domain = 200 + static_cast<uint32_t>(self % 32);
  const std::string topic_name = "sss_navigation_correction_node_test";
  const std::string config = dir + "/optimiser.yaml";
  sss::test::OptimiserNodeConfig node_config;
  node_config.origin_latitude_deg = kOriginLat;
  node_config.origin_longitude_deg = kOriginLon;
  node_config.lcm_url = lcm_url;
  node_config.state_directory = state_dir;
  node_config.dds_domain_id = domain;
  node_config.dds_topic = topic_name;
  node_config.vehicle_id = 7;
  ASSERT_TRUE(sss::test::writeOptimiserNodeConfig(config, node_config));
  const sss::core::LocalTangentPlane plane(kOriginLat, kOriginLon);

  // ---- the test's side of the bus --------------------------------------------------------------------
  sss::core::HealthMonitor health(sss::core::monotonicUtime());
  sss::transport::LcmBus bus(lcm_url, health);
  ASSERT_TRUE(bus.good());
  Observer seen;
  bus.subscribe<sss_msgs::pose_t>("SSS_POSE", [&](const sss_msgs::pose_t& m) {
    ++seen.pose_count[m.utime];
    seen.poses[m.utime] = m;
    seen.pose_arrival_us.emplace(m.utime, sss::core::monotonicUtime());
  });
  bus.subscribe<sss_msgs::trajectory_t>("SSS_TRAJECTORY", [&](const sss_msgs::trajectory_t& m) {
    seen.trajectory_ids.push_back(m.subframe_id);
    std::map<int64_t, Eigen::Vector3d> nodes;
    for (int i = 0; i < m.num_nodes; ++i) {
      nodes[m.subframe_id[i]] = Eigen::Vector3d(m.position_ned_m[i][0], m.position_ned_m[i][1], m.position_ned_m[i][2]);
    }
    seen.trajectories.push_back(nodes);
  });
  bus.subscribe<sss_msgs::status_t>("SSS_STATUS", [&](const sss_msgs::status_t& m) {
    if (m.process != "sss-optimiser") return;
    ++seen.status_messages[m.pid];
    auto& counters = seen.counters[m.pid];
    for (int i = 0; i < m.num_counters; ++i) counters[m.counter_name[i]] = m.counter_value[i];
  });

  // DDS reader (the navigation computer), in its own participant on the isolated loopback domain,
  // created before the process so discovery is done when the first correction goes out.
  dds::Participant participant(domain, dds::loopbackConfigXml());
  ASSERT_TRUE(participant.good()) << participant.error();
  dds::Topic<sss_dds_NavigationCorrection> topic(participant, &sss_dds_NavigationCorrection_desc, topic_name);
  ASSERT_TRUE(topic.good()) << topic.error();
  dds::QosSettings deep;
  deep.history_depth = 64;  // keep every live sample between two polls
  dds::Reader<sss_dds_NavigationCorrection> reader(participant, topic, deep);
  ASSERT_TRUE(reader.good()) << reader.error();

  auto pumpFor = [&](double seconds) {
    const int64_t until = sss::core::monotonicUtime() + static_cast<int64_t>(seconds * 1e6);
    for (;;) {
      const int64_t now = sss::core::monotonicUtime();
      if (now >= until) break;
      bus.handleTimeout(static_cast<int>(std::min<int64_t>(10, (until - now + 999) / 1000)));
      sss_dds_NavigationCorrection sample{};
      while (reader.take(sample)) seen.dds_samples.push_back(sample);
    }
  };
  auto waitFor = [&](const std::function<bool()>& done, double timeout_s) {
    return sss::test::pollUntil([&] { pumpFor(0.01); }, done, timeout_s);
  };
  auto counterOf = [&](pid_t pid, const std::string& name) {
    const auto p = seen.counters.find(pid);
    if (p == seen.counters.end()) return -1.0;
    const auto c = p->second.find(name);
    return c == p->second.end() ? -1.0 : c->second;
  };

  std::set<int64_t> nav_sent;  // utimes of valid nav samples
  auto sendNav = [&](int64_t utime_us) {
    const sss_msgs::nav_t nav = makeNav(utime_us, plane);
    bus.publish("SSS_NAV", nav);
    nav_sent.insert(utime_us);
  };
  // Sends the samples and waits for their poses.
  auto sendNavAndWait = [&](const std::vector<int64_t>& utimes) {
    for (int64_t t : utimes) {
      sendNav(t);
      pumpFor(0.005);
    }
    return waitFor([&] {
      for (int64_t t : utimes)
        if (!seen.pose_count.count(t)) return false;
      return true;
    }, 5.0);
  };
  auto startOptimiser = [&]() {
    const pid_t pid = sss::test::spawnProcess({SSS_OPTIMISER_PATH, "--config", config});
    if (pid <= 0) return pid;
    // Its first SSS_STATUS: the loop runs, every subscription is in place.
    if (!waitFor([&] { return seen.status_messages[pid] > 0; }, 10.0)) {
      ::kill(pid, SIGKILL);
      ::waitpid(pid, nullptr, 0);
      return pid_t{-1};
    }
    return pid;
  };

  ChildGuard child;
  child.pid = startOptimiser();
  ASSERT_GT(child.pid, 0) << "sss-optimiser did not start or publish SSS_STATUS";
  const pid_t first_pid = child.pid;

  // ---- 1. DR only: one SSS_POSE per nav sample, equal to the DR pose ----------------------------------
  // Before any subframe (empty graph), then after all twelve subframes are in the graph.
  std::vector<int64_t> dr_phase;
  for (int k = 0; k < 3; ++k) dr_phase.push_back(kT0 + 2'000'000 + k * 7'000'000 + 1);
  ASSERT_TRUE(sendNavAndWait(dr_phase));
  for (int line = 0; line < 2; ++line) {
    for (int j = 0; j < kSubframesPerLine; ++j) {
      bus.publish("SSS_SUBFRAME", sss::messages::toSubframeMessage(makeSubframe(line, j), 16, 16.0));
      pumpFor(0.01);
    }
  }
  auto hasAllIds = [&](const std::vector<int64_t>& ids, int64_t count) {
    std::set<int64_t> s(ids.begin(), ids.end());
    for (int64_t id = 0; id < count; ++id)
      if (!s.count(id)) return false;
    return true;
  };
  ASSERT_TRUE(waitFor([&] { return !seen.trajectory_ids.empty() && hasAllIds(seen.trajectory_ids.back(), 12); }, 10.0))
      << "no SSS_TRAJECTORY with the 12 subframes";
  std::vector<int64_t> dr_phase_2;
  for (int k = 0; k < 10; ++k) dr_phase_2.push_back(kT0 + 1'000'000 + k * 5'500'000 + 2);          // line A
  for (int k = 0; k < 10; ++k) dr_phase_2.push_back(kLineBStartUs + 1'000'000 + k * 5'500'000 + 2);  // line B
  ASSERT_TRUE(sendNavAndWait(dr_phase_2));
  dr_phase.insert(dr_phase.end(), dr_phase_2.begin(), dr_phase_2.end());
  for (int64_t t : dr_phase) {
    const sss_msgs::pose_t& p = seen.poses.at(t);
    EXPECT_EQ(p.status, sss_msgs::pose_t::STATUS_DR_ONLY) << t;
    EXPECT_LT((positionOf(p) - stateAt(t).dr.translation).norm(), 1e-6) << t;
    const double dr_heading = sss::core::eulerFromQuaternion(stateAt(t).dr.rotation).heading_rad;
    EXPECT_NEAR(sss::core::wrapAngle(p.heading_rad - dr_heading), 0.0, 1e-9) << t;
  }

  // ---- 2. closures (true relative poses) -> corrected poses and trajectory ------------------------------
  for (int j = 0; j < kSubframesPerLine; ++j) {
    bus.publish("SSS_LOOP", sss::messages::toLoopClosureMessage(makeClosure(j), sss::core::nowUtime()));
    pumpFor(0.005);
  }
  // An update with the closures: line B's nodes move onto the truth.
  auto lineBCorrected = [&](const std::map<int64_t, Eigen::Vector3d>& nodes) {
    for (int j = 0; j < kSubframesPerLine; ++j) {
      const auto n = nodes.find(subframeId(1, j));
      if (n == nodes.end() || std::abs(n->second.y() - kLineBEastM) > 0.5) return false;
    }
    return true;
  };
  ASSERT_TRUE(waitFor([&] { return !seen.trajectories.empty() && lineBCorrected(seen.trajectories.back()); }, 10.0))
      << "no SSS_TRAJECTORY with line B corrected";
  EXPECT_TRUE(hasAllIds(seen.trajectory_ids.back(), 12));
  double worst_node_error = 0.0;
  for (const auto& [id, position] : seen.trajectories.back()) {
    const int line = id < kSubframesPerLine ? 0 : 1;
    const Eigen::Vector3d truth = stateAt(centreUtime(line, static_cast<int>(id % kSubframesPerLine))).truth.translation;
    worst_node_error = std::max(worst_node_error, (position - truth).norm());
  }
  std::printf("[optimiser_node_test] trajectory after closures: worst node error %.3f m (DR: %.3f m)\n",
              worst_node_error, kDrErrorM);
  EXPECT_LT(worst_node_error, kCorrectedToleranceM);

  std::vector<int64_t> corrected_phase;
  for (int k = 0; k < 12; ++k) corrected_phase.push_back(kLineBStartUs + 6'000'000 + k * 4'000'000 + 3);
  ASSERT_TRUE(sendNavAndWait(corrected_phase));
  double worst_corrected_error = 0.0;
  for (int64_t t : corrected_phase) {
    const sss_msgs::pose_t& p = seen.poses.at(t);
    const State s = stateAt(t);
    EXPECT_EQ(p.status, sss_msgs::pose_t::STATUS_CORRECTED) << t;
    const double dr_error = (s.dr.translation - s.truth.translation).norm();
    const double error = (positionOf(p) - s.truth.translation).norm();
    EXPECT_NEAR(dr_error, kDrErrorM, 1e-9);
    EXPECT_LT(error, kCorrectedToleranceM) << "corrected pose at " << t << " is " << error << " m off the truth (DR " << dr_error << ")";
    worst_corrected_error = std::max(worst_corrected_error, error);
    // The correction fields agree with the pose.
    for (int i = 0; i < 3; ++i)
      EXPECT_NEAR(p.correction_translation_m[i], p.position_ned_m[i] - s.dr.translation[i], 1e-9);
    EXPECT_GT(p.correction_utime, 0);
  }
  std::printf("[optimiser_node_test] SSS_POSE on line B after closures: worst error %.3f m (DR error %.3f m)\n",
              worst_corrected_error, kDrErrorM);

  // ---- 3a. DDS: live corrections match the SSS_POSE of the same utime ------------------------------------
  // The writer sends the newest correction at 10 Hz: the last corrected sample must arrive.
  ASSERT_TRUE(waitFor([&] {
    for (const auto& d : seen.dds_samples)
      if (d.utime_us == corrected_phase.back()) return true;
    return false;
  }, 5.0)) << "no DDS correction for the newest nav sample";
  int dds_corrected = 0, dds_dr_only = 0;
  auto checkDds = [&](const sss_dds_NavigationCorrection& d) {
    const auto found = seen.poses.find(d.utime_us);
    ASSERT_NE(found, seen.poses.end()) << "DDS correction for an unknown utime " << d.utime_us;
    const sss_msgs::pose_t& p = found->second;
    const State s = stateAt(d.utime_us);
    EXPECT_EQ(d.vehicle_id, 7u);
    const sss::core::GeodeticPosition geodetic = plane.toGeodetic(positionOf(p));
    EXPECT_NEAR(d.latitude_deg, geodetic.latitude_deg, 1e-10);
    EXPECT_NEAR(d.longitude_deg, geodetic.longitude_deg, 1e-10);
    EXPECT_NEAR(d.depth_m, p.position_ned_m[2], 1e-9);
    EXPECT_NEAR(d.heading_rad, p.heading_rad, 1e-12);
    EXPECT_NEAR(d.correction_north_m, p.position_ned_m[0] - s.dr.translation.x(), 1e-9);
    EXPECT_NEAR(d.correction_east_m, p.position_ned_m[1] - s.dr.translation.y(), 1e-9);
    EXPECT_NEAR(d.correction_down_m, p.position_ned_m[2] - s.dr.translation.z(), 1e-9);
    EXPECT_EQ(d.correction_utime_us, p.correction_utime);
    if (p.status == sss_msgs::pose_t::STATUS_CORRECTED) {
      EXPECT_EQ(d.status, sss_dds_CORRECTED);
      EXPECT_EQ(d.num_loop_closures, 6u);
      EXPECT_GT(d.quality, 0.0f);
      // Through the geodetic numbers too: the corrected position is near the truth.
      const Eigen::Vector3d ned = plane.toNed({d.latitude_deg, d.longitude_deg, d.depth_m});
      EXPECT_LT((ned - s.truth.translation).head<2>().norm(), kCorrectedToleranceM);
      EXPECT_NEAR(d.correction_east_m, -kDrErrorM, kCorrectedToleranceM);
      ++dds_corrected;
    } else {
      EXPECT_EQ(p.status, sss_msgs::pose_t::STATUS_DR_ONLY);
      EXPECT_EQ(d.status, sss_dds_DR_ONLY);
      EXPECT_EQ(d.quality, 0.0f);
      ++dds_dr_only;
    }
  };
  for (const auto& d : seen.dds_samples) checkDds(d);
  std::printf("[optimiser_node_test] DDS corrections received live: %d DR_ONLY, %d CORRECTED\n", dds_dr_only,
              dds_corrected);
  EXPECT_GE(dds_corrected, 1);

  // ---- 5. bad input: counted, not fatal -----------------------------------------------------------------
  {
    sss_msgs::loop_closure_t nan_translation = sss::messages::toLoopClosureMessage(makeClosure(2), sss::core::nowUtime());
    nan_translation.translation_ab_m[1] = std::nan("");
    bus.publish("SSS_LOOP", nan_translation);
    sss_msgs::loop_closure_t zero_quaternion = sss::messages::toLoopClosureMessage(makeClosure(3), sss::core::nowUtime());
    for (double& v : zero_quaternion.rotation_ab_wxyz) v = 0.0;
    bus.publish("SSS_LOOP", zero_quaternion);
    // Decodes, but its covariance is not positive definite: the graph refuses it.
    sss::core::LoopClosure singular = makeClosure(4);
    singular.covariance.setZero();
    bus.publish("SSS_LOOP", sss::messages::toLoopClosureMessage(singular, sss::core::nowUtime()));
    // A subframe whose image is shorter than its size says, and one whose centre pose is not finite
    // (decodes, refused by the graph).
    sss_msgs::subframe_t short_image = sss::messages::toSubframeMessage(makeSubframe(1, 0), 16, 16.0);
    short_image.subframe_id = 100;
    short_image.num_image_bytes -= 2;
    short_image.image.resize(static_cast<size_t>(short_image.num_image_bytes));
    bus.publish("SSS_SUBFRAME", short_image);
    sss::core::Subframe nan_centre = makeSubframe(1, kSubframesPerLine);
    nan_centre.id = 101;
    nan_centre.pings[kCentre].T_world_body.translation.x() = std::nan("");
    bus.publish("SSS_SUBFRAME", sss::messages::toSubframeMessage(nan_centre, 16, 16.0));
    sss_msgs::nav_t nan_nav = makeNav(kLineBStartUs + 30'000'000 + 5, plane);
    nan_nav.position_ned_m[0] = std::nan("");
    bus.publish("SSS_NAV", nan_nav);
    sss_msgs::nav_t nan_heading = makeNav(kLineBStartUs + 31'000'000 + 5, plane);
    nan_heading.heading_rad = std::numeric_limits<double>::infinity();
    bus.publish("SSS_NAV", nan_heading);
    ASSERT_TRUE(waitFor([&] {
      return counterOf(first_pid, "error.bad_loop_closure") >= 2.0 && counterOf(first_pid, "error.bad_nav") >= 2.0 &&
             counterOf(first_pid, "closures_refused") >= 1.0 && counterOf(first_pid, "error.bad_subframe") >= 1.0 &&
             counterOf(first_pid, "subframes_refused") >= 1.0;
    }, 5.0)) << "bad input not counted: error.bad_loop_closure " << counterOf(first_pid, "error.bad_loop_closure")
             << ", error.bad_nav " << counterOf(first_pid, "error.bad_nav") << ", closures_refused "
             << counterOf(first_pid, "closures_refused") << ", error.bad_subframe "
             << counterOf(first_pid, "error.bad_subframe") << ", subframes_refused "
             << counterOf(first_pid, "subframes_refused");
    EXPECT_EQ(counterOf(first_pid, "error.bad_loop_closure"), 2.0);
    EXPECT_EQ(counterOf(first_pid, "error.bad_nav"), 2.0);
    EXPECT_EQ(counterOf(first_pid, "closures_refused"), 1.0);
    EXPECT_EQ(counterOf(first_pid, "closures_accepted"), 6.0);
    EXPECT_EQ(counterOf(first_pid, "error.bad_subframe"), 1.0);
    EXPECT_EQ(counterOf(first_pid, "subframes_refused"), 1.0);
    EXPECT_EQ(counterOf(first_pid, "nodes"), 12.0);
    EXPECT_EQ(seen.pose_count.count(nan_nav.utime), 0u) << "a pose for a nav sample with a NaN position";
    EXPECT_EQ(seen.pose_count.count(nan_heading.utime), 0u) << "a pose for a nav sample with an infinite heading";
    EXPECT_EQ(::waitpid(first_pid, nullptr, WNOHANG), 0) << "sss-optimiser died on bad input";
  }

  // ---- 6. latency: 500 nav samples at 50 Hz, publish -> SSS_POSE -----------------------------------------
  std::map<int64_t, int64_t> sent_at_us;
  std::vector<int64_t> latency_phase;
  {
    const int64_t start = sss::core::monotonicUtime() + 20'000;
    for (int k = 0; k < 500; ++k) {
      const int64_t due = start + k * 20'000;
      for (int64_t now = sss::core::monotonicUtime(); now < due; now = sss::core::monotonicUtime()) {
        bus.handleTimeout(static_cast<int>((due - now) / 1000));
      }
      const int64_t utime = kLineBStartUs + 6'000'000 + k * 20'000 + 4;
      const sss_msgs::nav_t nav = makeNav(utime, plane);
      sent_at_us[utime] = sss::core::monotonicUtime();
      bus.publish("SSS_NAV", nav);
      nav_sent.insert(utime);
      latency_phase.push_back(utime);
      sss_dds_NavigationCorrection sample{};
      while (reader.take(sample)) seen.dds_samples.push_back(sample);
    }
    waitFor([&] { return seen.pose_count.count(latency_phase.back()) > 0; }, 2.0);
    pumpFor(0.3);
  }
  std::vector<double> latencies_ms;
  int missing = 0;
  for (int64_t t : latency_phase) {
    const auto arrival = seen.pose_arrival_us.find(t);
    if (arrival == seen.pose_arrival_us.end()) {
      ++missing;
      continue;
    }
    latencies_ms.push_back(1e-3 * static_cast<double>(arrival->second - sent_at_us[t]));
    EXPECT_EQ(seen.poses.at(t).status, sss_msgs::pose_t::STATUS_CORRECTED);
  }
  const double p50 = percentileMs(latencies_ms, 50.0);
  const double p99 = percentileMs(latencies_ms, 99.0);
  const double max_ms = latencies_ms.empty() ? NAN : *std::max_element(latencies_ms.begin(), latencies_ms.end());
  std::printf("[optimiser_node_test] LATENCY nav publish -> SSS_POSE receive over %zu samples at 50 Hz: "
              "p50 %.3f ms, p99 %.3f ms, max %.3f ms (%d missing)\n",
              latencies_ms.size(), p50, p99, max_ms, missing);
  std::fflush(stdout);
  EXPECT_EQ(missing, 0);
  EXPECT_LT(p99, 200.0);

  // ---- 3b. a late DDS reader gets the newest correction at once (transient-local) ------------------------
  ASSERT_TRUE(waitFor([&] {
    for (const auto& d : seen.dds_samples)
      if (d.utime_us == latency_phase.back()) return true;
    return false;
  }, 5.0)) << "the newest correction was not published on DDS";
  dds_corrected = dds_dr_only = 0;
  for (const auto& d : seen.dds_samples) checkDds(d);
  std::printf("[optimiser_node_test] DDS corrections received live in all: %d DR_ONLY, %d CORRECTED, each matching "
              "its SSS_POSE\n", dds_dr_only, dds_corrected);
  EXPECT_GE(dds_corrected, 40) << "10 Hz DDS over the 10 s of 50 Hz nav";
  {
    const int64_t joined = sss::core::monotonicUtime();
    // Another participant in this process's (loopback-configured) domain.
    dds::Participant late_participant(domain);
    ASSERT_TRUE(late_participant.good()) << late_participant.error();
    dds::Topic<sss_dds_NavigationCorrection> late_topic(late_participant, &sss_dds_NavigationCorrection_desc, topic_name);
    dds::Reader<sss_dds_NavigationCorrection> late_reader(late_participant, late_topic);
    ASSERT_TRUE(late_reader.good()) << late_reader.error();
    sss_dds_NavigationCorrection newest{};
    const bool got = late_reader.waitAndTake(newest, 2.0);
    const double after_s = 1e-6 * static_cast<double>(sss::core::monotonicUtime() - joined);
    std::printf("[optimiser_node_test] late DDS reader: %s after %.3f s\n", got ? "got the newest correction" : "nothing",
                after_s);
    ASSERT_TRUE(got) << "a late reader got no correction within 2 s";
    EXPECT_EQ(newest.utime_us, latency_phase.back());
    EXPECT_EQ(newest.status, sss_dds_CORRECTED);
    checkDds(newest);
    sss_dds_NavigationCorrection extra{};
    EXPECT_FALSE(late_reader.take(extra)) << "keep-last 1: only the newest";
  }

  // ---- 1 (all). exactly one SSS_POSE per valid nav sample so far -----------------------------------------
  pumpFor(0.2);
  for (int64_t t : nav_sent) EXPECT_EQ(seen.pose_count[t], 1) << "nav utime " << t;
  for (const auto& [t, n] : seen.pose_count) EXPECT_TRUE(nav_sent.count(t)) << "SSS_POSE for a utime never sent: " << t;

  // ---- 4. SIGKILL, restart from the checkpoint ------------------------------------------------------------
  ASSERT_TRUE(fs::exists(state_dir + "/optimiser.checkpoint"));
  ::kill(child.pid, SIGKILL);
  EXPECT_EQ(waitExitWithin(child.pid, 5.0), -1);
  child.pid = -1;
  const int64_t restart_begin = sss::core::monotonicUtime();
  child.pid = startOptimiser();
  ASSERT_GT(child.pid, 0) << "sss-optimiser did not restart";
  const pid_t second_pid = child.pid;
  std::printf("[optimiser_node_test] restart after SIGKILL: first SSS_STATUS after %.3f s\n",
              1e-6 * static_cast<double>(sss::core::monotonicUtime() - restart_begin));
  // Corrected at once from the restored graph, without the closures being sent again.
  std::vector<int64_t> restored_phase;
  for (int k = 0; k < 5; ++k) restored_phase.push_back(kLineBStartUs + 8'000'000 + k * 9'000'000 + 6);
  ASSERT_TRUE(sendNavAndWait(restored_phase));
  for (int64_t t : restored_phase) {
    const sss_msgs::pose_t& p = seen.poses.at(t);
    EXPECT_EQ(p.status, sss_msgs::pose_t::STATUS_CORRECTED) << t;
    EXPECT_LT((positionOf(p) - stateAt(t).truth.translation).norm(), kCorrectedToleranceM) << t;
  }
  // One more subframe on line B (pings 120..139): an update, after which the counters are published.
  const sss::core::Subframe after_restart = makeSubframe(1, kSubframesPerLine);
  ASSERT_EQ(after_restart.id, 12);
  bus.publish("SSS_SUBFRAME", sss::messages::toSubframeMessage(after_restart, 16, 16.0));
  ASSERT_TRUE(waitFor([&] { return counterOf(second_pid, "nodes") >= 13.0; }, 10.0))
      << "no SSS_STATUS counters after the restart (nodes " << counterOf(second_pid, "nodes") << ")";
  EXPECT_EQ(counterOf(second_pid, "nodes"), 13.0);
  EXPECT_EQ(counterOf(second_pid, "closures_accepted"), 6.0);
  EXPECT_GE(counterOf(second_pid, "updates"), 1.0);
  EXPECT_EQ(counterOf(second_pid, "odometer_resets"), 0.0);
  ASSERT_TRUE(waitFor([&] { return hasAllIds(seen.trajectory_ids.back(), 13); }, 5.0));
  std::vector<int64_t> after_restart_phase;
  for (int k = 0; k < 5; ++k) after_restart_phase.push_back(centreUtime(1, 1) + k * 10'000'000 + 7);
  ASSERT_TRUE(sendNavAndWait(after_restart_phase));
  for (int64_t t : after_restart_phase) {
    EXPECT_EQ(seen.poses.at(t).status, sss_msgs::pose_t::STATUS_CORRECTED) << t;
    EXPECT_LT((positionOf(seen.poses.at(t)) - stateAt(t).truth.translation).norm(), kCorrectedToleranceM) << t;
  }
  pumpFor(0.2);
  for (int64_t t : nav_sent) EXPECT_EQ(seen.pose_count[t], 1) << "nav utime " << t;

  // ---- 4 (end). SIGTERM: exit 0, products of every subframe (the checkpoint holds the ping poses) ----------
  ::kill(child.pid, SIGTERM);
  const int exit_code = waitExitWithin(child.pid, 15.0);
  child.pid = -1;
  EXPECT_EQ(exit_code, 0);
  const std::string tum = state_dir + "/products/slam.tum";
  ASSERT_TRUE(fs::exists(tum)) << tum;
  std::ifstream file(tum);
  std::map<std::string, Eigen::Vector3d> tum_poses;
  for (std::string line; std::getline(file, line);) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream fields(line);
    std::string stamp;
    Eigen::Vector3d t;
    fields >> stamp >> t.x() >> t.y() >> t.z();
    tum_poses[stamp] = t;
  }
  std::printf("[optimiser_node_test] products: %zu poses in slam.tum\n", tum_poses.size());
  EXPECT_EQ(tum_poses.size(), static_cast<size_t>(13 * kPingsPerSubframe));
  std::vector<sss::core::SubframePing> all_pings;
  for (int line = 0; line < 2; ++line)
    for (int j = 0; j < kSubframesPerLine + line; ++j)
      for (const auto& ping : makeSubframe(line, j).pings) all_pings.push_back(ping);
  double worst_tum_error = 0.0;
  for (const auto& ping : all_pings) {
    char stamp[64];
    std::snprintf(stamp, sizeof stamp, "%lld.%06lld", static_cast<long long>(ping.utime_us / 1000000),
                  static_cast<long long>(ping.utime_us % 1000000));
    const auto found = tum_poses.find(stamp);
    ASSERT_NE(found, tum_poses.end()) << "slam.tum lacks ping " << stamp;
    // Corrected (line B's DR carries a 2 m error). Between line A's last centre and line B's first,
    // the correction blends across the 100 s excursion: the half subframes next to it (5 s) get up
    // to kDrErrorM * 5 / 105 = 0.1 m of the other line's correction on top.
    const bool beside_excursion = ping.utime_us > centreUtime(0, kSubframesPerLine - 1) && ping.utime_us < centreUtime(1, 0);
    const double error = (found->second - stateAt(ping.utime_us).truth.translation).norm();
    worst_tum_error = std::max(worst_tum_error, error);
    EXPECT_LT(error, kCorrectedToleranceM + (beside_excursion ? 0.1 : 0.0)) << stamp;
  }
  std::printf("[optimiser_node_test] slam.tum, every ping before and after the restart: worst error %.3f m (DR %.3f m)\n",
              worst_tum_error, kDrErrorM);

  fs::remove_all(dir);
  const double total_s = 1e-6 * static_cast<double>(sss::core::monotonicUtime() - test_start_us);
  std::printf("[optimiser_node_test] total %.1f s\n", total_s);
}

}  // namespace
}  // namespace sss::optimiser
