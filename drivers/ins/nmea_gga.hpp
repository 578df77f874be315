// NMEA GGA (GPS fix data) sentences, e.g. "$GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,*47":
// UTC time of day, latitude/longitude (ddmm.mmmm / dddmm.mmmm with hemisphere), fix quality,
// satellites, HDOP, antenna altitude. Any talker ($GP, $GN, $IN, ...). Used where a sonar file
// carries its positions as NMEA (JSF message 2002) and, later, for GNSS fixes.
#pragma once

#include <optional>
#include <string>
#include <string_view>

namespace sss::ins {

struct GgaFix {
  double seconds_of_day = 0.0;  // UTC
  double latitude_deg = 0.0;
  double longitude_deg = 0.0;
  int quality = 0;              // 0 no fix, 1 GPS, 2 DGPS, 4 RTK fixed, 5 RTK float, 6 dead reckoning
  int satellites = 0;
  double hdop = 0.0;
  double altitude_m = 0.0;      // antenna above mean sea level
};

// The fix in one GGA sentence (with or without '$', CR/LF and '*hh'; a checksum present must
// match); nullopt for another sentence, a malformed one, or quality 0 (no fix).
std::optional<GgaFix> parseGga(const std::string& sentence);

// A position from GGA, or from RMC or GLL with status A (valid), whichever the sentence is: a sonar
// file's NMEA feed may carry only one of them. RMC and GLL carry no quality, satellites or HDOP:
// quality 1, the rest 0. nullopt for other sentences, malformed ones, no fix or status V.
std::optional<GgaFix> parseNmeaPosition(const std::string& sentence);

// hhmmss[.ss] as seconds of the day; false when it is not a time of day.
bool parseNmeaTimeOfDay(std::string_view text, double& seconds_of_day);

}  // namespace sss::ins
