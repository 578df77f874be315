// The answer to one nav sample (SSS_NAV) of the vehicle: its DR pose and the correction to
// publish, slewed (correction_slew.hpp) from the newest solved graph's. It also follows the
// navigation's frame: the mission origin that every sample carries, whose tangent plane
// geo-references the corrected pose. Samples without a pose or a time, and samples before the
// INS's first fix (no position, no frame), are not answered and say why. No middleware.
#pragma once

#include <cstdint>
#include <optional>

#include "pipeline/core/geodesy.hpp"
#include "pipeline/core/mission_origin.hpp"
#include "pipeline/core/pose.hpp"
#include "pipeline/core/sensor_types.hpp"
#include "pipeline/optimiser/correction_slew.hpp"
#include "pipeline/optimiser/pose_graph.hpp"

namespace sss::optimiser {

enum class NavVerdict {
  kCorrected,
  kBadSample,   // a non-finite pose or no time
  kNoPosition,  // before the INS's first fix: no position, no origin
};

struct NavCorrection {
  NavVerdict verdict = NavVerdict::kBadSample;
  sss::core::Pose dr;     // the sample's DR pose (T_world_body)
  Correction correction;  // to publish (slewed)
  // This sample brought the navigation's origin: the first one, or a new one (previous_origin set:
  // an INS bridge restarted without its state directory).
  bool origin_changed = false;
  std::optional<sss::core::MissionOrigin> previous_origin;
  std::optional<double> jump_m;  // the graph's correction jumped this much (a fix or closures accepted)
};

class NavCorrector {
 public:
  explicit NavCorrector(const CorrectionSlewOptions& slew = {});

  NavCorrection correct(const sss::core::NavSample& nav, const SlidingWindowPoseGraph& graph);

  // The tangent plane of the navigation's origin; set by the first corrected sample.
  const std::optional<sss::core::LocalTangentPlane>& plane() const { return plane_; }
  const CorrectionSlew& slew() const { return slew_; }

 private:
  CorrectionSlew slew_;
  std::optional<sss::core::LocalTangentPlane> plane_;
};

}  // namespace sss::optimiser
