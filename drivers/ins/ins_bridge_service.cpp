// sss-ins-bridge's logic around InsBridge. See ins_bridge_service.hpp.
#include "drivers/ins/ins_bridge_service.hpp"

#include <string_view>

#include "drivers/ins/fix_message.hpp"
#include "drivers/ins/nav_message.hpp"

namespace sss::ins {

InsBridgeService::InsBridgeService(const InsBridgeServiceOptions& options, sss::core::ServiceLog& log)
    : options_(options),
      bridge_(options.bridge),
      // A file replay is offline: nothing kept.
      state_(options.replay ? std::string() : options.state_directory),
      fix_reader_(options.fix_reader),
      fix_aligner_(options.fix_aligner),
      pacer_(options.replay_speed) {
  state_.restore(bridge_, log);
}

BridgeMessages InsBridgeService::onInsChunk(const InsInputChunk& chunk, sss::core::ServiceLog& log) {
  bridge_.onBytes(chunk.data, chunk.size, chunk.arrival_us, samples_);
  if (chunk.end_of_file) bridge_.finish(chunk.arrival_us, samples_);
  else if (chunk.stream_break) bridge_.onChunkEnd(chunk.arrival_us, samples_);
  if (!options_.replay) return publishSamples(chunk.arrival_us, log);
  replay_queue_.insert(replay_queue_.end(), samples_.begin(), samples_.end());
  samples_.clear();
  return {};
}

BridgeMessages InsBridgeService::onFixChunk(const InsInputChunk& chunk) {
  fix_reader_.feed(std::string_view(reinterpret_cast<const char*>(chunk.data), chunk.size));
  for (const PositionFix& fix : fix_reader_.take()) fix_aligner_.addFix(fix);
  BridgeMessages messages;
  messages.since_monotonic_us = chunk.arrival_us;
  appendPlacedFixes(messages);
  return messages;
}

BridgeMessages InsBridgeService::takeDue(int64_t now_monotonic_us, sss::core::ServiceLog& log, int max_samples) {
  for (int budget = max_samples;
       budget > 0 && !replay_queue_.empty() && pacer_.due(replay_queue_.front().ins.utime_us, now_monotonic_us);
       --budget) {
    samples_.push_back(replay_queue_.front());
    replay_queue_.pop_front();
  }
  return publishSamples(now_monotonic_us, log);
}

BridgeMessages InsBridgeService::publishSamples(int64_t since_monotonic_us, sss::core::ServiceLog& log) {
  state_.noteOrigin(bridge_, log);
  BridgeMessages messages;
  messages.since_monotonic_us = since_monotonic_us;
  messages.nav.reserve(samples_.size());
  for (const NavSample& sample : samples_) {
    messages.nav.push_back(toNavMessage(sample));
    if ((sample.ins.validity & kValidPosition) && sample.origin)
      fix_aligner_.addNav(sample.ins.utime_us, sample.position_ned_m, sample.distance_travelled_m, sample.origin);
  }
  samples_.clear();
  appendPlacedFixes(messages);
  return messages;
}

void InsBridgeService::appendPlacedFixes(BridgeMessages& messages) {
  // Fixes go out in the mission frame, which is known once the first position has fixed it.
  if (!options_.read_fixes || !bridge_.origin()) return;
  for (const AlignedFix& fix : fix_aligner_.take()) {
    messages.fixes.push_back(toFixMessage(fix, *bridge_.origin()));
    ++fixes_published_;
  }
}

void InsBridgeService::saveOdometerIfMoved(sss::core::ServiceLog& log) { state_.saveOdometerIfMoved(bridge_, log); }

std::vector<std::string> InsBridgeService::takeFixFaults() {
  if (!options_.read_fixes || fix_problem_reported_ || fix_reader_.firstProblem().empty()) return {};
  fix_problem_reported_ = true;
  return {"fixes: " + fix_reader_.firstProblem()};
}

void InsBridgeService::reportHealth(sss::core::HealthMonitor& health, int64_t now_monotonic_us) const {
  const std::string stale = bridge_.describeStale(now_monotonic_us);
  health.setState(stale.empty() ? sss::core::HealthState::kOk : sss::core::HealthState::kWarning,
                  stale.empty() ? "navigation ok" : stale);
  const auto& stream = bridge_.streamCounters();
  health.setCounter("nmea_sentences", static_cast<double>(stream.sentences));
  health.setCounter("nmea_bad_checksum", static_cast<double>(stream.bad_checksum));
  health.setCounter("nmea_missing_checksum", static_cast<double>(stream.missing_checksum));
  health.setCounter("nmea_overlong", static_cast<double>(stream.overlong));
  health.setCounter("nmea_truncated", static_cast<double>(stream.truncated));
  health.setCounter("nmea_garbage_bytes", static_cast<double>(stream.garbage_bytes));
  health.setCounter("ins_epochs", static_cast<double>(bridge_.assemblerCounters().epochs));
  health.setCounter("ins_epochs_out_of_order", static_cast<double>(bridge_.epochsOutOfOrder()));
  health.setCounter("odometer_m", bridge_.odometer().distance_travelled_m);
  health.setCounter("odometer_write_failures", static_cast<double>(state_.odometerWriteFailures()));
  if (options_.read_fixes) {
    const auto& aligned = fix_aligner_.counters();
    health.setCounter("fixes_in", static_cast<double>(aligned.fixes_in));
    health.setCounter("fixes_published", static_cast<double>(fixes_published_));
    health.setCounter("fixes_below_surface", static_cast<double>(aligned.below_surface));
    health.setCounter("fixes_outside_navigation", static_cast<double>(aligned.outside_navigation));
    const auto& read = fix_reader_.counters();
    health.setCounter("fix_sentences_skipped", static_cast<double>(read.rejected_sentences + read.malformed));
  }
  if (bridge_.origin()) {  // the mission frame, for the operator (NaN-free: only once it is known)
    health.setCounter("origin_latitude_deg", bridge_.origin()->latitude_deg);
    health.setCounter("origin_longitude_deg", bridge_.origin()->longitude_deg);
  }
}

}  // namespace sss::ins
