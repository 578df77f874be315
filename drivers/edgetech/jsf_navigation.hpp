// JSF navigation messages a 2205 may carry besides sonar data: 2002 NMEA string, 2020 pitch/roll,
// 2080 DVL, 2090 situation, 2091 situation v2. Decoded into one record with optional fields and
// our conventions (radians, heading clockwise from north, pitch bow up +, roll starboard down +).
// Layouts: EdgeTech JSF description 0023492 as transcribed in MB-System's mbsys_jstar2.h.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>

#include "drivers/edgetech/jsf_format.hpp"

namespace sss::edgetech {

struct JsfNavigationRecord {
  uint16_t message_type = 0;
  int64_t time_us = 0;                   // sonar clock
  std::optional<std::string> nmea;       // 2002: the sentence as sent
  std::optional<double> latitude_deg;    // 2090/2091
  std::optional<double> longitude_deg;
  std::optional<double> depth_m;         // 2080 (decimetres), 2090/2091
  std::optional<double> altitude_m;      // 2080 (mean of valid beam ranges), 2091
  std::optional<double> heading_rad;     // 2020, 2080, 2090, 2091
  std::optional<double> pitch_rad;
  std::optional<double> roll_rad;
  std::optional<double> heave_m;         // 2020, 2091 (positive down)
  std::optional<double> velocity_north_m_s;  // 2090 (NED), 2091 when its velocities are north/east
  std::optional<double> velocity_east_m_s;
  std::optional<double> velocity_down_m_s;
  std::optional<double> velocity_forward_m_s;    // 2080 ship coordinates, 2091 forward/starboard
  std::optional<double> velocity_starboard_m_s;
};

// True for the types decodeNavigation() understands.
bool isNavigationType(uint16_t message_type);
// Decodes a navigation message body (after the 16-byte header); fails when it is too short or not
// a navigation type.
sss::core::Result<JsfNavigationRecord> decodeNavigation(const JsfMessageHeader& header, const uint8_t* body,
                                                        size_t body_size);

}  // namespace sss::edgetech
