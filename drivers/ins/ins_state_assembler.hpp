// Combines parsed iXblue NMEA sentences into one InsState per INS output period, holds the newest
// value of each quantity and flags quantities that have not been received for too long.
//
// Epoch rule: iXblue sends a burst of sentences per output period, ending with $PIXSE,STATUS.
// An epoch is emitted when (a) STATUS arrives, or (b) a sentence of a kind already in the open
// epoch arrives (the STATUS of the previous burst was lost or is not configured: the open epoch
// is emitted first, one period late), or (c) flush() is called. The epoch time is TIME__ (1 us)
// or, without it, the ZDA time (10 ms); the date comes from the newest ZDA and is carried
// forward across midnight. An epoch with no time, or before any ZDA, is dropped and counted.
//
// Validity: kValid<X> = X was received in this epoch. Fields of quantities not received keep
// their newest earlier value. kStale<X> = X has not been received for longer than its timeout
// (or never), measured in INS time; it clears as soon as X returns.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "drivers/ins/ixblue_nmea.hpp"

namespace sss::ins {

struct InsAssemblerOptions {
  double heading_timeout_s = 1.0;
  double attitude_timeout_s = 1.0;
  double position_timeout_s = 5.0;
  double depth_timeout_s = 5.0;
  double velocity_timeout_s = 2.0;
  double altitude_timeout_s = 5.0;  // a DVL loses bottom lock over steep terrain and in turns
  // The protocol carries no altitude uncertainty: one sigma of the DVL range, from the
  // DVL's data sheet, reported in InsState::altitude_std_m with each altitude.
  double altitude_std_m = 0.1;
};

// Empty when valid, otherwise what is wrong: "heading_timeout_s = -1: must be > 0".
std::string validateOptions(const InsAssemblerOptions& options);

struct InsAssemblerCounters {
  int64_t sentences_used = 0;
  int64_t sentences_ignored = 0;  // recognised but carry nothing we use (UTMWGS, HEAVE_, ...)
  std::array<int64_t, kSentenceErrorCount> rejected{};  // by SentenceError (index 0 unused)
  int64_t epochs = 0;             // states emitted
  int64_t epochs_without_time = 0;
  int64_t epochs_without_date = 0;
  int64_t epochs_without_terminator = 0;  // closed by a repeated sentence, not by STATUS
};

class InsStateAssembler {
 public:
  explicit InsStateAssembler(const InsAssemblerOptions& options = {});

  // One verified sentence body (from NmeaStreamParser). Returns the states it completes: none,
  // one, or (rarely: a repeated STATUS) two.
  std::vector<InsState> addSentence(std::string_view body);
  // Closes the open epoch (end of file, or the bridge's own timeout with no STATUS).
  std::optional<InsState> flush();

  // kStale* flags as of INS time utime_us; lets the bridge report staleness when the INS has
  // gone silent and no epoch arrives at all.
  uint32_t staleFlags(int64_t utime_us) const;

  const InsAssemblerCounters& counters() const { return counters_; }
  // First error text per SentenceError (index by the enum), for logging each kind once.
  const std::string& firstError(SentenceError error) const;
  // Newest $PIXSE,ALGSTS / STATUS words (MSB << 32 | LSB), 0 until received.
  uint64_t algorithmStatus() const { return algorithm_status_; }
  uint64_t systemStatus() const { return system_status_; }

 private:
  enum Quantity { kHeading, kAttitude, kPosition, kDepth, kVelocity, kAltitude, kQuantityCount };

  struct Epoch {
    uint32_t kinds = 0;  // bit per ParsedSentence alternative index
    std::optional<HeadingSentence> heading;
    std::optional<AttitudeSentence> attitude;
    std::optional<PositionSentence> position;
    std::optional<SpeedSentence> speed;
    std::optional<TimeSentence> time;
    std::optional<AttitudeStdSentence> attitude_std;
    std::optional<PositionStdSentence> position_std;
    std::optional<SpeedStdSentence> speed_std;
    std::optional<DepthBelowTransducerSentence> altitude;
    std::optional<DateTimeSentence> date_time;
    bool has_status = false;
  };

  void store(const ParsedSentence& sentence);
  std::optional<InsState> closeEpoch(bool terminated);
  int64_t timeoutUs(Quantity quantity) const;

  InsAssemblerOptions options_;
  InsAssemblerCounters counters_;
  std::array<std::string, kSentenceErrorCount> first_errors_;
  Epoch epoch_;
  InsState held_;  // newest value of every quantity
  std::array<std::optional<int64_t>, kQuantityCount> last_received_utime_us_{};
  bool has_date_ = false;
  int64_t date_days_ = 0;          // days since 1970-01-01 of the reference time below
  int64_t date_time_of_day_us_ = 0;
  uint64_t algorithm_status_ = 0;
  uint64_t system_status_ = 0;
};

}  // namespace sss::ins
