// Line segmentation and subframe cutting. See subframe_builder.hpp.
#include "pipeline/subframe/subframe_builder.hpp"

#include <cmath>

namespace sss::subframe {

void readLineSegmenterOptions(sss::core::ConfigSection& section, LineSegmenterOptions& options) {
  using namespace sss::core;
  section.optional("max_heading_deviation_rad", options.max_heading_deviation_rad, {inRange(0.001, 3.14)});
  section.optional("min_steady_pings", options.min_steady_pings, {inRange(1, 10000)});
  section.optional("max_ping_gap_s", options.max_ping_gap_s, {greaterThan(0.0)});
  section.optional("curved_pieces_are_turns", options.curved_pieces_are_turns);
}

void readSubframeOptions(sss::core::ConfigSection& section, SubframeOptions& options) {
  using namespace sss::core;
  section.optional("pings_per_subframe", options.pings_per_subframe, {inRange(2, 100000)});
  section.optional("min_pings", options.min_pings, {inRange(1, 100000)});
  section.optional("intensity_bits", options.intensity_bits,
                   {satisfies<int>([](int b) { return b == 8 || b == 16; }, "8 or 16")});
  section.optional("max_intensity", options.max_intensity, {greaterThan(0.0)});
  if (options.min_pings > options.pings_per_subframe) {
    section.addProblem("min_pings", std::to_string(options.min_pings), "must not exceed pings_per_subframe");
  }
}

SubframeBuilder::SubframeBuilder(const LineSegmenterOptions& line_options, const SubframeOptions& options,
                                 const SubframeGeometry& geometry)
    : line_options_(line_options), options_(options), geometry_(geometry) {}

bool SubframeBuilder::deviates(double heading_rad) const {
  const double mean = std::atan2(line_sin_sum_, line_cos_sum_);
  return std::abs(sss::core::wrapAngle(heading_rad - mean)) > line_options_.max_heading_deviation_rad;
}

void SubframeBuilder::addPing(CanonicalPing ping, std::vector<Subframe>& out) {
  ++counters_.pings_in;
  const int64_t utime = ping.fused.ping.utime_us;
  const bool gap = last_utime_us_ != 0 &&
                   static_cast<double>(utime - last_utime_us_) * 1e-6 > line_options_.max_ping_gap_s;
  last_utime_us_ = utime;
  if (gap) {
    closeLine(out);
    candidate_.clear();
  }
  if (ping.turn) {
    closeLine(out);
    counters_.turn_pings += candidate_.size() + 1;
    candidate_.clear();
    return;
  }
  if (line_open_) {
    if (!deviates(ping.fused.steady_heading_rad)) {
      appendToLine(std::move(ping), out);
      return;
    }
    if (line_options_.curved_pieces_are_turns && !line_emitted_ && !current_.empty() &&
        std::abs(sss::core::wrapAngle(current_.back().fused.steady_heading_rad -
                                      current_.front().fused.steady_heading_rad)) >
            line_options_.max_heading_deviation_rad) {
      // Out of its heading before one subframe, having turned through the tolerance itself (a
      // straight piece ended by a sudden heading change stays a line): a piece of a slow turn.
      line_open_ = false;
      ++counters_.curved_pieces;
      counters_.turn_pings += current_.size();
      current_.clear();
    } else {
      closeLine(out);  // a heading change without a turn-rate signature: a new line
    }
  }
  // Hysteresis: a line opens only after min_steady_pings steady pings with one heading.
  if (!candidate_.empty() &&
      std::abs(sss::core::wrapAngle(ping.fused.steady_heading_rad - candidate_.front().fused.steady_heading_rad)) >
          line_options_.max_heading_deviation_rad) {
    counters_.turn_pings += candidate_.size();
    candidate_.clear();
  }
  candidate_.push_back(std::move(ping));
  if (static_cast<int>(candidate_.size()) >= line_options_.min_steady_pings) {
    line_open_ = true;
    line_emitted_ = false;
    ++line_id_;
    ++counters_.lines;
    line_sin_sum_ = line_cos_sum_ = 0.0;
    std::vector<CanonicalPing> pings = std::move(candidate_);
    candidate_.clear();
    for (CanonicalPing& p : pings) appendToLine(std::move(p), out);
  }
}

void SubframeBuilder::resumeNumbering(const SubframeNumbering& numbering) {
  next_subframe_id_ = numbering.next_subframe_id;
  line_id_ = numbering.next_line_id - 1;  // incremented when the next line opens
}

void SubframeBuilder::appendToLine(CanonicalPing&& ping, std::vector<Subframe>& out) {
  line_sin_sum_ += std::sin(ping.fused.steady_heading_rad);
  line_cos_sum_ += std::cos(ping.fused.steady_heading_rad);
  current_.push_back(std::move(ping));
  if (static_cast<int>(current_.size()) >= options_.pings_per_subframe) emit(out);
}

void SubframeBuilder::closeLine(std::vector<Subframe>& out) {
  if (!line_open_) return;
  line_open_ = false;
  if (current_.empty()) return;
  if (static_cast<int>(current_.size()) >= options_.min_pings) {
    ++counters_.partial_subframes;
    emit(out);
  } else {
    ++counters_.dropped_short_tails;
    counters_.dropped_tail_pings += current_.size();
    current_.clear();
  }
}

void SubframeBuilder::emit(std::vector<Subframe>& out) {
  Subframe subframe;
  subframe.id = next_subframe_id_++;
  subframe.line_id = line_id_;
  subframe.geometry = geometry_;
  const int rows = static_cast<int>(current_.size());
  const int cols = geometry_.columns();
  // The centre ping: the middle row (rows / 2), for full and partial subframes alike.
  subframe.centre_ping_index = rows / 2;
  subframe.pings.reserve(rows);
  subframe.image.resize(static_cast<size_t>(rows) * cols);
  subframe.mask.resize(static_cast<size_t>(rows) * cols);
  for (int r = 0; r < rows; ++r) {
    const CanonicalPing& ping = current_[r];
    SubframePing record;
    record.utime_us = ping.fused.ping.utime_us;
    record.ping_number = ping.fused.ping.ping_number;
    record.T_world_body = ping.fused.T_world_body;
    record.altitude_m = ping.fused.altitude_m;
    record.distance_travelled_m = ping.fused.distance_travelled_m;
    subframe.pings.push_back(record);
    std::copy(ping.intensity.begin(), ping.intensity.end(), subframe.image.begin() + static_cast<size_t>(r) * cols);
    std::copy(ping.mask.begin(), ping.mask.end(), subframe.mask.begin() + static_cast<size_t>(r) * cols);
  }
  subframe.last_ping_arrival_monotonic_us = current_.back().fused.ping.arrival_monotonic_us;
  ++counters_.subframes;
  line_emitted_ = true;
  current_.clear();
  out.push_back(std::move(subframe));
}

void SubframeBuilder::finish(std::vector<Subframe>& out) {
  closeLine(out);
  counters_.turn_pings += candidate_.size();
  candidate_.clear();
}

size_t SubframeBuilder::memoryBytes() const {
  size_t bytes = 0;
  for (const auto* list : {&candidate_, &current_}) {
    bytes += list->capacity() * sizeof(CanonicalPing);
    for (const CanonicalPing& p : *list) bytes += p.intensity.capacity() * sizeof(float) + p.mask.capacity();
  }
  return bytes;
}

}  // namespace sss::subframe
