// sss-bench-latency: nav-in to pose-out latency of sss-optimiser as a process, on LCM and on DDS.
// Starts sss-optimiser on a private LCM udpm port and a private loopback DDS domain, gives it a
// solved graph of synthetic lawnmower subframes and closures, then publishes SSS_NAV at a fixed
// rate and times each SSS_POSE (matched on utime). Two phases: "idle" (the graph is solved and
// quiet) and "loaded" (subframes of realistic size and closures keep arriving, so the worker
// thread solves while nav flows). Prints p50/p95/p99/max per phase and a JSON summary last.
//   sss-bench-latency [--samples 5000] [--rate-hz 200] [--dds-rate-hz 10] [--update-period-s 0.2]
//                     [--no-load] [--realtime] [--optimiser PATH] [--keep]
// --realtime measures the deployed scheduling (systemd/): the optimiser's loop SCHED_FIFO 10 with
// its other threads ordinary (reset on fork), the nav publisher and the DDS reader SCHED_FIFO 20
// as the INS bridge and a navigation computer would run them; the subframe/closure feeder, which
// stands for the matcher, stays ordinary. Needs CAP_SYS_NICE.
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"  // lcm-gen decode() false positive at -O3
#include <nlohmann/json.hpp>

#include <pthread.h>
#include <sched.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <map>
#include <mutex>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "pipeline/transport/command_line.hpp"
#include "navigation_correction.h"
#include "pipeline/core/geodesy.hpp"
#include "pipeline/core/pose.hpp"
#include "pipeline/core/time.hpp"
#include "pipeline/messages/closure_messages.hpp"
#include "tools/fixtures/synthetic_mission.hpp"
#include "pipeline/messages/subframe_messages.hpp"
#include "pipeline/transport/dds.hpp"
#include "pipeline/transport/lcm_bus.hpp"
#include "sss_msgs/nav_t.hpp"
#include "sss_msgs/pose_t.hpp"
#include "sss_msgs/status_t.hpp"
#include "tools/fixtures/nav_message.hpp"
#include "tools/fixtures/optimiser_node_config.hpp"
#include "tools/fixtures/poll_until.hpp"
#include "tools/fixtures/spawn_process.hpp"

