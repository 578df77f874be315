// The correction the vehicle is given, moved towards the graph's at a bounded rate. When a fix (or a
// closure) is accepted the graph's correction of the present pose can jump by metres; a controller
// fed that jump at once would steer hard for it. The published correction instead slews towards the
// new one at max_rate_m_s (and max_heading_rate_rad_s), its covariance widened by what is still to
// go, and the jump and the remaining lag are reported (SSS_STATUS). Pure C++, no middleware.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "pipeline/core/config.hpp"
#include "pipeline/optimiser/pose_graph.hpp"

namespace sss::optimiser {

struct CorrectionSlewOptions {
  double max_rate_m_s = 0.5;              // 0: no bound (the graph's correction at once)
  double max_heading_rate_rad_s = 0.005;  // ~0.3 deg/s
  double report_jump_m = 0.5;             // target jumps at least this large are logged
};

std::vector<std::string> validateCorrectionSlewOptions(const CorrectionSlewOptions& options);
void readCorrectionSlewOptions(sss::core::ConfigSection& section, CorrectionSlewOptions& options);

class CorrectionSlew {
 public:
  explicit CorrectionSlew(const CorrectionSlewOptions& options = {});

  // The correction to publish for a nav sample at utime_us given the graph's (target). The first
  // call, a step back in time and a disabled bound take the target as it is.
  Correction apply(const Correction& target, int64_t utime_us);

  double lagM() const { return lag_m_; }              // translation still to go after the last apply
  double lagHeadingRad() const { return lag_heading_rad_; }
  double lastJumpM() const { return last_jump_m_; }   // the last target jump (between two applies)
  uint64_t jumps() const { return jumps_; }           // target jumps of at least report_jump_m
  // A jump of at least report_jump_m since the last call (for one log line per jump), then cleared.
  std::optional<double> takeNewJump();

 private:
  CorrectionSlewOptions options_;
  std::optional<sss::core::Pose> published_;
  std::optional<sss::core::Pose> last_target_;
  int64_t last_utime_us_ = 0;
  double lag_m_ = 0.0;
  double lag_heading_rad_ = 0.0;
  double last_jump_m_ = 0.0;
  uint64_t jumps_ = 0;
  std::optional<double> new_jump_m_;
};

}  // namespace sss::optimiser
