// See frame_alignment.hpp.
#include "tools/eval/frame_alignment.hpp"

#include <Eigen/Geometry>
#include <cmath>

#include "pipeline/core/geodesy.hpp"
#include "tools/eval/heightmap_metrics.hpp"

namespace sss::eval {

namespace {

struct FramePair {
  sss::core::LocalTangentPlane from, to;
  Eigen::Vector3d convert(const Eigen::Vector3d& ned_from) const { return to.toNed(from.toGeodetic(ned_from)); }
  // The rotation taking vectors at p in the `from` axes into the `to` axes: the images of unit
  // steps along each axis (1 m: the planes' non-linearity over it is below 1e-9).
  Eigen::Matrix3d rotationAt(const Eigen::Vector3d& ned_from) const {
    const Eigen::Vector3d p = convert(ned_from);
    Eigen::Matrix3d m;
    for (int axis = 0; axis < 3; ++axis) m.col(axis) = convert(ned_from + Eigen::Vector3d::Unit(axis)) - p;
    Eigen::JacobiSVD<Eigen::Matrix3d> svd(m, Eigen::ComputeFullU | Eigen::ComputeFullV);
    return svd.matrixU() * svd.matrixV().transpose();  // the nearest rotation
  }
};

}  // namespace

bool sameOrigin(const sss::core::MissionOrigin& a, const sss::core::MissionOrigin& b) {
  return std::abs(a.latitude_deg - b.latitude_deg) < 1e-9 && std::abs(a.longitude_deg - b.longitude_deg) < 1e-9;
}

Eigen::Vector3d reexpressPosition(const Eigen::Vector3d& ned_m, const sss::core::MissionOrigin& from,
                                  const sss::core::MissionOrigin& to) {
  const FramePair frames{{from.latitude_deg, from.longitude_deg}, {to.latitude_deg, to.longitude_deg}};
  return frames.convert(ned_m);
}

void reexpressTrajectory(Trajectory& poses, const sss::core::MissionOrigin& from, const sss::core::MissionOrigin& to) {
  const FramePair frames{{from.latitude_deg, from.longitude_deg}, {to.latitude_deg, to.longitude_deg}};
  for (StampedPose& pose : poses) {
    const Eigen::Matrix3d R_to_from = frames.rotationAt(pose.T_world_body.translation);
    pose.T_world_body.translation = frames.convert(pose.T_world_body.translation);
    pose.T_world_body.rotation = Eigen::Quaterniond(R_to_from * pose.T_world_body.rotation.toRotationMatrix()).normalized();
  }
}

void reexpressHeightmap(HeightmapRaster& raster, const sss::core::MissionOrigin& from, const sss::core::MissionOrigin& to) {
  const FramePair frames{{from.latitude_deg, from.longitude_deg}, {to.latitude_deg, to.longitude_deg}};
  const double centre_north_m = raster.north_min_m + 0.5 * (raster.rows - 1) * raster.resolution_m;
  const double centre_east_m = raster.east_min_m + 0.5 * (raster.cols - 1) * raster.resolution_m;
  const Eigen::Vector3d centre_to = frames.convert({centre_north_m, centre_east_m, 0.0});
  for (int row = 0; row < raster.rows; ++row) {
    for (int col = 0; col < raster.cols; ++col) {
      float& depth = raster.at(row, col);
      if (!std::isfinite(depth)) continue;
      depth = static_cast<float>(frames.convert({raster.northM(row), raster.eastM(col), depth}).z());
    }
  }
  raster.north_min_m += centre_to.x() - centre_north_m;
  raster.east_min_m += centre_to.y() - centre_east_m;
}

}  // namespace sss::eval