namespace {

namespace fs = std::filesystem;

// The 1-minute load average: the figures depend on what else runs on the host's cores.
double loadAverage() {
  std::ifstream file("/proc/loadavg");
  double one_minute = std::nan("");
  file >> one_minute;
  return one_minute;
}

namespace dds = sss::transport::dds;
namespace synthetic = sss::optimiser::synthetic;
using sss::core::Pose;

constexpr double kOriginLat = 59.35;
constexpr double kOriginLon = 18.07;
constexpr int kPingsPerSubframe = 200;  // the paper's subframe: 50 s at 4 pings/s, 100 m at 2 m/s
constexpr double kPingPeriodS = 0.25;
constexpr double kSpeedMS = 2.0;

double percentile(std::vector<double> values, double percent) {
  if (values.empty()) return std::nan("");
  std::sort(values.begin(), values.end());
  const size_t rank = static_cast<size_t>(std::ceil(percent / 100.0 * static_cast<double>(values.size())));
  return values[std::min(values.size() - 1, rank == 0 ? 0 : rank - 1)];
}

struct Stats {
  double p50 = std::nan(""), p95 = std::nan(""), p99 = std::nan(""), max = std::nan("");
  size_t count = 0;
};

Stats statsOf(const std::vector<double>& values) {
  Stats s;
  s.count = values.size();
  if (values.empty()) return s;
  s.p50 = percentile(values, 50.0);
  s.p95 = percentile(values, 95.0);
  s.p99 = percentile(values, 99.0);
  s.max = *std::max_element(values.begin(), values.end());
  return s;
}

void printStats(const char* what, const Stats& s) {
  std::printf("  %-58s n %5zu  p50 %7.3f  p95 %7.3f  p99 %7.3f  max %7.3f ms\n", what, s.count, s.p50, s.p95, s.p99,
              s.max);
}

// A 200-ping subframe around a synthetic node: straight along the node's DR heading, 0.5 m per ping.
// The image is blank but of the size the subframe buffer publishes (the optimiser decodes it all).
sss::core::Subframe subframeAround(const synthetic::Node& node, int bins_per_side) {
  sss::core::Subframe sf;
  sf.id = node.subframe_id;
  sf.line_id = node.line;
  sf.centre_ping_index = kPingsPerSubframe / 2;
  sf.geometry.bins_per_side = bins_per_side;
  sf.geometry.bin_size_m = 0.06;
  sf.geometry.first_bin_range_m = 0.0;
  const Eigen::Vector3d forward = node.dr.rotation * Eigen::Vector3d::UnitX();
  for (int r = 0; r < kPingsPerSubframe; ++r) {
    const int offset = r - sf.centre_ping_index;
    sss::core::SubframePing ping;
    ping.utime_us = node.utime_us + static_cast<int64_t>(std::llround(offset * kPingPeriodS * 1e6));
    ping.ping_number = node.subframe_id * kPingsPerSubframe + r;
    const double along_m = offset * kPingPeriodS * kSpeedMS;
    ping.T_world_body = Pose(node.dr.rotation, node.dr.translation + along_m * forward);
    ping.altitude_m = 18.0;
    ping.distance_travelled_m = node.distance_m + along_m;
    sf.pings.push_back(ping);
  }
  sf.image.assign(static_cast<size_t>(sf.rows() * sf.cols()), 1.0f);
  sf.mask.assign(static_cast<size_t>(sf.rows() * sf.cols()), 0);
  return sf;
}

sss::core::LoopClosure matcherClosure(const synthetic::Closure& c, const std::map<int64_t, int64_t>& centre_utime) {
  sss::core::LoopClosure m;
  m.subframe_id_a = c.closure.subframe_id_a;
  m.subframe_id_b = c.closure.subframe_id_b;
  m.centre_utime_a_us = centre_utime.at(m.subframe_id_a);
  m.centre_utime_b_us = centre_utime.at(m.subframe_id_b);
  m.T_a_b = c.closure.T_a_b;
  m.covariance = c.closure.covariance;
  m.association_round = c.closure.association_round;
  m.num_matches = 1000;
  m.num_inliers = 300;
  m.total_cost = 1.0;
  m.mean_zncc = 0.8f;
  return m;
}

sss_msgs::nav_t makeNav(int64_t utime_us, const Pose& dr, double distance_m, const sss::core::LocalTangentPlane& plane) {
  return sss::test::makeNavMessage(utime_us, dr, distance_m, 18.0, kSpeedMS, plane);
}

// DDS samples as the navigation computer sees them, taken on their own thread as soon as they
// arrive (waitset), with the writer's source timestamp and the receive time on the same clocks.
struct DdsArrival {
  int64_t utime_us = 0;          // the nav sample the correction is for
  int status = 0;
  int64_t receive_monotonic_us = 0;
  int64_t write_to_read_ns = 0;  // dds_time() at take - source_timestamp (both CLOCK_REALTIME)
};

class DdsListener {
 public:
  DdsListener(uint32_t domain, const std::string& topic_name)
      : participant_(domain, dds::loopbackConfigXml()),
        topic_(participant_, &sss_dds_NavigationCorrection_desc, topic_name) {
    if (!participant_.good() || !topic_.good()) return;
    dds::QosSettings settings;
    settings.history_depth = 256;  // keep every sample between two takes
    reader_ = dds::Entity(dds_create_reader(participant_.handle(), topic_.handle(), dds::Qos(settings).get(), nullptr));
  }
  ~DdsListener() { stop(); }
  bool good() const { return reader_.good(); }
  std::string error() const {
    return !participant_.good() ? participant_.error() : !topic_.good() ? topic_.error() : reader_.error();
  }
  int matchedWriters() const {
    dds_subscription_matched_status_t status{};
    if (dds_get_subscription_matched_status(reader_.handle(), &status) != DDS_RETCODE_OK) return 0;
    return static_cast<int>(status.current_count);
  }
  void start() {
    thread_ = std::thread([this] { run(); });
  }
  void stop() {
    running_ = false;
    if (thread_.joinable()) thread_.join();
  }
  std::vector<DdsArrival> arrivals() {
    std::lock_guard<std::mutex> lock(mutex_);
    return arrivals_;
  }

