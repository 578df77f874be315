// Position fixes from NMEA GGA + GST + ZDA/RMC, see position_fix.hpp.
#include "drivers/ins/position_fix.hpp"

#include "drivers/ins/ixblue_nmea.hpp"
#include "drivers/ins/nmea_gga.hpp"
#include "drivers/ins/nmea_stream_parser.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <iterator>
#include <map>

namespace sss::ins {

namespace {

constexpr double kSecondsPerDay = 86400.0;

bool parseNumber(std::string_view text, double& value) {
  if (text.empty()) return false;
  const std::string copy(text);
  char* end = nullptr;
  value = std::strtod(copy.c_str(), &end);
  return end == copy.c_str() + copy.size() && std::isfinite(value);
}

// Days since 1970-01-01 of a Gregorian date; nullopt when it is not a date.
std::optional<int64_t> daysSinceEpoch(int year, int month, int day) {
  if (year < 1970 || year > 2200 || month < 1 || month > 12 || day < 1 || day > 31) return std::nullopt;
  std::tm tm{};
  tm.tm_year = year - 1900;
  tm.tm_mon = month - 1;
  tm.tm_mday = day;
  const time_t t = timegm(&tm);
  if (t < 0 || tm.tm_mday != day) return std::nullopt;  // 31 April normalises to 1 May: refused
  return static_cast<int64_t>(t) / 86400;
}

bool isSatelliteTalker(std::string_view talker) {
  static const char* const kTalkers[] = {"GP", "GN", "GL", "GA", "GB", "GI", "GQ", "BD"};
  for (const char* t : kTalkers)
    if (talker == t) return true;
  return false;
}

// Key of a time of day to the millisecond, to pair a GGA with the GST of the same epoch.
int64_t epochKey(double seconds_of_day) { return static_cast<int64_t>(std::llround(seconds_of_day * 1000.0)); }

}  // namespace

const char* fixSourceName(FixSource source) { return source == FixSource::kUsbl ? "usbl" : "gnss"; }

std::optional<FixSource> parseFixSourceName(std::string_view name) {
  if (name == "gnss") return FixSource::kGnss;
  if (name == "usbl") return FixSource::kUsbl;
  return std::nullopt;
}

struct PositionFixReader::Impl {
  NmeaStreamParser framing;
  std::vector<PositionFix> released;     // complete: not waiting for a GST any more
  std::optional<PositionFix> pending;    // the newest GGA, until its GST or the next fix
  std::optional<std::pair<int64_t, std::pair<double, double>>> last_gst;  // epoch, (north, east) sigma
  std::optional<int64_t> date_days;  // of the newest ZDA/RMC
  double date_seconds_of_day = 0.0;
};

namespace {
// A GST's sigma on the fix of its epoch.
void applyGst(PositionFix& fix, const std::pair<double, double>& sigma) {
  fix.sigma_north_m = sigma.first;
  fix.sigma_east_m = sigma.second;
  fix.sigma_from_gst = true;
}
}  // namespace

void PositionFixReader::release() {
  if (!impl_->pending) return;
  PositionFix& fix = *impl_->pending;
  fix.sigma_north_m = std::max(fix.sigma_north_m, options_.min_sigma_m);
  fix.sigma_east_m = std::max(fix.sigma_east_m, options_.min_sigma_m);
  if (fix.sigma_from_gst) ++counters_.gst;
  impl_->released.push_back(fix);
  impl_->pending.reset();
}

std::vector<PositionFix> PositionFixReader::take() {
  std::vector<PositionFix> out;
  out.swap(impl_->released);
  return out;
}

PositionFixReader::PositionFixReader(const FixReaderOptions& options, std::optional<FixSource> forced_source)
    : options_(options), forced_source_(forced_source), impl_(new Impl) {}

PositionFixReader::~PositionFixReader() { delete impl_; }

void PositionFixReader::problem(const std::string& text) {
  if (first_problem_.empty()) first_problem_ = text;
}

void PositionFixReader::feed(std::string_view bytes) {
  counters_.bytes += bytes.size();
  std::vector<std::string> sentences;
  impl_->framing.feed(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size(), sentences);
  for (const std::string& s : sentences) addSentence(s);
  countRejectedSentences();
}

// Sentences the framing refused, counted, and the first refusal's cause kept as the first problem
// (a live stream is never finished: it must say so as it goes).
void PositionFixReader::countRejectedSentences() {
  counters_.rejected_sentences = static_cast<uint64_t>(impl_->framing.rejectedSentences());
  if (counters_.rejected_sentences == 0 || !first_problem_.empty()) return;
  const NmeaStreamFirstErrors& e = impl_->framing.firstErrors();
  for (const std::string* text : {&e.bad_checksum, &e.missing_checksum, &e.overlong, &e.bad_character, &e.truncated})
    if (!text->empty()) {
      problem(*text);
      break;
    }
}

void PositionFixReader::addSentence(const std::string& body) {
  ++counters_.sentences;
  const std::vector<std::string_view> fields = splitFields(body);
  if (fields.empty() || fields[0].size() != 5) {
    ++counters_.other_sentences;
    return;
  }
  const std::string_view talker = fields[0].substr(0, 2);
  const std::string_view type = fields[0].substr(2);
  auto malformed = [&](const char* what) {
    ++counters_.malformed;
    problem(std::string("malformed ") + what + " sentence '" + body.substr(0, 80) + "'");
  };
  if (type == "GGA") {
    const std::optional<GgaFix> gga = parseGga(body);
    if (!gga) {
      // Quality 0 (no fix) is a valid sentence that says so; anything else did not parse.
      double quality = -1.0;
      if (fields.size() >= 7 && parseNumber(fields[6], quality) && quality == 0.0) {
        ++counters_.no_fix;
      } else {
        malformed("GGA");
      }
      return;
    }
    if (gga->quality == 6 || gga->quality == 7) {  // the receiver's own dead reckoning, or typed in
      ++counters_.no_fix;
      return;
    }
    PositionFix fix;
    fix.seconds_of_day = gga->seconds_of_day;
    fix.latitude_deg = gga->latitude_deg;
    fix.longitude_deg = gga->longitude_deg;
    fix.quality = gga->quality;
    fix.satellites = gga->satellites;
    fix.hdop = gga->hdop;
    fix.source = forced_source_ ? *forced_source_ : (isSatelliteTalker(talker) ? FixSource::kGnss : FixSource::kUsbl);
    if (fix.source == FixSource::kUsbl) {
      fix.sigma_north_m = fix.sigma_east_m = options_.usbl_default_sigma_m;
    } else {
      const double per_hdop = fix.quality == 2   ? options_.dgnss_sigma_per_hdop_m
                              : fix.quality == 4 ? options_.rtk_fixed_sigma_per_hdop_m
                              : fix.quality == 5 ? options_.rtk_float_sigma_per_hdop_m
                                                 : options_.gnss_sigma_per_hdop_m;
      const double hdop = fix.hdop > 0.0 ? fix.hdop : options_.missing_hdop;
      fix.sigma_north_m = fix.sigma_east_m = per_hdop * hdop;
    }
    if (impl_->date_days) {
      int64_t day = *impl_->date_days;
      if (fix.seconds_of_day < impl_->date_seconds_of_day - 0.5 * kSecondsPerDay) ++day;  // past midnight
      fix.utime_us = static_cast<int64_t>(std::llround((static_cast<double>(day) * kSecondsPerDay + fix.seconds_of_day) * 1e6));
      fix.dated = true;
    }
    // The GST of this epoch may have come just before it; otherwise it may follow.
    if (impl_->last_gst && impl_->last_gst->first == epochKey(fix.seconds_of_day)) applyGst(fix, impl_->last_gst->second);
    release();
    impl_->pending = fix;
    ++counters_.fixes;
  } else if (type == "GST") {
    // GST,time,rms,semi-major,semi-minor,orientation,sigma_lat,sigma_lon,sigma_alt
    double seconds = 0.0, sigma_lat = 0.0, sigma_lon = 0.0;
    if (fields.size() < 8 || !parseNmeaTimeOfDay(fields[1], seconds) || !parseNumber(fields[6], sigma_lat) ||
        !parseNumber(fields[7], sigma_lon) || !(sigma_lat > 0.0) || !(sigma_lon > 0.0)) {
      malformed("GST");
      return;
    }
    impl_->last_gst = std::make_pair(epochKey(seconds), std::make_pair(sigma_lat, sigma_lon));
    if (impl_->pending && epochKey(impl_->pending->seconds_of_day) == epochKey(seconds)) {
      applyGst(*impl_->pending, impl_->last_gst->second);
      release();
    }
  } else if (type == "ZDA" || type == "RMC") {
    // ZDA,time,dd,mm,yyyy,...   RMC,time,status,lat,N,lon,E,sog,cog,ddmmyy,...
    double seconds = 0.0;
    std::optional<int64_t> days;
    if (fields.size() >= 5 && type == "ZDA" && parseNmeaTimeOfDay(fields[1], seconds)) {
      double dd = 0, mm = 0, yyyy = 0;
      // Range-checked before the casts: a corrupt field holds any number (fuzzed: a day of 4e69).
      if (parseNumber(fields[2], dd) && parseNumber(fields[3], mm) && parseNumber(fields[4], yyyy) && dd >= 1.0 &&
          dd <= 31.0 && mm >= 1.0 && mm <= 12.0 && yyyy >= 1970.0 && yyyy <= 2200.0)
        days = daysSinceEpoch(static_cast<int>(yyyy), static_cast<int>(mm), static_cast<int>(dd));
    } else if (fields.size() >= 10 && type == "RMC" && parseNmeaTimeOfDay(fields[1], seconds) && fields[9].size() == 6) {
      double ddmmyy = 0;
      if (parseNumber(fields[9], ddmmyy) && ddmmyy >= 0.0 && ddmmyy < 1e6) {
        const int value = static_cast<int>(ddmmyy);
        days = daysSinceEpoch(2000 + value % 100, (value / 100) % 100, value / 10000);
      }
    }
    if (!days) {
      malformed(type == "ZDA" ? "ZDA" : "RMC");
      return;
    }
    impl_->date_days = days;
    impl_->date_seconds_of_day = seconds;
    ++counters_.date_sentences;
  } else {
    ++counters_.other_sentences;
  }
}

std::vector<PositionFix> PositionFixReader::finish() {
  std::vector<std::string> sentences;
  impl_->framing.flush(sentences);
  for (const std::string& s : sentences) addSentence(s);
  countRejectedSentences();
  release();
  return take();
}

sss::core::Result<FixFileContents> readPositionFixFile(const std::string& spec, const FixReaderOptions& options) {
  std::string path = spec;
  std::optional<FixSource> source;
  for (const char* prefix : {"gnss:", "usbl:"}) {
    if (spec.rfind(prefix, 0) == 0) {
      source = parseFixSourceName(std::string_view(prefix, 4));
      path = spec.substr(5);
    }
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    return sss::core::Status::error("cannot read the fix file " + path + " (give PATH, gnss:PATH or usbl:PATH)");
  }
  PositionFixReader reader(options, source);
  std::string chunk(64 * 1024, '\0');
  while (in) {
    in.read(chunk.data(), static_cast<std::streamsize>(chunk.size()));
    const std::streamsize n = in.gcount();
    if (n > 0) reader.feed(std::string_view(chunk.data(), static_cast<size_t>(n)));
  }
  FixFileContents contents;
  contents.fixes = reader.finish();
  contents.counters = reader.counters();
  contents.first_problem = reader.firstProblem();
  return contents;
}

void resolveFixDates(std::vector<PositionFix>& fixes, int64_t reference_utime_us) {
  const double reference_s = 1e-6 * static_cast<double>(reference_utime_us);
  const double reference_day = std::floor(reference_s / kSecondsPerDay);
  std::optional<double> previous_s;  // time of the previous undated fix once dated
  for (PositionFix& fix : fixes) {
    if (fix.dated) {
      previous_s.reset();
      continue;
    }
    double t = 0.0;
    if (previous_s) {
      // Continues from the previous fix: the same day, or the next when the time of day wrapped.
      const double day = std::floor(*previous_s / kSecondsPerDay);
      t = day * kSecondsPerDay + fix.seconds_of_day;
      if (t < *previous_s - 0.5 * kSecondsPerDay) t += kSecondsPerDay;
    } else {
      // The day that puts the first fix nearest the reference.
      double best = 0.0;
      for (double d = reference_day - 1.0; d <= reference_day + 1.0; d += 1.0) {
        const double candidate = d * kSecondsPerDay + fix.seconds_of_day;
        if (d == reference_day - 1.0 || std::abs(candidate - reference_s) < std::abs(best - reference_s)) best = candidate;
      }
      t = best;
    }
    fix.utime_us = static_cast<int64_t>(std::llround(t * 1e6));
    fix.dated = true;
    previous_s = t;
  }
}

namespace {

// hhmmss.ss of a utime and its calendar date (UTC).
struct NmeaTime {
  char text[16];
  std::tm tm{};
};
NmeaTime nmeaTime(int64_t utime_us) {
  NmeaTime out;
  const int64_t seconds = utime_us >= 0 ? utime_us / 1000000 : (utime_us - 999999) / 1000000;
  const double fraction_s = 1e-6 * static_cast<double>(utime_us - seconds * 1000000);
  const time_t t = static_cast<time_t>(seconds);
  gmtime_r(&t, &out.tm);
  std::snprintf(out.text, sizeof out.text, "%02d%02d%05.2f", out.tm.tm_hour, out.tm.tm_min,
                std::min(out.tm.tm_sec + fraction_s, 59.99));
  return out;
}

std::string nmeaSentence(const std::string& body) {
  char tail[8];
  std::snprintf(tail, sizeof tail, "*%02X\r\n", nmeaChecksum(body));
  return "$" + body + tail;
}

std::string zdaSentence(const std::string& talker, const NmeaTime& time) {
  char body[96];
  std::snprintf(body, sizeof body, "%sZDA,%s,%02d,%02d,%04d,00,00", talker.c_str(), time.text, time.tm.tm_mday,
                time.tm.tm_mon + 1, time.tm.tm_year + 1900);
  return nmeaSentence(body);
}

// GGA with latitude and longitude to 1e-7 minute (0.2 mm).
std::string ggaSentence(const std::string& talker, const NmeaTime& time, double latitude_deg, double longitude_deg,
                        int quality, int satellites, double hdop, double altitude_m) {
  // Degrees and minutes rounded as printed, so 59.99999999' never prints as 60'.
  auto split = [](double value, double& degrees, double& minutes) {
    degrees = std::floor(value);
    minutes = std::round((value - degrees) * 60.0 * 1e7) / 1e7;
    if (minutes >= 60.0) {
      degrees += 1.0;
      minutes = 0.0;
    }
  };
  double lat_degrees = 0, lat_minutes = 0, lon_degrees = 0, lon_minutes = 0;
  split(std::abs(latitude_deg), lat_degrees, lat_minutes);
  split(std::abs(longitude_deg), lon_degrees, lon_minutes);
  char body[160];
  std::snprintf(body, sizeof body, "%sGGA,%s,%02d%010.7f,%c,%03d%010.7f,%c,%d,%02d,%.1f,%.2f,M,0.0,M,,", talker.c_str(),
                time.text, static_cast<int>(lat_degrees), lat_minutes, latitude_deg < 0 ? 'S' : 'N',
                static_cast<int>(lon_degrees), lon_minutes, longitude_deg < 0 ? 'W' : 'E', quality, satellites, hdop,
                altitude_m);
  return nmeaSentence(body);
}

}  // namespace

std::string encodePositionFix(const PositionFix& fix, std::string_view talker) {
  const NmeaTime time = nmeaTime(fix.utime_us);
  const std::string t2(talker.substr(0, 2));
  std::string out = zdaSentence(t2, time);
  out += ggaSentence(t2, time, fix.latitude_deg, fix.longitude_deg, fix.quality, fix.satellites, fix.hdop, 0.0);
  const double rms = std::hypot(fix.sigma_north_m, fix.sigma_east_m);
  char body[160];
  std::snprintf(body, sizeof body, "%sGST,%s,%.3f,%.3f,%.3f,0.0,%.3f,%.3f,%.3f", t2.c_str(), time.text, rms,
                std::max(fix.sigma_north_m, fix.sigma_east_m), std::min(fix.sigma_north_m, fix.sigma_east_m),
                fix.sigma_north_m, fix.sigma_east_m, 2.0 * std::max(fix.sigma_north_m, fix.sigma_east_m));
  out += nmeaSentence(body);
  return out;
}

std::string encodeNavigationNmea(int64_t utime_us, double latitude_deg, double longitude_deg, double depth_m,
                                 double heading_rad, std::string_view talker) {
  const NmeaTime time = nmeaTime(utime_us);
  const std::string t2(talker.substr(0, 2));
  std::string out = zdaSentence(t2, time);
  // Quality 6: an estimated (dead-reckoned) position, never taken for a fix (not even by this reader).
  out += ggaSentence(t2, time, latitude_deg, longitude_deg, 6, 0, 0.0, -depth_m);
  double heading_deg = std::fmod(heading_rad * 180.0 / M_PI, 360.0);
  if (heading_deg < 0.0) heading_deg += 360.0;
  if (heading_deg >= 359.995) heading_deg = 0.0;  // as printed with 2 decimals
  char body[64];
  std::snprintf(body, sizeof body, "%sHDT,%.2f,T", t2.c_str(), heading_deg);
  out += nmeaSentence(body);
  return out;
}

}  // namespace sss::ins
