// Copies of the input sonar files (JSF, XTF) with every ping's navigation fields replaced by the
// corrected (SLAM) pose and every other byte unchanged, so that the mosaicking and target-picking
// software surveyors already use re-mosaics with the better navigation.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>

#include "drivers/xtf/xtf_reader.hpp"
#include "pipeline/core/status.hpp"

namespace sss::products {

// The navigation to write into a ping, in the file's units: latitude/longitude degrees, or the
// file's projected grid (XTF NavUnits 0, JSF metric coordinate units).
struct PingNavigation {
  bool projected = false;
  double latitude_deg = 0.0, longitude_deg = 0.0;
  double easting_m = 0.0, northing_m = 0.0;
  double depth_m = 0.0;
  double heading_rad = 0.0, pitch_rad = 0.0, roll_rad = 0.0;
};
// The corrected navigation at a ping's time (the time the project's own reader gives the ping);
// nullopt: none there (the ping is left as it was and counted).
using NavigationAt = std::function<std::optional<PingNavigation>(int64_t utime_us)>;

struct CorrectedCopyCounters {
  uint64_t records_corrected = 0;  // JSF type 80 messages (one per channel) or XTF sonar packets
  uint64_t records_without_pose = 0;  // pings left with their recorded navigation (no pose at their time)
  uint64_t records_without_position_field = 0;  // JSF message 82: no position to write (left as recorded)
};

// Copies in_path to out_path, then rewrites the navigation of every ping the project's reader
// finds (JSF type 80 messages; XTF sonar packets of the side-scan pair read). Fails with a message
// when a file cannot be read or written; out_path is removed then. laybacks_applied: the run moved
// towfish positions back by their layback (summary navigation.laybacks_applied > 0); every record
// whose layback the reader hands on (XTF: read with the run's reader options; JSF: the run applied
// the JSF layback) then gets layback 0 in the copy, since the position written is the fish's and a
// reader following Isis would move it back a second time.
sss::core::Status writeCorrectedJsf(const std::string& in_path, const std::string& out_path,
                                    const NavigationAt& navigation, CorrectedCopyCounters& counters,
                                    bool laybacks_applied = false);
sss::core::Status writeCorrectedXtf(const std::string& in_path, const std::string& out_path,
                                    const NavigationAt& navigation, CorrectedCopyCounters& counters,
                                    const sss::xtf::XtfReaderOptions& reader_options = {},
                                    bool laybacks_applied = false);

}  // namespace sss::products
