// Mission origin helpers, see mission_origin.hpp.
#include "pipeline/core/mission_origin.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>

namespace sss::core {

const char* originSourceName(OriginSource source) {
  switch (source) {
    case OriginSource::kConfigured: return "configured";
    case OriginSource::kFirstFix: return "first_fix";
    case OriginSource::kResumed: return "resumed";
    case OriginSource::kFromNavigation: return "from_navigation";
  }
  return "unknown";
}

bool isValidOrigin(double latitude_deg, double longitude_deg) {
  return std::isfinite(latitude_deg) && std::isfinite(longitude_deg) && std::abs(latitude_deg) < 90.0 &&
         std::abs(longitude_deg) <= 180.0;
}

bool isFirstFixCandidate(double latitude_deg, double longitude_deg) {
  return isValidOrigin(latitude_deg, longitude_deg) && !(latitude_deg == 0.0 && longitude_deg == 0.0);
}

std::optional<MissionOrigin> readMissionOrigin(ConfigSection& mission) {
  const bool has_latitude = mission.has("origin_latitude_deg");
  const bool has_longitude = mission.has("origin_longitude_deg");
  MissionOrigin origin;
  mission.optional("origin_latitude_deg", origin.latitude_deg, {inRange(-89.999, 89.999)});
  mission.optional("origin_longitude_deg", origin.longitude_deg, {inRange(-180.0, 180.0)});
  if (has_latitude != has_longitude) {
    const char* missing = has_latitude ? "origin_longitude_deg" : "origin_latitude_deg";
    mission.addProblem(missing, "(absent)",
                       "give both origin_latitude_deg and origin_longitude_deg, or neither (the origin is then "
                       "the mission's first valid position)");
    return std::nullopt;
  }
  if (!has_latitude) return std::nullopt;
  return origin;
}

std::string originCommentLine(const MissionOrigin& origin) {
  char line[128];
  std::snprintf(line, sizeof line, "# origin_latitude_deg %.9f origin_longitude_deg %.9f", origin.latitude_deg,
                origin.longitude_deg);
  return line;
}

std::string originYamlKeys(const MissionOrigin& origin) {
  char keys[128];
  std::snprintf(keys, sizeof keys, "origin_latitude_deg: %.15g\norigin_longitude_deg: %.15g\n", origin.latitude_deg,
                origin.longitude_deg);
  return keys;
}

std::optional<MissionOrigin> parseOriginCommentLine(const std::string& line) {
  std::istringstream in(line);
  std::string word;
  std::optional<double> latitude, longitude;
  while (in >> word) {
    if (word != "origin_latitude_deg" && word != "origin_longitude_deg") continue;
    std::string value;
    if (!(in >> value)) break;
    char* end = nullptr;
    const double number = std::strtod(value.c_str(), &end);
    if (end == value.c_str() || *end != '\0') return std::nullopt;
    (word == "origin_latitude_deg" ? latitude : longitude) = number;
  }
  if (!latitude || !longitude || !isValidOrigin(*latitude, *longitude)) return std::nullopt;
  return MissionOrigin{*latitude, *longitude};
}

namespace {
constexpr const char* kOriginStateFormat = "sss-origin/1";
}

Status writeOriginState(const std::string& path, const MissionOrigin& origin) {
  char latitude[32], longitude[32];
  std::snprintf(latitude, sizeof latitude, "%.9f", origin.latitude_deg);
  std::snprintf(longitude, sizeof longitude, "%.9f", origin.longitude_deg);
  return writeStateFile(path, kOriginStateFormat, {{"latitude_deg", latitude}, {"longitude_deg", longitude}});
}

Result<MissionOrigin> readOriginState(const std::string& path) {
  const Result<StateValues> read = readStateFile(path, kOriginStateFormat);
  if (!read) return read.status();
  const StateValues& values = read.value();
  MissionOrigin origin;
  if (!stateNumber(values, "latitude_deg", origin.latitude_deg) ||
      !stateNumber(values, "longitude_deg", origin.longitude_deg) ||
      !isValidOrigin(origin.latitude_deg, origin.longitude_deg)) {
    return Status::error(path + ": no valid latitude_deg / longitude_deg");
  }
  return origin;
}

}  // namespace sss::core
