// sss-subframe-buffer's numbering, idle flush and status. See subframe_buffer_service.hpp.
#include "pipeline/subframe/subframe_buffer_service.hpp"

#include <unistd.h>

#include <limits>
#include <utility>

#include "pipeline/core/state_file.hpp"

namespace sss::subframe {

namespace {

// The numbering saved by an earlier run; {0, 0} when there is none. A file that cannot be read
// is reported (numbering from 0 may collide with the subframes the optimiser already has).
SubframeNumbering loadNumbering(const std::string& path, ServiceLog& log) {
  SubframeNumbering numbering;
  if (path.empty() || access(path.c_str(), F_OK) != 0) return numbering;
  const sss::core::Result<sss::core::StateValues> read =
      sss::core::readStateFile(path, SubframeBufferService::kNumberingFormat);
  long long subframe_id = 0, line_id = 0;
  if (!read || !sss::core::stateInteger(*read, "next_subframe_id", subframe_id) ||
      !sss::core::stateInteger(*read, "next_line_id", line_id) || subframe_id < 0 || line_id < 0 ||
      line_id > std::numeric_limits<int>::max()) {
    log.errors.push_back("subframe numbering not resumed, starting from 0 (subframes the optimiser already has will "
                         "be refused as duplicates): " +
                         (read ? path + ": bad next_subframe_id / next_line_id" : read.message()));
    return numbering;
  }
  numbering.next_subframe_id = subframe_id;
  numbering.next_line_id = static_cast<int>(line_id);
  log.info.push_back("resumed the numbering from " + path + ": next subframe " + std::to_string(subframe_id) +
                     ", next line " + std::to_string(line_id));
  return numbering;
}

}  // namespace

SubframeBufferService::SubframeBufferService(const SubframeBufferServiceOptions& options, ServiceLog& log)
    : options_(options), buffer_(options.buffer) {
  if (options_.numbering_path.empty()) {
    log.warnings.push_back("no state directory (subframe_buffer.state_directory or $STATE_DIRECTORY): after a "
                           "restart the subframe ids start from 0 again");
  }
  buffer_.resumeNumbering(loadNumbering(options_.numbering_path, log));
}

std::vector<Subframe> SubframeBufferService::takeCompleted(ServiceLog& log) {
  // The numbering is saved before the subframes leave: a kill in between skips ids, it never
  // reuses one.
  if (!completed_.empty() && !options_.numbering_path.empty()) {
    const SubframeNumbering numbering = buffer_.numbering();
    const sss::core::Status saved =
        sss::core::writeStateFile(options_.numbering_path, kNumberingFormat,
                                  {{"next_subframe_id", std::to_string(numbering.next_subframe_id)},
                                   {"next_line_id", std::to_string(numbering.next_line_id)}});
    if (!saved) {
      if (numbering_write_failures_++ == 0)
        log.errors.push_back("subframe numbering not saved (counted from now on): " + saved.message);
    }
  }
  return std::exchange(completed_, {});
}

std::vector<Subframe> SubframeBufferService::addNav(const sss::core::NavSample& nav, ServiceLog& log) {
  buffer_.addNav(nav, completed_);
  return takeCompleted(log);
}

std::vector<Subframe> SubframeBufferService::addPing(sss::core::PingSample ping, int64_t now_monotonic_us,
                                                     ServiceLog& log) {
  last_ping_monotonic_us_ = now_monotonic_us;
  flushed_since_last_ping_ = false;
  buffer_.addPing(std::move(ping), completed_);
  return takeCompleted(log);
}

std::vector<Subframe> SubframeBufferService::flushIfIdle(int64_t now_monotonic_us, ServiceLog& log) {
  if (flushed_since_last_ping_) return {};
  if (now_monotonic_us - last_ping_monotonic_us_ < static_cast<int64_t>(options_.idle_flush_s * 1e6)) return {};
  buffer_.finish(completed_);
  flushed_since_last_ping_ = true;
  log.info.push_back("no ping for " + std::to_string(options_.idle_flush_s) + " s: closed the open survey line");
  return takeCompleted(log);
}

std::vector<Subframe> SubframeBufferService::finish(ServiceLog& log) {
  buffer_.finish(completed_);
  return takeCompleted(log);
}

void SubframeBufferService::reportHealth(sss::core::HealthMonitor& health, int64_t now_utime_us, ServiceLog& log) {
  const SubframeBufferCounters c = buffer_.counters();
  const auto set = [&](const char* name, uint64_t value) { health.setCounter(name, static_cast<double>(value)); };
  set("pings_in", c.fusion.pings_in);
  set("pings_fused", c.fusion.pings_out);
  set("pings_dropped_without_nav", c.fusion.droppedWithoutNav());
  set("pings_dropped_no_nav", c.fusion.dropped_no_nav);
  set("pings_dropped_too_old", c.fusion.dropped_too_old);
  set("pings_dropped_nav_gap", c.fusion.dropped_nav_gap);
  set("pings_out_of_order", c.fusion.pings_out_of_order);
  set("pings_reordered", c.fusion.pings_reordered);
  set("pings_duplicate", c.fusion.pings_duplicate);
  set("pings_dropped_no_altitude", c.fusion.dropped_no_altitude);
  set("pings_dropped_before_first_fix", c.fusion.dropped_before_first_fix);
  set("altitude_from_nav", c.fusion.altitude_from_nav);
  set("altitude_from_ping", c.fusion.altitude_from_ping);
  set("altitude_from_bottom_track", c.fusion.altitude_from_bottom_track);
  set("altitude_implausible", c.fusion.altitude_implausible);
  set("nav_in", c.fusion.nav_in);
  set("nav_without_position", c.fusion.nav_without_position);
  set("nav_out_of_order", c.fusion.nav_out_of_order);
  set("turn_rows", c.turn_rows);
  set("lines", c.builder.lines);
  set("subframes_out", c.builder.subframes);
  set("partial_subframes", c.builder.partial_subframes);
  set("dropped_short_tails", c.builder.dropped_short_tails);
  set("curved_pieces", c.builder.curved_pieces);
  set("memory_bytes", buffer_.memoryBytes());
  set("numbering_write_failures", numbering_write_failures_);

  // Each cause of lost pings: counted always, an error of its kind and a log line the first time.
  if (c.fusion.droppedWithoutNav() > reported_no_nav_) {
    if (health.recordError("ping_without_nav", "pings dropped without bracketing navigation (check SSS_NAV)",
                           now_utime_us))
      log.warnings.push_back("pings dropped without bracketing navigation; further drops are counted in SSS_STATUS");
    reported_no_nav_ = c.fusion.droppedWithoutNav();
  }
  if (c.fusion.pings_out_of_order > reported_out_of_order_) {
    if (health.recordError("ping_out_of_order", "pings older than one already processed were dropped", now_utime_us))
      log.warnings.push_back("out-of-order pings dropped; further ones are counted in SSS_STATUS");
    reported_out_of_order_ = c.fusion.pings_out_of_order;
  }
  if (c.fusion.dropped_no_altitude > reported_no_altitude_) {
    if (health.recordError("ping_without_altitude", "pings dropped: no valid nav or sonar altitude", now_utime_us))
      log.warnings.push_back(
          "pings dropped without a valid altitude (no DVL altitude in SSS_NAV, none in the ping and no seabed return "
          "found; subframe_buffer.fusion.altitude_source: auto or bottom_track tracks the bottom in the returns); "
          "further ones are counted in SSS_STATUS");
    reported_no_altitude_ = c.fusion.dropped_no_altitude;
  }
}

}  // namespace sss::subframe
