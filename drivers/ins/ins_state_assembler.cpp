// InsStateAssembler: epoch grouping of the iXblue sentence burst, unit and sign conversion to
// NED/FRD radians, date tracking across midnight, and per-quantity staleness.
#include "drivers/ins/ins_state_assembler.hpp"

#include <cmath>

namespace sss::ins {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDegToRad = kPi / 180.0;
constexpr int64_t kMicrosecondsPerDay = 86400LL * 1000000LL;

// One bit per sentence kind, for the "kind already in this epoch" test. ALGSTS and STATUS share
// a struct but are different sentences of the same burst.
uint32_t kindBit(const ParsedSentence& sentence) {
  const auto* status = std::get_if<StatusSentence>(&sentence);
  constexpr size_t kStatusBit = std::variant_size_v<ParsedSentence>;
  return 1u << (status && !status->algorithm ? kStatusBit : sentence.index());
}

}  // namespace

std::string validateOptions(const InsAssemblerOptions& options) {
  const std::pair<const char*, double> timeouts[] = {
      {"heading_timeout_s", options.heading_timeout_s},
      {"attitude_timeout_s", options.attitude_timeout_s},
      {"position_timeout_s", options.position_timeout_s},
      {"depth_timeout_s", options.depth_timeout_s},
      {"velocity_timeout_s", options.velocity_timeout_s},
      {"altitude_timeout_s", options.altitude_timeout_s}};
  for (const auto& [name, value] : timeouts) {
    // An upper bound keeps the microsecond conversion far from int64 overflow.
    if (!(value > 0.0 && value <= 86400.0)) {
      return std::string(name) + " = " + std::to_string(value) + ": must be in (0, 86400] s";
    }
  }
  if (!(options.altitude_std_m >= 0.0 && options.altitude_std_m < 1000.0)) {
    return "altitude_std_m = " + std::to_string(options.altitude_std_m) +
           ": must be in [0, 1000) m";
  }
  return {};
}

InsStateAssembler::InsStateAssembler(const InsAssemblerOptions& options) : options_(options) {
  // Bad options are a programming or config-loader error; fall back to the defaults rather
  // than divide or overflow on them.
  if (!validateOptions(options_).empty()) options_ = InsAssemblerOptions{};
}

const std::string& InsStateAssembler::firstError(SentenceError error) const {
  return first_errors_[static_cast<size_t>(error)];
}

int64_t InsStateAssembler::timeoutUs(Quantity quantity) const {
  double seconds = 0.0;
  switch (quantity) {
    case kHeading: seconds = options_.heading_timeout_s; break;
    case kAttitude: seconds = options_.attitude_timeout_s; break;
    case kPosition: seconds = options_.position_timeout_s; break;
    case kDepth: seconds = options_.depth_timeout_s; break;
    case kVelocity: seconds = options_.velocity_timeout_s; break;
    case kAltitude: seconds = options_.altitude_timeout_s; break;
    case kQuantityCount: break;
  }
  return static_cast<int64_t>(std::llround(seconds * 1e6));
}

uint32_t InsStateAssembler::staleFlags(int64_t utime_us) const {
  static const uint32_t kStaleBit[kQuantityCount] = {kStaleHeading,  kStaleAttitude,
                                                     kStalePosition, kStaleDepth,
                                                     kStaleVelocity, kStaleAltitude};
  uint32_t flags = 0;
  for (int q = 0; q < kQuantityCount; ++q) {
    const auto& last = last_received_utime_us_[static_cast<size_t>(q)];
    // utime values come from parsed dates within 1980..2199, so the difference cannot overflow.
    if (!last || utime_us - *last > timeoutUs(static_cast<Quantity>(q))) flags |= kStaleBit[q];
  }
  return flags;
}

std::vector<InsState> InsStateAssembler::addSentence(std::string_view body) {
  std::vector<InsState> states;
  SentenceParseResult parsed = parseSentence(body);
  if (parsed.error != SentenceError::kNone) {
    const auto index = static_cast<size_t>(parsed.error);
    ++counters_.rejected[index];
    if (first_errors_[index].empty()) first_errors_[index] = std::move(parsed.error_text);
    return states;
  }
  if (std::holds_alternative<IgnoredSentence>(parsed.sentence)) {
    ++counters_.sentences_ignored;
    return states;
  }
  ++counters_.sentences_used;
  const uint32_t bit = kindBit(parsed.sentence);
  if (epoch_.kinds & bit) {
    // The previous burst ended without STATUS: close it before this one starts.
    if (auto state = closeEpoch(false)) states.push_back(*state);
  }
  epoch_.kinds |= bit;
  store(parsed.sentence);
  if (epoch_.has_status) {
    if (auto state = closeEpoch(true)) states.push_back(*state);
  }
  return states;
}

std::optional<InsState> InsStateAssembler::flush() { return closeEpoch(true); }

