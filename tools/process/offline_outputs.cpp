// The outputs of sss-process's runner. See offline_runner_internal.hpp.
#include "tools/process/offline_runner_internal.hpp"

namespace sss::offline {

namespace fs = std::filesystem;

using sss::core::Pose;

// With fixes: fixes.csv (every fix the optimiser saw, its decision and residual) and
// dead_reckoning_fixed.tum, the best answer without side-scan: the same nodes, odometry and fixes in
// a graph without closures (what an aided-INS smoother with the same fixes gives).
Status Runner::writeFixOutputs(const std::string& dir) {
  const sss::optimiser::SlidingWindowPoseGraph& graph = optimiser_.graph();
  const std::vector<sss::optimiser::FixRecord> records = graph.fixes();
  sss::offline::FixSummary& s = summary_.fixes;
  s.accepted = graph.fixCounters().accepted;
  s.rejected_gate = graph.fixCounters().rejected_gate;
  if (records.empty()) return Status::success();
  double sum_squared = 0.0;
  s.accepted_independent_equivalent = 0.0;
  for (const auto& r : records)
    if (r.status == sss::optimiser::FixStatus::kAccepted) {
      sum_squared += r.residual_ne_m.squaredNorm();
      s.accepted_independent_equivalent += r.information_weight;
    }
  s.rms_residual_m = s.accepted > 0 ? std::sqrt(sum_squared / static_cast<double>(s.accepted)) : 0.0;

  const std::string csv_path = dir + "/fixes.csv";
  std::FILE* f = std::fopen(csv_path.c_str(), "w");
  if (!f) return Status::error("cannot write " + csv_path);
  std::fprintf(f, "# absolute fixes given to the optimiser (local NED of the mission origin); residual = fix - SLAM "
                  "estimate at the fix time; chi2 = innovation at the gate (2 dof); information_weight = the share of the fix's "
                  "information the solve takes (its error correlated with the fix before it)\n"
                  "utime_us,source,north_m,east_m,sigma_north_m,sigma_east_m,status,innovation_chi2,subframe_id,"
                  "residual_north_m,residual_east_m,information_weight\n");
  for (const auto& r : records) {
    const char* status = r.status == sss::optimiser::FixStatus::kAccepted   ? "accepted"
                         : r.status == sss::optimiser::FixStatus::kRejected ? "rejected_gate"
                                                                              : "pending";
    std::fprintf(f, "%lld,%s,%.3f,%.3f,%.3f,%.3f,%s,%.3f,%lld,%.3f,%.3f,%.6f\n", static_cast<long long>(r.fix.utime_us),
                 r.fix.source.c_str(), r.fix.position_ne_m.x(), r.fix.position_ne_m.y(),
                 std::sqrt(r.fix.covariance_m2(0, 0)), std::sqrt(r.fix.covariance_m2(1, 1)), status, r.innovation_chi2,
                 static_cast<long long>(r.subframe_id), r.residual_ne_m.x(), r.residual_ne_m.y(), r.information_weight);
  }
  if (std::fclose(f) != 0) return Status::error("cannot write " + csv_path);

  sss::optimiser::SlidingWindowPoseGraph fixed(options_.optimiser.graph);
  // The same odometry as the SLAM graph (the INS's drift when it reported one), the same anchor
  // (the INS's accuracy at the first node): the baseline differs from SLAM by the closures alone.
  if (const Status drift = fixed.setOdometryDriftFraction(graph.odometryDriftFraction()); !drift) return drift;
  const Eigen::Vector2d& anchor_ins_sigma_ne_m = graph.firstNodeInsSigma();
  // The SLAM graph took this anchor, nodes and fixes, so a refusal here is a bug, not bad input.
  if (anchor_ins_sigma_ne_m.x() > 0.0 || anchor_ins_sigma_ne_m.y() > 0.0) {
    const Status anchored =
        fixed.setFirstNodeHorizontalSigma(anchor_ins_sigma_ne_m.x(), anchor_ins_sigma_ne_m.y());
    if (!anchored) return anchored;
  }
  for (const sss::optimiser::NodeState& n : graph.nodes()) {
    const Status added = fixed.addNode(n.subframe_id, n.utime_us, n.T_world_body_dr, n.distance_travelled_m);
    if (!added) return added;
  }
  for (const auto& r : records) {
    const Status added = fixed.addFix(r.fix);
    if (!added) return added;
  }
  fixed.fullSmoothing();
  std::vector<sss::optimiser::StampedPose> poses;
  poses.reserve(dr_per_ping_.size());
  for (const auto& p : dr_per_ping_) poses.push_back({p.utime_us, fixed.correctionAt(p.utime_us).T_corrected_dr * p.T_world_body});
  return sss::optimiser::writeTum(dir + "/dead_reckoning_fixed.tum", poses,
                                  "sss-process: dead reckoning with the same fixes, no side-scan (graph without "
                                  "closures) at every ping" + frame_comment_,
                                  origin_);
}

// The corrected navigation for the survey's own tools: navigation.csv (every ping: UTC time,
// latitude, longitude, local north/east, depth below the ellipsoid, attitude, altitude, horizontal 1-sigma,
// DR or SLAM) and, when
// the frame is geographic, navigation.nmea (ZDA + GGA + HDT per ping, GGA quality 6: estimated).
Status Runner::writeNavigation(const std::string& dir, const std::vector<sss::optimiser::StampedPose>& slam) const {
  std::vector<double> altitude_m;
  for (const PingAltitude& p : altitude_per_ping_) altitude_m.push_back(p.altitude_m);
  return sss::products::writeNavigationFiles(dir, slam, optimiser_, origin_, altitude_m);
}

// --write-corrected: a copy of the sonar file with the SLAM navigation in every ping it has a pose for.
Status Runner::writeCorrectedCopy(const std::vector<sss::optimiser::StampedPose>& slam) {
  std::optional<sss::core::LocalTangentPlane> plane;
  if (origin_) plane.emplace(origin_->latitude_deg, origin_->longitude_deg);
  if (!plane && !projected_origin_) return Status::success();  // no frame on Earth: said in the findings
  std::error_code ec;
  fs::create_directories(request_.corrected_dir, ec);
  const std::string out_path = (fs::path(request_.corrected_dir) / fs::path(request_.sonar_path).filename()).string();
  // The pose at a ping's time: slam has one pose per ping, so an exact time; else the nearest
  // neighbours interpolated when they are less than a second apart.
  const sss::products::NavigationAt navigation =
      [&](int64_t utime_us) -> std::optional<sss::products::PingNavigation> {
    auto after = std::lower_bound(slam.begin(), slam.end(), utime_us,
                                  [](const sss::optimiser::StampedPose& p, int64_t t) { return p.utime_us < t; });
    sss::core::Pose pose;
    if (after != slam.end() && after->utime_us == utime_us) {
      pose = after->T_world_body;
    } else {
      if (after == slam.begin() || after == slam.end() || after->utime_us - (after - 1)->utime_us > 1000000) {
        return std::nullopt;
      }
      const auto before = after - 1;
      const double fraction =
          static_cast<double>(utime_us - before->utime_us) / static_cast<double>(after->utime_us - before->utime_us);
      pose = sss::core::interpolate(before->T_world_body, after->T_world_body, fraction);
    }
    sss::products::PingNavigation nav;
    const sss::core::EulerAngles euler = sss::core::eulerFromQuaternion(pose.rotation);
    nav.heading_rad = euler.heading_rad;
    nav.pitch_rad = euler.pitch_rad;
    nav.roll_rad = euler.roll_rad;
    if (plane) {
      // The inverse of how the readers place a ping: toNed(latitude, longitude, depth).
      const sss::core::GeodeticPosition geo = plane->toGeodetic(pose.translation);
      nav.latitude_deg = geo.latitude_deg;
      nav.longitude_deg = geo.longitude_deg;
      nav.depth_m = geo.depth_m;
    } else {
      nav.projected = true;
      nav.easting_m = projected_origin_->x() + pose.translation.y();
      nav.northing_m = projected_origin_->y() + pose.translation.x();
      nav.depth_m = pose.translation.z();
    }
    return nav;
  };
  sss::products::CorrectedCopyCounters counters;
  const Status written =
      hasExtension(request_.sonar_path, ".xtf")
          ? sss::products::writeCorrectedXtf(request_.sonar_path, out_path, navigation, counters, options_.xtf,
                                             summary_.nav_laybacks_applied > 0)
          : sss::products::writeCorrectedJsf(request_.sonar_path, out_path, navigation, counters,
                                             options_.sonar.apply_layback && summary_.nav_laybacks_applied > 0);
  if (!written) return written;
  summary_.corrected_copy = out_path;
  summary_.corrected_records = counters.records_corrected;
  summary_.corrected_records_without_position_field = counters.records_without_position_field;
  summary_.corrected_records_without_pose = counters.records_without_pose;
  return Status::success();
}

std::optional<sss::products::RasterFrame> Runner::rasterFrame() const {
  sss::products::RasterFrame frame;
  if (projected_origin_) {
    frame.projected = true;
    frame.grid_easting_offset_m = projected_origin_->x();
    frame.grid_northing_offset_m = projected_origin_->y();
    frame.projected_crs = options_.projected_crs;
    return frame;
  }
  if (!origin_) return std::nullopt;
  frame.origin = origin_;
  return frame;
}

Status Runner::writeRaster(const std::string& dir, const std::string& name, const sss::products::FrameRaster& raster) {
  if (!options_.write_geotiff) return Status::success();
  const std::optional<sss::products::RasterFrame> frame = rasterFrame();
  if (!frame) return Status::success();  // no frame on Earth (said once in the findings)
  sss::products::GeoTiffInfo info;
  if (const Status written = sss::products::writeGeoTiff(dir + "/" + name, raster, *frame, &info); !written) {
    return written;
  }
  summary_.geotiffs.push_back(name);
  summary_.geotiff_crs = info.crs_name;
  summary_.geotiff_epsg = info.epsg;
  return Status::success();
}

// For GIS (QGIS opens them as they are; RFC 7946, WGS 84 longitude/latitude): track.geojson, the SLAM
// and DR tracks (a vertex every 4 pings), and subframes.geojson, each subframe's footprint on the
// seabed under the SLAM poses (its swath of canonical ground range either side, a vertex every 25
// pings) with its id and line. Only in a geographic frame.
Status Runner::writeGeoJson(const std::string& dir, const std::vector<sss::optimiser::StampedPose>& slam) const {
  return sss::products::writeGeoJsonFiles(dir, slam, dr_per_ping_, footprints_, optimiser_, origin_);
}

// altitude.csv: the altitude every ping was processed with and where it came from.
Status Runner::writeAltitudeCsv(const std::string& path) const {
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (!f) return Status::error("cannot write " + path);
  std::fprintf(f, "# the sonar's altitude above the seabed each ping was processed with; source: nav (DVL), "
                  "ping_header (the sonar's own field) or bottom_track (its returns; quality 0..1)\n"
                  "utime_us,altitude_m,source,bottom_track_quality\n");
  for (const PingAltitude& p : altitude_per_ping_) {
    std::fprintf(f, "%lld,%.3f,%s,%.2f\n", static_cast<long long>(p.utime_us), p.altitude_m,
                 sss::subframe::altitudeSourceName(p.source), p.quality);
  }
  if (std::fclose(f) != 0) return Status::error("cannot write " + path);
  return Status::success();
}

Status Runner::writeOutputs() {
  const std::string dir = request_.out_dir;
  // Per-ping trajectories: DR as fused, SLAM = the correction at the ping time applied to it.
  std::vector<sss::optimiser::StampedPose> slam;
  slam.reserve(dr_per_ping_.size());
  for (const auto& p : dr_per_ping_) {
    slam.push_back({p.utime_us, optimiser_.correctionAt(p.utime_us).T_corrected_dr * p.T_world_body});
  }
  summary_.pings_with_pose = dr_per_ping_.size();
  Status written = sss::optimiser::writeTum(dir + "/dead_reckoning.tum", dr_per_ping_,
                                            "sss-process: dead reckoning at every ping" + frame_comment_, origin_);
  if (written) {
    written = sss::optimiser::writeTum(dir + "/slam.tum", slam,
                                       "sss-process: SLAM-corrected pose at every ping" + frame_comment_, origin_);
  }
  if (written) written = writeFixOutputs(dir);
  if (written) written = writeNavigation(dir, slam);
  if (written) written = writeGeoJson(dir, slam);
  if (written && !request_.corrected_dir.empty()) written = writeCorrectedCopy(slam);
  if (!written) return written;
  if (!footprints_.empty()) {
    const sss::products::CoverageGrid coverage =
        sss::products::computeCoverage(sss::products::slamStrips(footprints_, optimiser_), 5.0);
    summary_.coverage_covered_m2 = coverage.covered_m2;
    summary_.coverage_seen_twice_m2 = coverage.seen_twice_m2;
    written = sss::products::writeCoverageFiles(dir + "/coverage.yaml", coverage, origin_);
    if (written) written = writeRaster(dir, "coverage.tif", sss::products::coverageRaster(coverage));
  }
  if (written) written = sss::products::writeTieReportCsv(dir + "/loop_closures.csv", optimiser_);
  if (written) written = writeAltitudeCsv(dir + "/altitude.csv");
  if (written) written = match_writer_.close();
  if (!written) return written;

  const auto& counters = optimiser_.graph().counters();
  summary_.closures_accepted = counters.closures_accepted;
  summary_.closures_rejected = counters.closures_rejected_gate + counters.closures_rejected_inconsistent +
                               counters.closures_rejected_no_support;
  summary_.closures_pending = counters.closures_pending;
  summary_.closures_superseded = counters.closures_superseded;
  summary_.variance_factors = optimiser_.graph().varianceFactors();
  summary_.separation_bias = optimiser_.graph().separationBias();
  summary_.calibration = optimiser_.graph().calibration();
  summary_.anchor_ins_sigma_ne_m = optimiser_.graph().firstNodeInsSigma();
  summary_.anchor_sigma_ne_m = optimiser_.graph().firstNodeHorizontalSigma();
  summary_.odometry_drift_fraction = optimiser_.odometryDriftFraction();
  summary_.odometry_drift_fraction_configured = options_.optimiser.graph.odometry_drift_fraction;
  summary_.odometry_drift_updates = optimiser_.counters().odometry_drift_updates;

  // Bathymetry: SLAM poses (the product) and DR poses (the baseline the map error is compared to).
  const auto& bathymetry = options_.optimiser.bathymetry;
  const std::vector<sss::optimiser::SeabedPoint> points = optimiser_.seabedPoints(false);
  const std::vector<sss::optimiser::SeabedPoint> points_dr = optimiser_.seabedPoints(true);
  summary_.seabed_points = points.size();
  written = sss::optimiser::writeSeabedPly(dir + "/bathymetry.ply", points, origin_);
  if (written) written = sss::optimiser::writeSeabedPly(dir + "/bathymetry_dr.ply", points_dr, origin_);
  if (!written) return written;
  const struct {
    const std::vector<sss::optimiser::SeabedPoint>& points;
    const char* name;
    const char* description;
  } heightmaps[] = {{points, "heightmap", "sss-process: seabed re-triangulated with the SLAM poses"},
                    {points_dr, "heightmap_dr", "sss-process: seabed triangulated with the DR poses"}};
  for (const auto& heightmap : heightmaps) {
    if (heightmap.points.empty()) continue;
    const sss::optimiser::HeightmapGrid grid = sss::optimiser::gridSeabedPoints(heightmap.points, bathymetry);
    written = sss::optimiser::writeHeightmapFiles(dir + "/" + heightmap.name + ".yaml", grid, heightmap.description,
                                                  origin_);
    if (written) {
      written = writeRaster(dir, std::string(heightmap.name) + ".tif",
                            sss::products::heightmapRaster(grid, std::string(heightmap.description) + " (depth m, down)"));
    }
    if (!written) return written;
  }

  if (request_.write_mosaics) {
    const std::optional<sss::products::RasterFrame> frame =
        options_.write_geotiff ? rasterFrame() : std::optional<sss::products::RasterFrame>();
    sss::products::GeoTiffInfo info;
    const size_t before = summary_.geotiffs.size();
    written = sss::products::writeMosaicProducts(dir, mosaic_store_.subframes(), optimiser_, options_.pictures, origin_,
                                                 frame, "sss-process", summary_.geotiffs, info);
    if (!written) return written;
    if (summary_.geotiffs.size() > before) {
      summary_.geotiff_crs = info.crs_name;
      summary_.geotiff_epsg = info.epsg;
    }
  }
  return Status::success();
}

}  // namespace sss::offline
