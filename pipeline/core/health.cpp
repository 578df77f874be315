// Health figures, see health.hpp.
#include "pipeline/core/health.hpp"

#include <algorithm>
#include <cmath>

namespace sss::core {

double percentile(std::vector<int64_t>& samples, double percent) {
  if (samples.empty()) return 0.0;
  std::sort(samples.begin(), samples.end());
  const double rank = std::ceil(percent / 100.0 * static_cast<double>(samples.size()));
  const size_t index = static_cast<size_t>(std::clamp(rank, 1.0, static_cast<double>(samples.size()))) - 1;
  return static_cast<double>(samples[index]);
}

HealthMonitor::HealthMonitor(int64_t start_monotonic_us)
    : start_monotonic_us_(start_monotonic_us), last_snapshot_monotonic_us_(start_monotonic_us) {}

void HealthMonitor::recordMessage(const std::string& channel, bool outgoing, int64_t latency_us) {
  std::lock_guard<std::mutex> lock(mutex_);
  ChannelAccumulator& acc = channels_[{channel, outgoing}];
  acc.messages += 1;
  // Past the bound, keep a uniform-ish sample by overwriting round robin: memory stays fixed.
  if (acc.latencies_us.size() < kMaxLatencySamples) {
    acc.latencies_us.push_back(latency_us);
  } else {
    acc.latencies_us[static_cast<size_t>(acc.messages) % kMaxLatencySamples] = latency_us;
  }
}

void HealthMonitor::recordDrop(const std::string& channel, bool outgoing, int64_t count) {
  std::lock_guard<std::mutex> lock(mutex_);
  channels_[{channel, outgoing}].drops += count;
}

void HealthMonitor::setQueueDepth(const std::string& channel, bool outgoing, int32_t depth) {
  std::lock_guard<std::mutex> lock(mutex_);
  channels_[{channel, outgoing}].queue_depth = depth;
}

void HealthMonitor::setCounter(const std::string& name, double value) {
  std::lock_guard<std::mutex> lock(mutex_);
  counters_[name] = value;
}

void HealthMonitor::incrementCounter(const std::string& name, double delta) {
  std::lock_guard<std::mutex> lock(mutex_);
  counters_[name] += delta;
}

double HealthMonitor::counter(const std::string& name) const {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto it = counters_.find(name);
  return it == counters_.end() ? 0.0 : it->second;
}

bool HealthMonitor::recordError(const std::string& kind, const std::string& message, int64_t utime_us) {
  std::lock_guard<std::mutex> lock(mutex_);
  errors_total_ += 1;
  last_error_ = message;
  last_error_utime_ = utime_us;
  counters_["error." + kind] += 1.0;
  return ++error_counts_[kind] == 1;
}

void HealthMonitor::setState(HealthState state, const std::string& text) {
  std::lock_guard<std::mutex> lock(mutex_);
  state_ = state;
  state_text_ = text;
}

HealthSnapshot HealthMonitor::snapshot(int64_t now_monotonic_us) {
  std::lock_guard<std::mutex> lock(mutex_);
  HealthSnapshot snap;
  snap.state = state_;
  snap.state_text = state_text_;
  snap.uptime_s = static_cast<double>(now_monotonic_us - start_monotonic_us_) * 1e-6;
  const double period_s = std::max(1e-6, static_cast<double>(now_monotonic_us - last_snapshot_monotonic_us_) * 1e-6);
  for (auto& [key, acc] : channels_) {
    ChannelHealth ch;
    ch.channel = key.first;
    ch.outgoing = key.second;
    ch.messages = acc.messages;
    ch.rate_hz = static_cast<double>(acc.messages - acc.messages_at_last_snapshot) / period_s;
    ch.latency_p50_ms = percentile(acc.latencies_us, 50.0) * 1e-3;
    ch.latency_p99_ms = percentile(acc.latencies_us, 99.0) * 1e-3;
    // percentile() sorted the samples: the last one is the largest.
    ch.latency_max_ms = acc.latencies_us.empty() ? 0.0 : static_cast<double>(acc.latencies_us.back()) * 1e-3;
    ch.queue_depth = acc.queue_depth;
    ch.drops = acc.drops;
    snap.channels.push_back(ch);
    acc.messages_at_last_snapshot = acc.messages;
    acc.latencies_us.clear();
  }
  snap.counters.assign(counters_.begin(), counters_.end());
  snap.errors_total = errors_total_;
  snap.last_error = last_error_;
  snap.last_error_utime = last_error_utime_;
  last_snapshot_monotonic_us_ = now_monotonic_us;
  return snap;
}

}  // namespace sss::core