void InsStateAssembler::store(const ParsedSentence& sentence) {
  if (const auto* s = std::get_if<HeadingSentence>(&sentence)) epoch_.heading = *s;
  else if (const auto* s = std::get_if<AttitudeSentence>(&sentence)) epoch_.attitude = *s;
  else if (const auto* s = std::get_if<PositionSentence>(&sentence)) epoch_.position = *s;
  else if (const auto* s = std::get_if<SpeedSentence>(&sentence)) epoch_.speed = *s;
  else if (const auto* s = std::get_if<TimeSentence>(&sentence)) epoch_.time = *s;
  else if (const auto* s = std::get_if<AttitudeStdSentence>(&sentence)) epoch_.attitude_std = *s;
  else if (const auto* s = std::get_if<PositionStdSentence>(&sentence)) epoch_.position_std = *s;
  else if (const auto* s = std::get_if<SpeedStdSentence>(&sentence)) epoch_.speed_std = *s;
  else if (const auto* s = std::get_if<DepthBelowTransducerSentence>(&sentence))
    epoch_.altitude = *s;
  else if (const auto* s = std::get_if<DateTimeSentence>(&sentence)) epoch_.date_time = *s;
  else if (const auto* s = std::get_if<StatusSentence>(&sentence)) {
    const uint64_t word = (static_cast<uint64_t>(s->word_msb) << 32) | s->word_lsb;
    if (s->algorithm) {
      algorithm_status_ = word;
    } else {
      system_status_ = word;
      epoch_.has_status = true;
    }
  }
}

std::optional<InsState> InsStateAssembler::closeEpoch(bool terminated) {
  Epoch epoch = epoch_;
  epoch_ = Epoch{};
  if (epoch.kinds == 0) return std::nullopt;

  if (epoch.date_time) {
    has_date_ = true;
    date_days_ = daysFromCivil(epoch.date_time->year, epoch.date_time->month,
                               epoch.date_time->day);
    date_time_of_day_us_ = epoch.date_time->time_of_day_us;
  }
  int64_t time_of_day_us = 0;
  if (epoch.time) {
    time_of_day_us = epoch.time->time_of_day_us;
  } else if (epoch.date_time) {
    time_of_day_us = epoch.date_time->time_of_day_us;
  } else {
    ++counters_.epochs_without_time;
    return std::nullopt;
  }
  if (!has_date_) {
    ++counters_.epochs_without_date;
    return std::nullopt;
  }
  if (!terminated) ++counters_.epochs_without_terminator;

  // The date belongs to the reference time; a time of day half a day away from it lies on the
  // neighbouring day (midnight passed since the last ZDA, or TIME__ slightly before a ZDA that
  // already turned the date).
  int64_t days = date_days_;
  if (time_of_day_us < date_time_of_day_us_ - kMicrosecondsPerDay / 2) ++days;
  if (time_of_day_us > date_time_of_day_us_ + kMicrosecondsPerDay / 2) --days;
  date_days_ = days;
  date_time_of_day_us_ = time_of_day_us;
  const int64_t utime_us = days * kMicrosecondsPerDay + time_of_day_us;

  InsState& s = held_;
  s.utime_us = utime_us;
  uint32_t valid = 0;
  auto received = [&](Quantity q, uint32_t bit) {
    last_received_utime_us_[q] = utime_us;
    valid |= bit;
  };
  if (epoch.heading) {
    s.heading_rad = epoch.heading->heading_deg * kDegToRad;
    received(kHeading, kValidHeading);
  }
  if (epoch.attitude) {
    s.roll_rad = epoch.attitude->roll_deg * kDegToRad;     // + port up = + starboard down
    s.pitch_rad = -epoch.attitude->pitch_deg * kDegToRad;  // iXblue + bow down, FRD + bow up
    received(kAttitude, kValidAttitude);
  }
  if (epoch.position) {
    s.latitude_deg = epoch.position->latitude_deg;
    s.longitude_deg = epoch.position->longitude_deg;
    s.depth_m = -epoch.position->altitude_m;
    received(kPosition, kValidPosition);
    received(kDepth, kValidDepth);
  }
  if (epoch.speed) {
    s.velocity_north_m_s = epoch.speed->north_m_s;
    s.velocity_east_m_s = epoch.speed->east_m_s;
    s.velocity_down_m_s = -epoch.speed->up_m_s;
    received(kVelocity, kValidVelocity);
  }
  if (epoch.altitude && epoch.altitude->has_depth) {
    s.altitude_m = epoch.altitude->depth_m;
    s.altitude_std_m = options_.altitude_std_m;
    received(kAltitude, kValidAltitude);
  }
  if (epoch.attitude_std) {
    s.heading_std_rad = epoch.attitude_std->heading_std_deg * kDegToRad;
    s.roll_std_rad = epoch.attitude_std->roll_std_deg * kDegToRad;
    s.pitch_std_rad = epoch.attitude_std->pitch_std_deg * kDegToRad;
    valid |= kValidAttitudeStd;
  }
  if (epoch.position_std) {
    s.latitude_std_m = epoch.position_std->latitude_std_m;
    s.longitude_std_m = epoch.position_std->longitude_std_m;
    s.depth_std_m = epoch.position_std->altitude_std_m;
    valid |= kValidPositionStd;
  }
  if (epoch.speed_std) {
    s.velocity_east_std_m_s = epoch.speed_std->east_std_m_s;
    s.velocity_north_std_m_s = epoch.speed_std->north_std_m_s;
    s.velocity_down_std_m_s = epoch.speed_std->up_std_m_s;
    valid |= kValidVelocityStd;
  }
  // A stale altitude is unknown, not the last value: the seabed may have dropped away.
  const uint32_t stale = staleFlags(utime_us);
  if (stale & kStaleAltitude) s.altitude_m = -1.0;
  s.validity = valid | stale;
  ++counters_.epochs;
  return s;
}

}  // namespace sss::ins
