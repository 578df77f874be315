// sss-ins-bridge's state across restarts. See bridge_state.hpp.
#include "drivers/ins/bridge_state.hpp"

#include <unistd.h>

#include <cstdio>
#include <optional>

#include "pipeline/core/mission_origin.hpp"
#include "pipeline/core/state_file.hpp"

namespace sss::ins {
namespace {

constexpr const char* kOdometerFormat = "sss-ins-bridge odometer 1";

std::string formatted(const char* format, double value) {
  char text[40];
  std::snprintf(text, sizeof text, format, value);
  return text;
}

// Exact in the state file; degrees to ~1 cm and metres to 0.1 m in the log.
std::string number(double value) { return formatted("%.17g", value); }
std::string metres(double value) { return formatted("%.1f", value); }
std::string degrees(double value) { return formatted("%.7f", value); }

}  // namespace

BridgeStateStore::BridgeStateStore(const std::string& state_directory) {
  if (state_directory.empty()) return;
  odometer_path_ = state_directory + "/odometer";
  origin_path_ = state_directory + "/origin";
}

void BridgeStateStore::restore(InsBridge& bridge, BridgeStateLog& log) {
  if (!odometer_path_.empty() && access(odometer_path_.c_str(), F_OK) == 0) {
    const sss::core::Result<sss::core::StateValues> read = sss::core::readStateFile(odometer_path_, kOdometerFormat);
    const sss::core::StateValues values = read ? read.value() : sss::core::StateValues{};
    OdometerState state;
    long long utime_us = 0;
    const bool ok = read && sss::core::stateNumber(values, "distance_travelled_m", state.distance_travelled_m) &&
                    sss::core::stateInteger(values, "utime_us", utime_us) &&
                    sss::core::stateNumber(values, "north_m", state.position_ned_m.x()) &&
                    sss::core::stateNumber(values, "east_m", state.position_ned_m.y()) &&
                    sss::core::stateNumber(values, "down_m", state.position_ned_m.z()) &&
                    state.distance_travelled_m >= 0.0;
    if (ok) {
      state.utime_us = utime_us;
      bridge.resumeOdometer(state);
      saved_odometer_utime_us_ = state.utime_us;
      log.info.push_back("resumed the odometer from " + odometer_path_ + ": " + metres(state.distance_travelled_m) +
                         " m travelled");
    } else {
      log.errors.push_back("odometer not resumed, distance travelled starts from 0 (the optimiser bridges the reset): " +
                           (read ? odometer_path_ + ": a value is missing or invalid" : read.message()));
    }
  }
  if (bridge.origin()) {
    log.info.push_back("mission origin (configured): " + degrees(bridge.origin()->latitude_deg) + " " +
                       degrees(bridge.origin()->longitude_deg));
  } else if (!origin_path_.empty() && access(origin_path_.c_str(), F_OK) == 0) {
    if (const sss::core::Result<sss::core::MissionOrigin> kept = sss::core::readOriginState(origin_path_)) {
      bridge.resumeOrigin(*kept);
      log.info.push_back("mission origin kept from " + origin_path_ + ": " + degrees(kept->latitude_deg) + " " +
                         degrees(kept->longitude_deg) + " (delete the file to start a new mission frame)");
    } else {
      log.errors.push_back("mission origin not resumed, the first fix sets a new one: " + kept.message());
    }
  }
  origin_said_ = bridge.origin().has_value();
}

void BridgeStateStore::noteOrigin(const InsBridge& bridge, BridgeStateLog& log) {
  if (origin_said_ || !bridge.origin()) return;
  origin_said_ = true;
  const sss::core::MissionOrigin origin = *bridge.origin();
  log.info.push_back("mission origin (first INS fix): " + degrees(origin.latitude_deg) + " " +
                     degrees(origin.longitude_deg));
  if (origin_path_.empty()) return;
  if (const sss::core::Status saved = sss::core::writeOriginState(origin_path_, origin); !saved) {
    log.errors.push_back("mission origin not saved (a restart would choose a new one): " + saved.message);
  }
}

void BridgeStateStore::saveOdometerIfMoved(const InsBridge& bridge, BridgeStateLog& log) {
  const OdometerState state = bridge.odometer();
  if (odometer_path_.empty() || state.utime_us == saved_odometer_utime_us_) return;
  const sss::core::Status saved = sss::core::writeStateFile(odometer_path_, kOdometerFormat,
                                                            {{"distance_travelled_m", number(state.distance_travelled_m)},
                                                             {"utime_us", std::to_string(state.utime_us)},
                                                             {"north_m", number(state.position_ned_m.x())},
                                                             {"east_m", number(state.position_ned_m.y())},
                                                             {"down_m", number(state.position_ned_m.z())}},
                                                            sss::core::Durability::kSurvivesProcessKill);
  if (saved) {
    saved_odometer_utime_us_ = state.utime_us;
  } else if (odometer_write_failures_++ == 0) {
    log.errors.push_back("odometer not saved (counted from now on): " + saved.message);
  }
}

}  // namespace sss::ins
