// Simulated missions for the subframe tests: pings rendered in process (OpenMP), DR or true nav
// as NavInput, true poses per ping; cached per option set so a test binary renders each once.
#pragma once

#include <omp.h>

#include <map>
#include <memory>
#include <vector>

#include "pipeline/subframe/ping_nav_fusion.hpp"
#include "tools/sim/mission.hpp"
#include "tools/sim/simulated_survey.hpp"

namespace sss::subframe::test {

struct TestMission {
  std::unique_ptr<sss::sim::Mission> mission;
  std::vector<PingInput> pings;
  std::vector<NavInput> dr_nav;     // the INS/DVL DR at 20 Hz
  std::vector<NavInput> true_nav;   // ground truth at 20 Hz, true altitude
};

inline std::unique_ptr<TestMission> makeTestMission(const sss::sim::SimOptions& options) {
  auto m = std::make_unique<TestMission>();
  m->mission = std::make_unique<sss::sim::Mission>(options);
  const sss::sim::Mission& mission = *m->mission;
  const size_t count = mission.pingCount();
  m->pings.resize(count);
  const sss::sim::SonarOptions& sonar = mission.sonar().options();
#pragma omp parallel for schedule(dynamic, 8)
  for (long i = 0; i < static_cast<long>(count); ++i) {
    const sss::sim::PingSamples samples = mission.renderPing(static_cast<size_t>(i));
    PingInput& ping = m->pings[i];
    ping.utime_us = mission.pingUtimeUs(static_cast<size_t>(i));
    ping.ping_number = i;
    ping.sound_speed_m_s = sonar.sound_speed_m_s;
    ping.sample_interval_s = sonar.sampleIntervalS();
    ping.start_range_m = 0.0;
    ping.altitude_m = mission.truthAtPing(static_cast<size_t>(i)).altitude_m;
    ping.port = samples.port;
    ping.starboard = samples.starboard;
  }
  const int64_t start = options.start_utime_us;
  for (const sss::sim::NavSample& s : mission.deadReckoning().samples()) {
    m->dr_nav.push_back(sss::sim::navInputFrom(start + static_cast<int64_t>(std::llround(s.time_s * 1e6)), s.T_world_body, s.altitude_m));
  }
  const double dt = 1.0 / options.dead_reckoning.rate_hz;
  for (double t = 0.0; t <= mission.durationS() + 1e-9; t += dt) {
    const sss::sim::TrajectorySample truth = mission.trajectory().sample(t);
    m->true_nav.push_back(sss::sim::navInputFrom(start + static_cast<int64_t>(std::llround(t * 1e6)), truth.T_world_body, truth.altitude_m));
  }
  return m;
}

// Feeds nav and pings in time order (nav up to lead_s past each ping first, as it arrives live).
template <typename Buffer, typename Out>
void feedInOrder(Buffer& buffer, const std::vector<NavInput>& nav, const std::vector<PingInput>& pings, Out& out,
                 double lead_s = 0.2) {
  size_t n = 0;
  for (const PingInput& ping : pings) {
    while (n < nav.size() && nav[n].utime_us <= ping.utime_us + static_cast<int64_t>(lead_s * 1e6)) buffer.addNav(nav[n++], out);
    buffer.addPing(ping, out);
  }
  while (n < nav.size()) buffer.addNav(nav[n++], out);
  buffer.finish(out);
}

// A short lawnmower: `lines` lines of line_length_m, 70 m apart, 75 m range, 4 Hz.
inline sss::sim::SimOptions shortLawnmower(int lines, double line_length_m) {
  sss::sim::SimOptions options;
  options.trajectory.lines = lines;
  options.trajectory.line_length_m = line_length_m;
  options.trajectory.line_spacing_m = 70.0;
  return options;
}

}  // namespace sss::subframe::test
