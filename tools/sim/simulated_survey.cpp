// A simulated survey cut into subframes, and the exact ground truth of its pixels.
#include "tools/sim/simulated_survey.hpp"

#include <omp.h>

#include <cmath>

#include "pipeline/subframe/ping_nav_fusion.hpp"

namespace sss::sim {
namespace {

using sss::subframe::NavInput;
using sss::subframe::PingInput;
using sss::core::Subframe;

}  // namespace

NavInput navInputFrom(int64_t utime_us, const sss::core::Pose& T_world_body, double altitude_m) {
  NavInput nav;
  nav.utime_us = utime_us;
  nav.position_ned_m = T_world_body.translation;
  const sss::core::EulerAngles e = sss::core::eulerFromQuaternion(T_world_body.rotation);
  nav.roll_rad = e.roll_rad;
  nav.pitch_rad = e.pitch_rad;
  nav.heading_rad = e.heading_rad;
  nav.altitude_m = altitude_m;
  nav.altitude_valid = true;
  return nav;
}

std::vector<sss::core::Pose> posesWithDrError(const Subframe& a, const Subframe& b, double along_m, double lateral_m) {
  const Eigen::Matrix3d R = a.centre().T_world_body.rotation.toRotationMatrix();
  Eigen::Vector3d forward = R.col(0), starboard = R.col(1);
  forward.z() = starboard.z() = 0.0;
  const sss::core::Pose shift(Eigen::Quaterniond::Identity(),
                              along_m * forward.normalized() + lateral_m * starboard.normalized());
  std::vector<sss::core::Pose> poses;
  poses.reserve(b.pings.size());
  for (const auto& ping : b.pings) poses.push_back(shift * ping.T_world_body);
  return poses;
}

SimulatedSurvey simulateSurvey(const SimOptions& options, const sss::subframe::SubframeBufferOptions& buffer_options) {
  SimulatedSurvey survey;
  survey.mission = std::make_unique<Mission>(options);
  const Mission& mission = *survey.mission;
  const SonarOptions& sonar = mission.sonar().options();
  std::vector<PingInput> pings(mission.pingCount());
#pragma omp parallel for schedule(dynamic, 8)
  for (long i = 0; i < static_cast<long>(pings.size()); ++i) {
    PingSamples samples = mission.renderPing(static_cast<size_t>(i));
    PingInput& ping = pings[i];
    ping.utime_us = mission.pingUtimeUs(static_cast<size_t>(i));
    ping.ping_number = i;
    ping.sound_speed_m_s = sonar.sound_speed_m_s;
    ping.sample_interval_s = sonar.sampleIntervalS();
    ping.altitude_m = mission.truthAtPing(static_cast<size_t>(i)).altitude_m;
    ping.port = std::move(samples.port);
    ping.starboard = std::move(samples.starboard);
  }
  // Nav up to 0.2 s past each ping first, as it arrives live.
  std::vector<NavInput> nav;
  for (const NavSample& s : mission.deadReckoning().samples()) {
    nav.push_back(navInputFrom(options.start_utime_us + static_cast<int64_t>(std::llround(s.time_s * 1e6)), s.T_world_body,
                          s.altitude_m));
  }
  sss::subframe::SubframeBuffer buffer(buffer_options);
  size_t n = 0;
  for (PingInput& ping : pings) {
    while (n < nav.size() && nav[n].utime_us <= ping.utime_us + 200000) buffer.addNav(nav[n++], survey.subframes);
    buffer.addPing(std::move(ping), survey.subframes);
  }
  while (n < nav.size()) buffer.addNav(nav[n++], survey.subframes);
  buffer.finish(survey.subframes);
  return survey;
}

std::vector<sss::core::Pose> truePoses(const Mission& mission, const Subframe& subframe) {
  std::vector<sss::core::Pose> poses;
  poses.reserve(subframe.pings.size());
  for (const auto& ping : subframe.pings) {
    poses.push_back(mission.truthAtPing(static_cast<size_t>(ping.ping_number)).T_world_body);
  }
  return poses;
}

SubframeTruth::SubframeTruth(const Mission& mission)
    : mission_(mission), geometry_(&mission.seabed(), mission.sonar().options()) {}

std::optional<Eigen::Vector3d> SubframeTruth::seabedPoint(const Subframe& subframe, int row, double column) const {
  if (row < 0 || row >= subframe.rows()) return std::nullopt;
  const double ground_m = subframe.geometry.signedGroundRangeM(column);
  const double altitude_m = subframe.pings[row].altitude_m;
  const double slant_m = std::hypot(ground_m, altitude_m);
  const sss::core::Pose T_world_sonar =
      mission_.truthAtPing(static_cast<size_t>(subframe.pings[row].ping_number)).T_world_body *
      subframe.geometry.T_body_sonar;
  const auto hit = geometry_.sampleToSeabed(T_world_sonar, ground_m < 0.0 ? Side::kPort : Side::kStarboard,
                                            slant_m / mission_.sonar().options().sampleSpacingM());
  if (!hit) return std::nullopt;
  return hit->position_ned_m;
}

std::vector<sss::core::Pose> SubframeTruth::sonarPoses(const Subframe& subframe) const {
  std::vector<sss::core::Pose> sonar = truePoses(mission_, subframe);
  for (auto& pose : sonar) pose = pose * subframe.geometry.T_body_sonar;
  return sonar;
}

std::optional<Eigen::Vector2d> SubframeTruth::pixelOf(const Subframe& subframe, const Eigen::Vector3d& point) const {
  return pixelOf(subframe, point, sonarPoses(subframe));
}

std::optional<Eigen::Vector2d> SubframeTruth::pixelOf(const Subframe& subframe, const Eigen::Vector3d& point,
                                                      const std::vector<sss::core::Pose>& sonar) const {
  if (sonar.empty()) return std::nullopt;
  // The fan-plane crossing (no visibility test: a shadowed point is rare and the ray cast of a
  // profile per query would dominate an evaluation of 10^5 matches).
  const auto signedDistance = [&](const sss::core::Pose& pose) {
    return (pose.rotation * Eigen::Vector3d::UnitX()).dot(point - pose.translation);
  };
  double previous = signedDistance(sonar[0]);
  for (size_t i = 1; i < sonar.size(); ++i) {
    const double current = signedDistance(sonar[i]);
    if (previous >= 0.0 && current < 0.0) {
      const double alpha = previous / (previous - current);
      const sss::core::Pose pose = sss::core::interpolate(sonar[i - 1], sonar[i], alpha);
      const Eigen::Vector3d offset = point - pose.translation;
      const double slant_m = offset.norm();
      const double altitude_m = (1.0 - alpha) * subframe.pings[i - 1].altitude_m + alpha * subframe.pings[i].altitude_m;
      if (slant_m <= altitude_m) return std::nullopt;
      const double ground_m = std::sqrt(slant_m * slant_m - altitude_m * altitude_m);
      const bool starboard = (pose.rotation * Eigen::Vector3d::UnitY()).dot(offset) >= 0.0;
      const sss::core::SubframeGeometry& g = subframe.geometry;
      const double bin = (ground_m - g.first_bin_range_m) / g.bin_size_m;
      const double column = starboard ? g.bins_per_side + bin : g.bins_per_side - 1 - bin;
      if (column < 0.0 || column > g.columns() - 1) return std::nullopt;
      return Eigen::Vector2d(static_cast<double>(i - 1) + alpha, column);
    }
    previous = current;
  }
  return std::nullopt;
}

sss::core::Pose SubframeTruth::trueRelativePose(const Subframe& a, const Subframe& b) const {
  const auto ta = mission_.truthAtPing(static_cast<size_t>(a.centre().ping_number)).T_world_body;
  const auto tb = mission_.truthAtPing(static_cast<size_t>(b.centre().ping_number)).T_world_body;
  return sss::core::between(ta, tb);
}

}  // namespace sss::sim
