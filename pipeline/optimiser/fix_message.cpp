// SSS_FIX translation, see fix_message.hpp.
#include "pipeline/optimiser/fix_message.hpp"

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <cmath>

namespace sss::optimiser {

sss::core::Result<AbsoluteFix> fromFixMessage(const sss_msgs::fix_t& m) {
  using sss::core::Status;
  if (m.source != "gnss" && m.source != "usbl") {
    return Status::error("fix source '" + m.source + "' is neither gnss nor usbl");
  }
  AbsoluteFix fix;
  fix.utime_us = m.utime;
  fix.source = m.source;
  fix.position_ne_m = Eigen::Vector2d(m.position_ne_m[0], m.position_ne_m[1]);
  fix.covariance_m2 << m.covariance_ne_m2[0], m.covariance_ne_m2[1], m.covariance_ne_m2[2], m.covariance_ne_m2[3];
  fix.dr_position_m = Eigen::Vector3d(m.dr_position_ned_m[0], m.dr_position_ned_m[1], m.dr_position_ned_m[2]);
  fix.dr_distance_m = m.dr_distance_travelled_m;
  if (!fix.position_ne_m.allFinite() || !fix.dr_position_m.allFinite() || !std::isfinite(fix.dr_distance_m)) {
    return Status::error("fix position, DR position or distance is not finite");
  }
  const double scale = std::max(1.0, fix.covariance_m2.cwiseAbs().maxCoeff());
  if (!fix.covariance_m2.allFinite() || std::abs(fix.covariance_m2(0, 1) - fix.covariance_m2(1, 0)) > 1e-9 * scale ||
      Eigen::LLT<Eigen::Matrix2d>(fix.covariance_m2).info() != Eigen::Success || !(fix.covariance_m2.determinant() > 0.0)) {
    return Status::error("fix covariance is not finite, symmetric and positive definite");
  }
  return fix;
}

sss::core::MissionOrigin fixMessageOrigin(const sss_msgs::fix_t& m) { return {m.origin_latitude_deg, m.origin_longitude_deg}; }

}  // namespace sss::optimiser
