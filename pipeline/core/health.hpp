// Health figures of one process: per-channel message counts, rates, handler latencies, queue
// depths and drops, named counters, and the last error. Thread-safe; snapshot() once per status
// period turns them into the figures SSS_STATUS carries.
#pragma once

#include <cstdint>
#include <map>
#include <mutex>
#include <string>
#include <vector>

namespace sss::core {

enum class HealthState { kOk = 0, kWarning = 1, kError = 2 };

struct ChannelHealth {
  std::string channel;
  bool outgoing = false;
  int64_t messages = 0;
  double rate_hz = 0.0;
  double latency_p50_ms = 0.0;
  double latency_p99_ms = 0.0;
  double latency_max_ms = 0.0;
  int32_t queue_depth = 0;
  int64_t drops = 0;
};

struct HealthSnapshot {
  HealthState state = HealthState::kOk;
  std::string state_text;
  double uptime_s = 0.0;
  std::vector<ChannelHealth> channels;
  std::vector<std::pair<std::string, double>> counters;
  int64_t errors_total = 0;
  std::string last_error;
  int64_t last_error_utime = 0;
};

class HealthMonitor {
 public:
  // start_monotonic_us: monotonic time the process started (for uptime and the first rate).
  explicit HealthMonitor(int64_t start_monotonic_us);

  void recordMessage(const std::string& channel, bool outgoing, int64_t latency_us);
  void recordDrop(const std::string& channel, bool outgoing, int64_t count = 1);
  void setQueueDepth(const std::string& channel, bool outgoing, int32_t depth);

  void setCounter(const std::string& name, double value);
  void incrementCounter(const std::string& name, double delta = 1.0);
  double counter(const std::string& name) const;

  // Counts an error of a kind (e.g. "jsf_bad_checksum") and keeps its message as the last error.
  // Returns true the first time this kind is seen: the caller logs it then, and only then.
  bool recordError(const std::string& kind, const std::string& message, int64_t utime_us);

  void setState(HealthState state, const std::string& text);

  // Figures since the previous snapshot (rates, latency percentiles), then starts a new period.
  HealthSnapshot snapshot(int64_t now_monotonic_us);

 private:
  struct ChannelAccumulator {
    int64_t messages = 0;
    int64_t messages_at_last_snapshot = 0;
    std::vector<int64_t> latencies_us;  // this period only; bounded by kMaxLatencySamples
    int32_t queue_depth = 0;
    int64_t drops = 0;
  };
  static constexpr size_t kMaxLatencySamples = 4096;

  mutable std::mutex mutex_;
  int64_t start_monotonic_us_;
  int64_t last_snapshot_monotonic_us_;
  // Keyed by (channel, outgoing): a process may publish and receive the same channel.
  std::map<std::pair<std::string, bool>, ChannelAccumulator> channels_;
  std::map<std::string, double> counters_;
  std::map<std::string, int64_t> error_counts_;
  HealthState state_ = HealthState::kOk;
  std::string state_text_ = "ok";
  int64_t errors_total_ = 0;
  std::string last_error_;
  int64_t last_error_utime_ = 0;
};

// Percentile (0..100) of a sample set by nearest rank; 0 for an empty set. Sorts in place.
double percentile(std::vector<int64_t>& samples, double percent);

}  // namespace sss::core
