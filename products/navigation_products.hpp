// The corrected navigation and the tie report as files other tools read: navigation.csv and
// navigation.nmea (GGA + HDT) per ping, loop_closures.csv (every closure, its decision and its offset
// before and after the solve). Written by sss-process and by the live optimiser at the end of a
// mission, from the optimiser engine's state.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "pipeline/core/mission_origin.hpp"
#include "pipeline/optimiser/optimiser_engine.hpp"

namespace sss::products {

// loop_closures.csv: per closure the matcher's relative pose and covariance, the optimiser's
// decision and why, the subframe centres under the final estimate, and its offset from DR's and
// from the estimate's relative pose (along, across, depth, heading: the tie report).
sss::core::Status writeTieReportCsv(const std::string& path, const sss::optimiser::OptimiserEngine& engine);

// dir/navigation.csv (UTC time, latitude, longitude, north, east, depth, heading, pitch, roll,
// altitude, horizontal sigma, source DR or SLAM, one row per pose) and, with an origin,
// dir/navigation.nmea (GGA + HDT per pose). altitude_m[i] goes with poses[i] (-1 when absent).
sss::core::Status writeNavigationFiles(const std::string& dir, const std::vector<sss::optimiser::StampedPose>& poses,
                                       const sss::optimiser::OptimiserEngine& engine,
                                       const std::optional<sss::core::MissionOrigin>& origin,
                                       const std::vector<double>& altitude_m);

}  // namespace sss::products
