// The corrected pose of a nav sample. See nav_corrector.hpp.
#include "pipeline/optimiser/nav_corrector.hpp"

#include <cmath>

namespace sss::optimiser {

NavCorrector::NavCorrector(const CorrectionSlewOptions& slew) : slew_(slew) {}

NavCorrection NavCorrector::correct(const sss::core::NavSample& nav, const SlidingWindowPoseGraph& graph) {
  NavCorrection answer;
  if (!nav.position_ned_m.allFinite() || !std::isfinite(nav.heading_rad) || !std::isfinite(nav.roll_rad) ||
      !std::isfinite(nav.pitch_rad) || nav.utime_us <= 0) {
    answer.verdict = NavVerdict::kBadSample;
    return answer;
  }
  if (!nav.position_valid || !nav.origin) {
    answer.verdict = NavVerdict::kNoPosition;
    return answer;
  }
  if (!plane_ || plane_->originLatitudeDeg() != nav.origin->latitude_deg ||
      plane_->originLongitudeDeg() != nav.origin->longitude_deg) {
    answer.origin_changed = true;
    if (plane_) answer.previous_origin = sss::core::MissionOrigin{plane_->originLatitudeDeg(), plane_->originLongitudeDeg()};
    plane_.emplace(nav.origin->latitude_deg, nav.origin->longitude_deg);
  }
  answer.verdict = NavVerdict::kCorrected;
  answer.dr = sss::core::poseOf(nav);
  answer.correction = slew_.apply(graph.correctionAt(nav.utime_us), nav.utime_us);
  answer.jump_m = slew_.takeNewJump();
  return answer;
}

}  // namespace sss::optimiser
