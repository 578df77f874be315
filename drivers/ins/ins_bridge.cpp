// INS bridge logic, see ins_bridge.hpp.
#include "drivers/ins/ins_bridge.hpp"

#include <algorithm>
#include <cmath>

#include "pipeline/core/pose.hpp"

namespace sss::ins {

InsBridge::InsBridge(const InsBridgeOptions& options)
    : options_(options), parser_(options.stream), assembler_(options.assembler) {
  if (options.origin) setOrigin(*options.origin, sss::core::OriginSource::kConfigured);
}

void InsBridge::setOrigin(const sss::core::MissionOrigin& origin, sss::core::OriginSource source) {
  origin_ = origin;
  origin_source_ = source;
  plane_.emplace(origin.latitude_deg, origin.longitude_deg);
}

void InsBridge::resumeOrigin(const sss::core::MissionOrigin& origin) {
  if (!origin_) setOrigin(origin, sss::core::OriginSource::kResumed);
}

void InsBridge::onBytes(const uint8_t* data, size_t size, int64_t host_monotonic_us, std::vector<NavSample>& out) {
  sentences_.clear();
  parser_.feed(data, size, sentences_);
  assemble(sentences_, host_monotonic_us, out);
}

void InsBridge::onChunkEnd(int64_t host_monotonic_us, std::vector<NavSample>& out) {
  sentences_.clear();
  parser_.flush(sentences_);
  assemble(sentences_, host_monotonic_us, out);
}

void InsBridge::finish(int64_t host_monotonic_us, std::vector<NavSample>& out) {
  onChunkEnd(host_monotonic_us, out);
  if (const auto state = assembler_.flush()) emit(*state, host_monotonic_us, out);
}

void InsBridge::assemble(std::vector<std::string>& sentences, int64_t host_monotonic_us, std::vector<NavSample>& out) {
  for (const std::string& body : sentences) {
    for (const InsState& state : assembler_.addSentence(body)) emit(state, host_monotonic_us, out);
  }
}

void InsBridge::emit(const InsState& state, int64_t host_monotonic_us, std::vector<NavSample>& out) {
  if (last_ins_utime_us_ != 0 && state.utime_us <= last_ins_utime_us_) {
    // A repeated or older epoch (UDP reordering, an INS time step back): the chain needs time
    // to move forward; the sample is counted and dropped.
    ++epochs_out_of_order_;
    return;
  }
  last_ins_utime_us_ = state.utime_us;
  last_epoch_host_us_ = host_monotonic_us;

  NavSample sample;
  sample.ins = state;
  if (!plane_ && (state.validity & kValidPosition) &&
      sss::core::isFirstFixCandidate(state.latitude_deg, state.longitude_deg)) {
    setOrigin({state.latitude_deg, state.longitude_deg}, sss::core::OriginSource::kFirstFix);
  }
  sample.origin = origin_;
  if (plane_) sample.position_ned_m = plane_->toNed({state.latitude_deg, state.longitude_deg, state.depth_m});
  const Eigen::Quaterniond q_world_body = sss::core::quaternionFromEuler(state.roll_rad, state.pitch_rad, state.heading_rad);
  const Eigen::Vector3d velocity_ned(state.velocity_north_m_s, state.velocity_east_m_s, state.velocity_down_m_s);
  sample.velocity_body_m_s = q_world_body.conjugate() * velocity_ned;
  if ((state.validity & kValidPosition) && plane_) {
    // After a resume, the saved position counts only if it is recent (a restart, not another dive).
    const double gap_s = static_cast<double>(state.utime_us - last_position_utime_us_) * 1e-6;
    const bool counts = !resumed_ || (gap_s >= 0.0 && gap_s <= options_.odometer_max_bridged_gap_s);
    if (last_position_ned_m_ && counts) distance_travelled_m_ += (sample.position_ned_m - *last_position_ned_m_).head<2>().norm();
    last_position_ned_m_ = sample.position_ned_m;
    last_position_utime_us_ = state.utime_us;
    resumed_ = false;
  }
  sample.distance_travelled_m = distance_travelled_m_;
  out.push_back(sample);
}

OdometerState InsBridge::odometer() const {
  OdometerState state;
  state.distance_travelled_m = distance_travelled_m_;
  if (last_position_ned_m_) {
    state.utime_us = last_position_utime_us_;
    state.position_ned_m = *last_position_ned_m_;
  }
  return state;
}

void InsBridge::resumeOdometer(const OdometerState& state) {
  distance_travelled_m_ = state.distance_travelled_m;
  resumed_ = true;
  if (state.utime_us > 0) {
    last_position_ned_m_ = state.position_ned_m;
    last_position_utime_us_ = state.utime_us;
  }
}

uint32_t InsBridge::staleFlagsAt(int64_t host_monotonic_us) const {
  if (last_ins_utime_us_ == 0) return kStaleAll;
  return assembler_.staleFlags(last_ins_utime_us_ + (host_monotonic_us - last_epoch_host_us_));
}

std::string InsBridge::describeStale(int64_t host_monotonic_us) const {
  const uint32_t stale = staleFlagsAt(host_monotonic_us);
  if (stale == 0) return "";
  if (last_ins_utime_us_ == 0) return "no INS data yet";
  const double silent_s = static_cast<double>(host_monotonic_us - last_epoch_host_us_) * 1e-6;
  std::string text;
  auto add = [&](uint32_t flag, const char* name) {
    if (stale & flag) text += std::string(text.empty() ? "stale: " : ", ") + name;
  };
  add(kStaleHeading, "heading");
  add(kStaleAttitude, "attitude");
  add(kStalePosition, "position");
  add(kStaleDepth, "depth");
  add(kStaleVelocity, "velocity");
  add(kStaleAltitude, "altitude");
  if (silent_s > 1.0) text += " (no INS epoch for " + std::to_string(static_cast<int>(silent_s)) + " s)";
  return text;
}

std::vector<std::string> InsBridge::takeNewFaultMessages() {
  std::vector<std::string> faults;
  auto once = [&](const std::string& kind, const std::string& text) {
    if (text.empty() || std::find(reported_.begin(), reported_.end(), kind) != reported_.end()) return;
    reported_.push_back(kind);
    faults.push_back("INS: " + text);
  };
  const NmeaStreamFirstErrors& stream = parser_.firstErrors();
  once("bad_checksum", stream.bad_checksum);
  once("missing_checksum", stream.missing_checksum);
  once("overlong", stream.overlong);
  once("bad_character", stream.bad_character);
  once("truncated", stream.truncated);
  once("garbage", stream.garbage);
  for (int e = 1; e < kSentenceErrorCount; ++e) {
    once(std::string("sentence_") + sentenceErrorName(static_cast<SentenceError>(e)),
         assembler_.firstError(static_cast<SentenceError>(e)));
  }
  if (epochs_out_of_order_ > 0) once("out_of_order", "an epoch not newer than the previous one was dropped");
  return faults;
}

void readInsBridgeOptions(sss::core::ConfigSection& section, InsBridgeOptions& options) {
  using namespace sss::core;
  section.optional("heading_timeout_s", options.assembler.heading_timeout_s, {inRange(0.01, 600.0)});
  section.optional("attitude_timeout_s", options.assembler.attitude_timeout_s, {inRange(0.01, 600.0)});
  section.optional("position_timeout_s", options.assembler.position_timeout_s, {inRange(0.01, 600.0)});
  section.optional("depth_timeout_s", options.assembler.depth_timeout_s, {inRange(0.01, 600.0)});
  section.optional("velocity_timeout_s", options.assembler.velocity_timeout_s, {inRange(0.01, 600.0)});
  section.optional("altitude_timeout_s", options.assembler.altitude_timeout_s, {inRange(0.01, 600.0)});
  section.optional("altitude_std_m", options.assembler.altitude_std_m, {inRange(0.001, 100.0)});
  section.optional("odometer_max_bridged_gap_s", options.odometer_max_bridged_gap_s, {inRange(0.0, 86400.0)});
  int max_sentence_bytes = static_cast<int>(options.stream.max_sentence_bytes);
  section.optional("max_sentence_bytes", max_sentence_bytes, {inRange(82, 4096)});
  options.stream.max_sentence_bytes = static_cast<size_t>(max_sentence_bytes);
}

}  // namespace sss::ins
