// Port/starboard joining, see ping_assembler.hpp.
#include "drivers/edgetech/ping_assembler.hpp"

#include <algorithm>

namespace sss::edgetech {

PingAssembler::PingAssembler(PingAssemblerOptions options) : options_(options) {}

void PingAssembler::emit(Pending&& pending, std::vector<AssembledPing>& out) {
  if (pending.ping.complete()) {
    ++counters_.complete_pings;
  } else {
    ++counters_.incomplete_pings;
  }
  out.push_back(std::move(pending.ping));
}

void PingAssembler::add(SonarChannelRecord record, int64_t arrival_us, std::vector<AssembledPing>& out) {
  if (record.subsystem == options_.subsystem) {
    if (!configured_seen_) {
      configured_seen_ = true;
      counters_.other_subsystem += held_other_.size();
      held_other_.clear();
    }
    join(std::move(record), arrival_us, out);
    return;
  }
  const bool side_scan = record.subsystem >= kSubsystemSideScanLow && record.subsystem <= kSubsystemSideScanLow + 2;
  if (!configured_seen_ && side_scan && options_.adopt_other_side_scan_after > 0) {
    if (!held_other_.empty() && held_other_.front().first.subsystem != record.subsystem) {
      // Two other frequencies and not the configured one: nothing says which one is meant.
      counters_.other_subsystem += held_other_.size() + 1;
      held_other_.clear();
      configured_seen_ = true;  // stop adopting
      return;
    }
    held_other_.emplace_back(std::move(record), arrival_us);
    if (static_cast<int>(held_other_.size()) >= options_.adopt_other_side_scan_after) adoptHeld(out);
    return;
  }
  ++counters_.other_subsystem;
}

void PingAssembler::adoptHeld(std::vector<AssembledPing>& out) {
  options_.subsystem = held_other_.front().first.subsystem;
  counters_.adopted_subsystem = options_.subsystem;
  configured_seen_ = true;
  for (auto& [held, held_arrival_us] : held_other_) join(std::move(held), held_arrival_us, out);
  held_other_.clear();
}

void PingAssembler::join(SonarChannelRecord record, int64_t arrival_us, std::vector<AssembledPing>& out) {
  auto it = std::find_if(pending_.begin(), pending_.end(),
                         [&](const Pending& p) { return p.ping.ping_number == record.ping_number; });
  if (it == pending_.end()) {
    Pending fresh;
    fresh.ping.ping_number = record.ping_number;
    fresh.first_arrival_us = arrival_us;
    pending_.push_back(std::move(fresh));
    it = std::prev(pending_.end());
  }
  std::optional<SonarChannelRecord>& side = record.channel == kChannelPort ? it->ping.port : it->ping.starboard;
  if (side) ++counters_.duplicate_channels;
  side = std::move(record);
  it->ping.last_arrival_us = arrival_us;
  if (it->ping.complete()) {
    // Older incomplete pings keep waiting for their own timeout: a sonar may interleave sides.
    Pending done = std::move(*it);
    pending_.erase(it);
    emit(std::move(done), out);
  }
  while (static_cast<int>(pending_.size()) > options_.max_pending_pings) {
    Pending oldest = std::move(pending_.front());
    pending_.pop_front();
    emit(std::move(oldest), out);
  }
}

void PingAssembler::expire(int64_t now_us, std::vector<AssembledPing>& out) {
  const int64_t timeout_us = static_cast<int64_t>(options_.missing_side_timeout_s * 1e6);
  while (!pending_.empty() && now_us - pending_.front().first_arrival_us >= timeout_us) {
    Pending oldest = std::move(pending_.front());
    pending_.pop_front();
    emit(std::move(oldest), out);
  }
}

void PingAssembler::flush(std::vector<AssembledPing>& out) {
  if (!configured_seen_ && !held_other_.empty()) adoptHeld(out);  // a short file of another frequency only
  while (!pending_.empty()) {
    Pending oldest = std::move(pending_.front());
    pending_.pop_front();
    emit(std::move(oldest), out);
  }
}

}  // namespace sss::edgetech