 private:
  void run() {
    const dds_entity_t waitset = dds_create_waitset(participant_.handle());
    const dds_entity_t condition = dds_create_readcondition(reader_.handle(), DDS_ANY_STATE);
    dds_waitset_attach(waitset, condition, 0);
    constexpr size_t kMax = 64;
    void* samples[kMax] = {nullptr};
    dds_sample_info_t infos[kMax];
    while (running_) {
      dds_waitset_wait(waitset, nullptr, 0, DDS_MSECS(50));
      const dds_return_t n = dds_take(reader_.handle(), samples, infos, kMax, kMax);
      if (n <= 0) continue;
      const dds_time_t now_ns = dds_time();
      const int64_t now_monotonic_us = sss::core::monotonicUtime();
      {
        std::lock_guard<std::mutex> lock(mutex_);
        for (dds_return_t i = 0; i < n; ++i) {
          if (!infos[i].valid_data) continue;
          const auto* sample = static_cast<const sss_dds_NavigationCorrection*>(samples[i]);
          arrivals_.push_back({sample->utime_us, static_cast<int>(sample->status), now_monotonic_us,
                               now_ns - infos[i].source_timestamp});
        }
      }
      dds_return_loan(reader_.handle(), samples, n);
    }
    dds_delete(condition);
    dds_delete(waitset);
  }

  dds::Participant participant_;
  dds::Topic<sss_dds_NavigationCorrection> topic_;
  dds::Entity reader_;
  std::thread thread_;
  std::atomic<bool> running_{true};
  std::mutex mutex_;
  std::vector<DdsArrival> arrivals_;
};

struct PhaseResult {
  Stats lcm_ms;
  Stats dds_nav_ms;    // nav publish -> DDS sample carrying that nav's utime received
  Stats dds_write_ms;  // DDS write (source timestamp) -> read
  int missing_poses = 0;
  int corrected_poses = 0;
  size_t dds_samples = 0;
  double updates = 0.0;              // graph updates during the phase (SSS_STATUS)
  double max_last_update_ms = 0.0;   // longest update reported during the phase
  int subframes_sent = 0;
  int closures_sent = 0;
};

}  // namespace

