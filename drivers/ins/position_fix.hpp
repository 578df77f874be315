// Absolute position fixes from NMEA 0183 files or streams: GNSS (a receiver on the vehicle's mast,
// valid only at the surface) and USBL (the ship's acoustic positioning, relayed by the modem or
// logged on the ship). A fix is a GGA sentence; its accuracy comes from the GST sentence of the same
// time when there is one, sent just before or after it (latitude and longitude 1-sigma in metres), else from the GGA's HDOP and
// fix quality (GNSS) or a configured sigma (USBL). The date comes from ZDA or RMC sentences; a file
// without them has times of day only, resolved against the mission's time (resolveFixDates).
// Talkers GP, GN, GL, GA, GB, GI, GQ and BD are satellite systems: GNSS; any other talker (a USBL
// system's own, "II", "U0".."U9") is USBL, unless the file is named with its source (gnss:/usbl:).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "pipeline/core/status.hpp"

namespace sss::ins {

enum class FixSource { kGnss, kUsbl };
const char* fixSourceName(FixSource source);  // "gnss", "usbl"
std::optional<FixSource> parseFixSourceName(std::string_view name);

struct FixReaderOptions {
  // GNSS horizontal sigma per axis = HDOP x this, by GGA fix quality (a receiver's user range error).
  double gnss_sigma_per_hdop_m = 2.5;       // quality 1 (autonomous), 3, 8
  double dgnss_sigma_per_hdop_m = 0.7;      // quality 2 (SBAS/DGPS)
  double rtk_fixed_sigma_per_hdop_m = 0.03; // quality 4
  double rtk_float_sigma_per_hdop_m = 0.3;  // quality 5
  double missing_hdop = 2.0;                // HDOP assumed when the field is empty
  // USBL GGA carries no accuracy: this per axis unless a GST gives one.
  double usbl_default_sigma_m = 2.0;
  double min_sigma_m = 0.02;                // no fix is trusted beyond this
};

struct PositionFix {
  int64_t utime_us = 0;          // valid when dated (resolveFixDates dates the others)
  bool dated = false;
  double seconds_of_day = 0.0;   // UTC, from the GGA
  double latitude_deg = 0.0;
  double longitude_deg = 0.0;
  double sigma_north_m = 0.0;
  double sigma_east_m = 0.0;
  bool sigma_from_gst = false;
  FixSource source = FixSource::kGnss;
  int quality = 0;
  int satellites = 0;
  double hdop = 0.0;
};

struct FixReaderCounters {
  uint64_t bytes = 0;
  uint64_t sentences = 0;         // framed and checksum-verified
  uint64_t rejected_sentences = 0;  // framing: bad checksum, overlong, control bytes, truncated
  uint64_t fixes = 0;             // GGA with a usable fix
  uint64_t no_fix = 0;            // GGA of quality 0 (none), 6 (dead reckoning) or 7 (manual)
  uint64_t malformed = 0;         // GGA/GST/ZDA/RMC whose fields do not parse
  uint64_t gst = 0;               // GST sentences matched to a GGA
  uint64_t date_sentences = 0;    // ZDA or RMC giving the date
  uint64_t other_sentences = 0;   // anything else (ignored)
};

// Reads fixes from bytes in any chunking (a file or a serial/UDP stream).
class PositionFixReader {
 public:
  // forced_source: the source of every fix regardless of the talker.
  explicit PositionFixReader(const FixReaderOptions& options = {},
                             std::optional<FixSource> forced_source = std::nullopt);
  ~PositionFixReader();
  PositionFixReader(const PositionFixReader&) = delete;
  PositionFixReader& operator=(const PositionFixReader&) = delete;

  void feed(std::string_view bytes);
  // The fixes complete so far (in input order), each with the sigma of a GST of its epoch sent just
  // before or just after it; the newest waits for its GST until the next fix or finish().
  std::vector<PositionFix> take();
  // End of input: completes the last sentence and returns the fixes not taken yet.
  std::vector<PositionFix> finish();

  const FixReaderCounters& counters() const { return counters_; }
  // The first problem met (a rejected or malformed sentence), naming the cause; empty: none.
  const std::string& firstProblem() const { return first_problem_; }

 private:
  struct Impl;
  void addSentence(const std::string& body);
  void release();  // the pending fix is complete
  void problem(const std::string& text);
  void countRejectedSentences();

  FixReaderOptions options_;
  std::optional<FixSource> forced_source_;
  Impl* impl_;
  FixReaderCounters counters_;
  std::string first_problem_;
};

// What readPositionFixFile found in a file: its fixes and the sentences it skipped.
struct FixFileContents {
  std::vector<PositionFix> fixes;
  FixReaderCounters counters;
  std::string first_problem;  // the first skipped sentence's cause; empty when none was
};

// Reads a whole file. `spec` is PATH, gnss:PATH or usbl:PATH (the source of every fix in it).
// Fails with the reason when the file cannot be read.
sss::core::Result<FixFileContents> readPositionFixFile(const std::string& spec, const FixReaderOptions& options);

// Dates the fixes that have a time of day only: each takes the day that puts it nearest to
// reference_utime_us (the mission's first navigation time), and a time of day running backwards by
// more than 12 h from one fix to the next is the next day. Dated fixes are left as they are.
void resolveFixDates(std::vector<PositionFix>& fixes, int64_t reference_utime_us);

// The sentences of one dated fix, CR/LF terminated with checksums: ZDA (date and time), GGA
// (position to 1e-7 minute, quality, satellites, HDOP) and GST (its sigmas), all from `talker`.
std::string encodePositionFix(const PositionFix& fix, std::string_view talker = "GP");

// A navigation solution as NMEA for tools that take a nav stream: ZDA, GGA (quality 6, estimated:
// never a fix; antenna altitude = -depth) and HDT (true heading, 0.01 deg).
std::string encodeNavigationNmea(int64_t utime_us, double latitude_deg, double longitude_deg, double depth_m,
                                 double heading_rad, std::string_view talker = "IN");

}  // namespace sss::ins
