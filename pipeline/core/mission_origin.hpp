// The mission origin: the point on the WGS-84 ellipsoid where a mission's local NED frame is
// tangent. It is configured (mission.origin_latitude_deg / origin_longitude_deg, an override) or,
// when not, taken from the data: the first valid position of the mission (the INS's first fix,
// the sonar file's embedded navigation). There is no built-in default coordinate: a default
// somewhere on Earth puts every other mission's frame hundreds of km away from its survey.
// The origin travels with everything in that frame: in SSS_NAV, in the header line of every TUM
// file, in summary.json and beside every geo-referenced product.
#pragma once

#include <optional>
#include <string>

#include "pipeline/core/config.hpp"
#include "pipeline/core/state_file.hpp"

namespace sss::core {

struct MissionOrigin {
  double latitude_deg = 0.0;
  double longitude_deg = 0.0;
};

// Where the origin in use came from (logged and written to summary.json).
enum class OriginSource {
  kConfigured,      // mission.origin_* in the configuration
  kFirstFix,        // the first valid position of the navigation
  kResumed,         // kept from an earlier run of a live process (its state directory)
  kFromNavigation,  // carried by the SSS_NAV messages (set by the INS bridge)
};
const char* originSourceName(OriginSource source);

// A usable origin: finite, latitude in [-90, 90] (not at a pole: the tangent plane's north is
// undefined there), longitude in [-180, 180].
bool isValidOrigin(double latitude_deg, double longitude_deg);
// A position that can found a mission frame: a valid origin and not exactly 0 N 0 E, which INSs
// and sonar files write before they have a fix.
bool isFirstFixCandidate(double latitude_deg, double longitude_deg);

// Reads mission.origin_latitude_deg and origin_longitude_deg: both (the override) or neither
// (nullopt: the origin comes from the data); one alone is a configuration problem.
std::optional<MissionOrigin> readMissionOrigin(ConfigSection& mission);

// The comment line that records an origin in text products (TUM files, YAML headers):
// "# origin_latitude_deg 59.350000000 origin_longitude_deg 18.070000000" (9 decimals: < 0.1 mm).
std::string originCommentLine(const MissionOrigin& origin);
// The same as YAML keys, for the geo-references beside rasters (heightmaps, mosaics):
// "origin_latitude_deg: 59.35\norigin_longitude_deg: 18.07\n" (15 significant digits).
std::string originYamlKeys(const MissionOrigin& origin);
// The origin in such a line (with or without the leading '#'); nullopt when the line holds none.
std::optional<MissionOrigin> parseOriginCommentLine(const std::string& line);

// A live process keeps the origin it chose in its state directory, so that a restart mid-mission
// keeps the frame: file `origin` of format "sss-origin/1" with keys latitude_deg, longitude_deg.
Status writeOriginState(const std::string& path, const MissionOrigin& origin);
Result<MissionOrigin> readOriginState(const std::string& path);

}  // namespace sss::core