int main(int argc, char** argv) {
  int samples = 5000;
  double rate_hz = 200.0, dds_rate_hz = 10.0, update_period_s = 0.2;
  int bins_per_side = 1250;
  bool load = true, keep = false, realtime = false;
  std::string optimiser_path = SSS_OPTIMISER_PATH;
  sss::cli::CommandLine command_line(
      "sss-bench-latency",
      "runs sss-optimiser on a private LCM port and loopback DDS domain, publishes N SSS_NAV at HZ and times SSS_POSE "
      "and the DDS correction; first with a solved, quiet graph, then (unless --no-load) while subframes and "
      "closures arrive and the graph is solved every S s. Last line: JSON summary.",
      "--realtime: the deployed scheduling (optimiser loop SCHED_FIFO 10, nav publisher and DDS reader SCHED_FIFO 20;\n"
      "needs CAP_SYS_NICE).");
  command_line.add_option("--samples", samples, "nav samples N")->check(CLI::Range(10, 100000000))->capture_default_str();
  command_line.add_option("--rate-hz", rate_hz, "nav rate HZ")->check(CLI::Range(1e-3, 5000.0))->capture_default_str();
  command_line.add_option("--dds-rate-hz", dds_rate_hz, "DDS correction rate")
      ->check(CLI::Range(1e-3, 1000.0))
      ->capture_default_str();
  command_line.add_option("--update-period-s", update_period_s, "graph update period S")
      ->check(sss::cli::nonNegative())
      ->capture_default_str();
  command_line.add_option("--bins-per-side", bins_per_side, "subframe bins per side")->check(sss::cli::positive())
      ->capture_default_str();
  bool no_load = false;
  command_line.add_flag("--no-load", no_load, "only the quiet graph");
  command_line.add_flag("--realtime", realtime, "the deployed scheduling");
  command_line.add_option("--optimiser", optimiser_path, "the sss-optimiser to run")->capture_default_str();
  command_line.add_flag("--keep", keep, "keep the private state directory");
  if (const int code = sss::cli::parseCommandLine(command_line, argc, argv); code >= 0) return code;
  load = !no_load;

  // The publisher thread first, before any thread is started, so the DDS reader's threads (ours and
  // Cyclone's) inherit it.
  if (realtime) {
    sched_param priority{};
    priority.sched_priority = 20;
    if (sched_setscheduler(0, SCHED_FIFO, &priority) != 0) {
      std::fprintf(stderr, "sss-bench-latency: --realtime: SCHED_FIFO refused (%s); run as root or with CAP_SYS_NICE\n",
                   std::strerror(errno));
      return 2;
    }
  }

  // ---- private bus, domain and state directory ------------------------------------------------------
  std::random_device random;
  const pid_t self = getpid();
  const int lcm_port = 40000 + static_cast<int>(random() % 20000);
  const std::string lcm_url = "udpm://239.255.76.67:" + std::to_string(lcm_port) + "?ttl=0&recv_buf_size=16777216";
  const uint32_t domain = 10 + static_cast<uint32_t>(random() % 80);  // the tests use 100..231
  const std::string topic_name = "sss_navigation_correction_bench_" + std::to_string(self);
  const std::string dir = "/tmp/sss-bench-latency-" + std::to_string(self);
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string config = dir + "/optimiser.yaml";
  sss::test::OptimiserNodeConfig node_config;
  node_config.origin_latitude_deg = kOriginLat;
  node_config.origin_longitude_deg = kOriginLon;
  node_config.lcm_url = lcm_url;
  node_config.log_level = "warn";
  node_config.update_period_s = update_period_s;
  node_config.state_directory = dir + "/state";
  node_config.dds_domain_id = domain;
  node_config.dds_topic = topic_name;
  node_config.dds_rate_hz = dds_rate_hz;
  if (!sss::test::writeOptimiserNodeConfig(config, node_config)) {
    std::fprintf(stderr, "sss-bench-latency: cannot write %s\n", config.c_str());
    return 1;
  }
  std::printf("sss-bench-latency: %s, LCM %s, DDS domain %u (loopback), state %s\n", optimiser_path.c_str(),
              lcm_url.c_str(), domain, dir.c_str());

  // ---- the mission: 16 lines of 1 km, a node per 100 m subframe, closures between adjacent lines ------
  synthetic::MissionOptions mission_options;
  mission_options.num_lines = 16;
  mission_options.line_length_m = 1000.0;
  mission_options.heading_bias_rad = 0.001;
  const synthetic::Mission mission = synthetic::makeLawnmowerMission(mission_options);
  std::map<int64_t, int64_t> centre_utime;
  for (const auto& n : mission.nodes) centre_utime[n.subframe_id] = n.utime_us;
  const size_t preload_nodes = std::min<size_t>(40, mission.nodes.size());  // 4 lines solved before the idle phase
  const sss::core::LocalTangentPlane plane(kOriginLat, kOriginLon);

  // ---- our side: LCM, DDS reader (the navigation computer) --------------------------------------------
  sss::core::HealthMonitor health(sss::core::monotonicUtime());
  sss::transport::LcmBus bus(lcm_url, health);
  if (!bus.good()) {
    std::fprintf(stderr, "sss-bench-latency: cannot open LCM %s\n", lcm_url.c_str());
    return 1;
  }
  std::map<int64_t, int64_t> pose_arrival_us;  // utime -> monotonic
  std::map<int64_t, int> pose_status;
  bus.subscribe<sss_msgs::pose_t>("SSS_POSE", [&](const sss_msgs::pose_t& m) {
    pose_arrival_us.emplace(m.utime, sss::core::monotonicUtime());
    pose_status[m.utime] = m.status;
  });
  pid_t child = -1;
  std::map<std::string, double> counters;
  int status_messages = 0;
  bus.subscribe<sss_msgs::status_t>("SSS_STATUS", [&](const sss_msgs::status_t& m) {
    if (m.process != "sss-optimiser" || m.pid != child) return;
    ++status_messages;
    for (int i = 0; i < m.num_counters; ++i) counters[m.counter_name[i]] = m.counter_value[i];
  });
  DdsListener listener(domain, topic_name);
  if (!listener.good()) {
    std::fprintf(stderr, "sss-bench-latency: DDS reader: %s\n", listener.error().c_str());
    return 1;
  }
  listener.start();

  auto pumpFor = [&](double seconds) {
    const int64_t until = sss::core::monotonicUtime() + static_cast<int64_t>(seconds * 1e6);
    for (int64_t now = sss::core::monotonicUtime(); now < until; now = sss::core::monotonicUtime())
      bus.handleTimeout(static_cast<int>(std::max<int64_t>(1, (until - now) / 1000)));
  };
  auto waitFor = [&](const std::function<bool()>& done, double timeout_s) {
    return sss::test::pollUntil([&] { pumpFor(0.01); }, done, timeout_s);
  };
  auto counter = [&](const std::string& name) {
    const auto c = counters.find(name);
    return c == counters.end() ? -1.0 : c->second;
  };
  auto cleanup = [&](int code) {
    listener.stop();
    if (child > 0) {
      ::kill(child, SIGKILL);
      ::waitpid(child, nullptr, 0);
    }
    if (!keep) fs::remove_all(dir);
    return code;
  };

  // As systemd starts it (sss-optimiser.service): the loop SCHED_FIFO 10, every thread it starts
  // (solver, Cyclone's) ordinary.
  child = realtime ? sss::test::spawnProcess({"/usr/bin/chrt", "--fifo", "--reset-on-fork", "10", optimiser_path,
                                              "--config", config})
                   : sss::test::spawnProcess({optimiser_path, "--config", config});
  if (child <= 0 || !waitFor([&] { return status_messages > 0; }, 15.0)) {
    std::fprintf(stderr, "sss-bench-latency: %s did not start (no SSS_STATUS)\n", optimiser_path.c_str());
    return cleanup(1);
  }
  if (!waitFor([&] { return listener.matchedWriters() > 0; }, 15.0)) {
    std::fprintf(stderr, "sss-bench-latency: the optimiser's DDS writer was not discovered\n");
    return cleanup(1);
  }

  // ---- the feeder: subframes and closures from their own LCM instance and thread (the subframe buffer
  // and the matcher are other processes), so building and sending 1.5 MB messages never delays the
  // timing of the poses on this thread -------------------------------------------------------------------
  sss::core::HealthMonitor feed_health(sss::core::monotonicUtime());
  sss::transport::LcmBus feed_bus(lcm_url, feed_health);
  std::atomic<size_t> next_node{0};  // nodes sent
  size_t next_closure = 0;
  std::atomic<int> subframes_sent{0}, closures_sent{0};
  auto sendNode = [&]() {
    const size_t index = next_node.load();
    const synthetic::Node& node = mission.nodes[index];
    feed_bus.publish("SSS_SUBFRAME", sss::messages::toSubframeMessage(subframeAround(node, bins_per_side), 16, 16.0));
    ++subframes_sent;
    while (next_closure < mission.closures.size() &&
           mission.closures[next_closure].newer_node == static_cast<int>(index)) {
      feed_bus.publish("SSS_LOOP", sss::messages::toLoopClosureMessage(
                                       matcherClosure(mission.closures[next_closure++], centre_utime), sss::core::nowUtime()));
      ++closures_sent;
    }
    next_node = index + 1;
  };

  // ---- preload: the first lines and their closures, solved ------------------------------------------------
  while (next_node < preload_nodes) {
    sendNode();
    pumpFor(0.05);
  }
  if (!waitFor([&] { return counter("nodes") >= static_cast<double>(preload_nodes) && counter("updates") >= 1.0; },
               30.0)) {
    std::fprintf(stderr, "sss-bench-latency: the optimiser did not take the %zu preload subframes (nodes %.0f)\n",
                 preload_nodes, counter("nodes"));
    return cleanup(1);
  }
  pumpFor(2.0 * update_period_s + 0.5);
  std::printf("preload: %zu subframes of %d pings x %d columns, %d closures; graph %.0f nodes, %.0f closures accepted\n",
              preload_nodes, kPingsPerSubframe, 2 * bins_per_side, closures_sent.load(), counter("nodes"),
              counter("closures_accepted"));

  // ---- one phase: N nav samples at rate_hz, optionally with subframes arriving -----------------------------
  const int64_t period_us = static_cast<int64_t>(std::llround(1e6 / rate_hz));
  const int64_t subframe_half_us = static_cast<int64_t>(kPingsPerSubframe / 2 * kPingPeriodS * 1e6);
  int64_t nav_utime = 0;
  auto runPhase = [&](bool with_load) {
    PhaseResult result;
    const double updates_before = counter("updates");
    double max_update_ms = 0.0;
    std::map<int64_t, int64_t> sent_at_us;
    const int64_t start = sss::core::monotonicUtime() + 20'000;
    const int64_t duration_us = samples * period_us;
    const int sub_before = subframes_sent, clo_before = closures_sent;
    // Subframes spread evenly over the phase.
    std::thread feeder;
    if (with_load) {
      feeder = std::thread([&] {
        if (realtime) {  // the matcher's stand-in: ordinary scheduling
          sched_param ordinary{};
          pthread_setschedparam(pthread_self(), SCHED_OTHER, &ordinary);
        }
        const size_t first = next_node, count = mission.nodes.size() - first;
        for (size_t i = 0; i < count; ++i) {
          const int64_t due = start + static_cast<int64_t>(i) * duration_us / static_cast<int64_t>(count);
          const int64_t now = sss::core::monotonicUtime();
          if (due > now) std::this_thread::sleep_for(std::chrono::microseconds(due - now));
          sendNode();
        }
      });
    }
    for (int k = 0; k < samples; ++k) {
      const int64_t due = start + k * period_us;
      for (int64_t now = sss::core::monotonicUtime(); now < due; now = sss::core::monotonicUtime()) {
        bus.handleTimeout(static_cast<int>((due - now) / 1000));
        if (counter("updates") > updates_before) max_update_ms = std::max(max_update_ms, counter("last_update_ms"));
      }
      // Nav time runs on from the newest subframe's last ping (a subframe is older than the nav).
      const synthetic::Node& newest = mission.nodes[next_node.load() - 1];
      nav_utime = std::max(nav_utime + period_us, newest.utime_us + subframe_half_us + 1);
      const sss_msgs::nav_t nav = makeNav(nav_utime, newest.dr, newest.distance_m, plane);
      sent_at_us[nav_utime] = sss::core::monotonicUtime();
      bus.publish("SSS_NAV", nav);
    }
    if (feeder.joinable()) feeder.join();
    const int64_t last = std::prev(sent_at_us.end())->first;
    waitFor([&] { return pose_arrival_us.count(last) > 0; }, 2.0);
    pumpFor(0.5);  // the last DDS write
    if (counter("updates") > updates_before) max_update_ms = std::max(max_update_ms, counter("last_update_ms"));
    std::vector<double> lcm_ms;
    for (const auto& [utime, sent] : sent_at_us) {
      const auto arrival = pose_arrival_us.find(utime);
      if (arrival == pose_arrival_us.end()) {
        ++result.missing_poses;
        continue;
      }
      lcm_ms.push_back(1e-3 * static_cast<double>(arrival->second - sent));
      result.corrected_poses += pose_status[utime] == sss_msgs::pose_t::STATUS_CORRECTED ? 1 : 0;
    }
    std::vector<double> dds_nav_ms, dds_write_ms;
    for (const DdsArrival& a : listener.arrivals()) {
      // The phase's last nav sample may have been held back by the rate limit and left by the
      // timer: an end effect.
      const auto sent = sent_at_us.find(a.utime_us);
      if (sent == sent_at_us.end() || a.utime_us == last) continue;
      dds_nav_ms.push_back(1e-3 * static_cast<double>(a.receive_monotonic_us - sent->second));
      dds_write_ms.push_back(1e-6 * static_cast<double>(a.write_to_read_ns));
    }
    result.lcm_ms = statsOf(lcm_ms);
    result.dds_nav_ms = statsOf(dds_nav_ms);
    result.dds_write_ms = statsOf(dds_write_ms);
    result.dds_samples = dds_nav_ms.size();
    result.updates = counter("updates") - updates_before;
    result.max_last_update_ms = max_update_ms;
    result.subframes_sent = subframes_sent - sub_before;
    result.closures_sent = closures_sent - clo_before;
    return result;
  };
  auto report = [&](const char* name, const PhaseResult& r) {
    std::printf("%s: %d SSS_NAV at %.0f Hz (%d poses CORRECTED, %d missing); %d subframes + %d closures sent, "
                "%.0f graph updates (longest %.1f ms)\n",
                name, samples, rate_hz, r.corrected_poses, r.missing_poses, r.subframes_sent, r.closures_sent,
                r.updates, r.max_last_update_ms);
    printStats("LCM  SSS_NAV publish -> SSS_POSE receive", r.lcm_ms);
    printStats("DDS  SSS_NAV publish -> correction for it received", r.dds_nav_ms);
    printStats("DDS  write (source timestamp) -> read", r.dds_write_ms);
  };

  const double load_before = loadAverage();
  const PhaseResult idle = runPhase(false);
  report("idle", idle);
  std::fflush(stdout);
  PhaseResult loaded;
  if (load) {
    loaded = runPhase(true);
    report("loaded", loaded);
  }
  const double load_after = loadAverage();
  std::printf("scheduling: %s; host load average (1 min, %ld cores): %.2f before, %.2f after\n",
              realtime ? "SCHED_FIFO as deployed (--realtime)" : "normal", sysconf(_SC_NPROCESSORS_ONLN),
              load_before, load_after);
  std::printf("LCM: the time from publishing SSS_NAV to receiving its SSS_POSE (decode, correction, encode, two\n"
              "  udpm hops). DDS: the optimiser writes the corrected pose of a nav sample as it answers it, at most\n"
              "  %.0f Hz (nav at %.0f Hz: one sample in %.0f goes out); 'correction for it' is from publishing the nav\n"
              "  sample a DDS sample carries (utime_us) to its arrival; 'write -> read' is the DDS transport alone\n"
              "  (writer source timestamp vs dds_time() at the reader, same clock).\n",
              dds_rate_hz, rate_hz, rate_hz / dds_rate_hz);

  // ---- stop: SIGTERM, clean exit --------------------------------------------------------------------------
  ::kill(child, SIGTERM);
  int exit_status = 0;
  bool exited = false;
  for (int i = 0; i < 300 && !exited; ++i) {
    exited = ::waitpid(child, &exit_status, WNOHANG) == child;
    if (!exited) std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  if (exited) child = -1;
  const bool clean = exited && WIFEXITED(exit_status) && WEXITSTATUS(exit_status) == 0;
  if (!clean) std::fprintf(stderr, "sss-bench-latency: sss-optimiser did not exit cleanly on SIGTERM\n");
  cleanup(0);

  // The machine-readable last line (nlohmann: a figure that is not finite, or not measured, is null).
  auto num = [](double v) { return std::isfinite(v) ? nlohmann::ordered_json(v) : nlohmann::ordered_json(); };
  nlohmann::ordered_json figures;
  figures["lcm_p50_ms"] = num(idle.lcm_ms.p50);
  figures["lcm_p95_ms"] = num(idle.lcm_ms.p95);
  figures["lcm_p99_ms"] = num(idle.lcm_ms.p99);
  figures["lcm_max_ms"] = num(idle.lcm_ms.max);
  figures["dds_p50_ms"] = num(idle.dds_nav_ms.p50);
  figures["dds_p95_ms"] = num(idle.dds_nav_ms.p95);
  figures["dds_p99_ms"] = num(idle.dds_nav_ms.p99);
  figures["dds_max_ms"] = num(idle.dds_nav_ms.max);
  figures["dds_write_to_read_p50_ms"] = num(idle.dds_write_ms.p50);
  figures["dds_write_to_read_p99_ms"] = num(idle.dds_write_ms.p99);
  figures["loaded_lcm_p50_ms"] = num(load ? loaded.lcm_ms.p50 : NAN);
  figures["loaded_lcm_p99_ms"] = num(load ? loaded.lcm_ms.p99 : NAN);
  figures["loaded_lcm_max_ms"] = num(load ? loaded.lcm_ms.max : NAN);
  figures["loaded_dds_p50_ms"] = num(load ? loaded.dds_nav_ms.p50 : NAN);
  figures["loaded_dds_p99_ms"] = num(load ? loaded.dds_nav_ms.p99 : NAN);
  figures["loaded_dds_write_to_read_p99_ms"] = num(load ? loaded.dds_write_ms.p99 : NAN);
  figures["loaded_updates"] = load ? loaded.updates : 0.0;
  figures["samples"] = samples;
  figures["rate_hz"] = rate_hz;
  figures["dds_rate_hz"] = dds_rate_hz;
  figures["dds_samples"] = idle.dds_samples;
  figures["missing"] = idle.missing_poses + loaded.missing_poses;
  figures["load_average"] = std::max(load_before, load_after);
  figures["scheduling"] = realtime ? "fifo" : "normal";
  std::printf("%s\n", figures.dump().c_str());
  return idle.missing_poses + loaded.missing_poses > 0 || !clean ? 1 : 0;
}
