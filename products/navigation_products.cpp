// Corrected navigation and tie report files, see navigation_products.hpp.
#include "products/navigation_products.hpp"

#include <Eigen/Eigenvalues>

#include <cmath>
#include <cstdio>
#include <map>

#include "drivers/ins/position_fix.hpp"
#include "pipeline/core/geodesy.hpp"
#include "pipeline/core/time.hpp"

namespace sss::products {

using sss::core::Status;
namespace {

const char* statusName(sss::optimiser::ClosureStatus status) {
  switch (status) {
    case sss::optimiser::ClosureStatus::kAccepted: return "accepted";
    case sss::optimiser::ClosureStatus::kRejected: return "rejected";
    case sss::optimiser::ClosureStatus::kSuperseded: return "superseded";
    case sss::optimiser::ClosureStatus::kPending: return "pending";
  }
  return "unknown";
}

const char* rejectionName(sss::optimiser::ClosureRejection rejection) {
  switch (rejection) {
    case sss::optimiser::ClosureRejection::kNone: return "none";
    case sss::optimiser::ClosureRejection::kChiSquareGate: return "chi_square_gate";
    case sss::optimiser::ClosureRejection::kInconsistent: return "inconsistent";
    case sss::optimiser::ClosureRejection::kNoSupport: return "no_support";
  }
  return "unknown";
}

}  // namespace

Status writeTieReportCsv(const std::string& path, const sss::optimiser::OptimiserEngine& engine) {
  std::map<int64_t, int64_t> utime_of;
  for (const auto& node : engine.graph().nodes()) utime_of[node.subframe_id] = node.utime_us;
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (!f) {
    return Status::error("cannot write " + path);
  }
  std::fprintf(f, "# loop closures from the matcher and the optimiser's decision; T_a_b maps B's centre body frame into A's;\n"
                  "# north/east: the two subframe centres under the final SLAM estimate (local NED, m);\n"
                  "# cov_*: the closure's published covariance of B's centre position, in A's body frame (m^2);\n"
                  "# sigma_heading_rad: of its heading\n"
                  "# before_* / after_*: the closure's offset from DR's relative pose (before the solve) and from the final\n"
                  "# estimate's (after): along, across (A's body x, y), depth (m) and heading (rad): the tie report\n");
  std::fprintf(f, "subframe_id_a,subframe_id_b,utime_a_us,utime_b_us,round,status,rejection,dx_m,dy_m,dz_m,droll_rad,"
                  "dpitch_rad,dheading_rad,num_inliers,mean_zncc,north_a_m,east_a_m,north_b_m,east_b_m,cov_xx_m2,"
                  "cov_xy_m2,cov_yy_m2,sigma_heading_rad,before_along_m,before_across_m,before_depth_m,before_heading_rad,"
                  "after_along_m,after_across_m,after_depth_m,after_heading_rad\n");
  for (const auto& summary : engine.closureSummaries()) {
    const auto& c = summary.record.closure;
    const sss::core::EulerAngles euler = sss::core::eulerFromQuaternion(c.T_a_b.rotation);
    // The covariance is over the tangent of T_a_b * Exp(delta): its translation part is in B's
    // frame; to first order B's position moves by R_a_b dt, so rotate it into A's.
    const Eigen::Matrix3d R_a_b = c.T_a_b.rotation.toRotationMatrix();
    const Eigen::Matrix3d position_covariance = R_a_b * c.covariance.topLeftCorner<3, 3>() * R_a_b.transpose();
    // Heading variance: of the rotation about A's down axis, from the rotation block (B's frame).
    const Eigen::Vector3d down_in_b = R_a_b.transpose() * Eigen::Vector3d::UnitZ();
    const double heading_variance = down_in_b.dot(c.covariance.bottomRightCorner<3, 3>() * down_in_b);
    // Offsets of the closure from DR's and from the estimate's relative pose of the same two centres.
    auto offset = [&](const sss::core::Pose& reference) {
      const Eigen::Vector3d d = c.T_a_b.translation - reference.translation;
      const double heading = sss::core::wrapAngle(euler.heading_rad -
                                                  sss::core::eulerFromQuaternion(reference.rotation).heading_rad);
      return Eigen::Vector4d(d.x(), d.y(), d.z(), heading);
    };
    const Eigen::Vector4d before = offset(summary.T_a_b_dr), after = offset(summary.T_a_b_estimate);
    std::fprintf(f, "%lld,%lld,%lld,%lld,%d,%s,%s,%.4f,%.4f,%.4f,%.6f,%.6f,%.6f,%d,%.4f,%.3f,%.3f,%.3f,%.3f,%.6g,%.6g,"
                    "%.6g,%.6g,%.4f,%.4f,%.4f,%.6f,%.4f,%.4f,%.4f,%.6f\n",
                 static_cast<long long>(c.subframe_id_a), static_cast<long long>(c.subframe_id_b),
                 static_cast<long long>(utime_of[c.subframe_id_a]), static_cast<long long>(utime_of[c.subframe_id_b]),
                 c.association_round, statusName(summary.record.status), rejectionName(summary.record.rejection),
                 c.T_a_b.translation.x(), c.T_a_b.translation.y(), c.T_a_b.translation.z(), euler.roll_rad,
                 euler.pitch_rad, euler.heading_rad, c.num_inliers, summary.mean_zncc, summary.centre_a_ned_m.x(),
                 summary.centre_a_ned_m.y(), summary.centre_b_ned_m.x(), summary.centre_b_ned_m.y(),
                 position_covariance(0, 0), position_covariance(0, 1), position_covariance(1, 1),
                 std::sqrt(std::max(heading_variance, 0.0)), before(0), before(1), before(2), before(3), after(0),
                 after(1), after(2), after(3));
  }
  if (std::fclose(f) != 0) return Status::error("cannot write " + path);
  return Status::success();
}

Status writeNavigationFiles(const std::string& dir, const std::vector<sss::optimiser::StampedPose>& poses,
                            const sss::optimiser::OptimiserEngine& engine,
                            const std::optional<sss::core::MissionOrigin>& origin,
                            const std::vector<double>& altitude_m) {
  std::optional<sss::core::LocalTangentPlane> plane;
  if (origin) plane.emplace(origin->latitude_deg, origin->longitude_deg);
  const std::string csv_path = dir + "/navigation.csv";
  std::FILE* csv = std::fopen(csv_path.c_str(), "w");
  std::FILE* nmea = plane ? std::fopen((dir + "/navigation.nmea").c_str(), "w") : nullptr;
  if (!csv || (plane && !nmea)) {
    if (csv) std::fclose(csv);
    if (nmea) std::fclose(nmea);
    return Status::error("cannot write " + (csv ? dir + "/navigation.nmea" : csv_path));
  }
  std::fprintf(csv, "# sss-process: corrected navigation at every ping%s; horizontal_sigma_m: 1-sigma of the position "
                    "(the larger axis); source: SLAM (corrected by closures or fixes) or DR\n"
                    "utc_time,utime_us,latitude_deg,longitude_deg,north_m,east_m,depth_m,heading_deg,pitch_deg,roll_deg,"
                    "altitude_m,horizontal_sigma_m,source\n",
               plane ? "" : " (projected frame without a CRS: no latitude/longitude)");
  for (size_t i = 0; i < poses.size(); ++i) {
    const int64_t t = poses[i].utime_us;
    const sss::core::Pose& pose = poses[i].T_world_body;
    const sss::optimiser::Correction correction = engine.correctionAt(t);
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> horizontal(correction.covariance.topLeftCorner<2, 2>());
    const double sigma_m = std::sqrt(std::max(horizontal.eigenvalues().maxCoeff(), 0.0));
    const sss::core::EulerAngles euler = sss::core::eulerFromQuaternion(pose.rotation);
    const double altitude = i < altitude_m.size() ? altitude_m[i] : -1.0;
    const char* source = correction.status == sss::optimiser::CorrectionStatus::kDrOnly ? "DR" : "SLAM";
    double heading_deg = std::fmod(euler.heading_rad * 180.0 / M_PI, 360.0);
    if (heading_deg < 0.0) heading_deg += 360.0;
    std::string lat = "", lon = "";
    double depth_m = pose.translation.z();  // below the ellipsoid when geographic, else the frame's down
    if (plane) {
      const sss::core::GeodeticPosition geo = plane->toGeodetic(pose.translation);
      char text[32];
      std::snprintf(text, sizeof text, "%.9f", geo.latitude_deg);
      lat = text;
      std::snprintf(text, sizeof text, "%.9f", geo.longitude_deg);
      lon = text;
      depth_m = geo.depth_m;
      const std::string sentences =
          sss::ins::encodeNavigationNmea(t, geo.latitude_deg, geo.longitude_deg, geo.depth_m, euler.heading_rad);
      std::fputs(sentences.c_str(), nmea);
    }
    std::fprintf(csv, "%s,%lld,%s,%s,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%.3f,%.3f,%s\n",
                 sss::core::formatUtimeIso8601(t).c_str(), static_cast<long long>(t), lat.c_str(), lon.c_str(),
                 pose.translation.x(), pose.translation.y(), depth_m, heading_deg,
                 euler.pitch_rad * 180.0 / M_PI, euler.roll_rad * 180.0 / M_PI, altitude, sigma_m, source);
  }
  const bool csv_ok = std::fclose(csv) == 0;
  const bool nmea_ok = !nmea || std::fclose(nmea) == 0;
  if (!csv_ok || !nmea_ok) {
    return Status::error("cannot write " + (csv_ok ? dir + "/navigation.nmea" : csv_path));
  }
  return Status::success();
}

}  // namespace sss::products
