// sss-process's runner on a short simulated survey (3 lines of 200 m, 50 m apart, drifting DR):
// the outputs exist and are consistent, SLAM beats DR against the simulator's truth, a run is
// bit-for-bit repeatable and its recorded LCM log replays to the same trajectory, the sonar
// file's embedded navigation works without an INS file, and bad input is refused cleanly.
#include "tests/process/offline_runner_fixture.hpp"
#include "tests/support/status_assertions.hpp"

namespace {

TEST_F(OfflineRunnerTest, SonarAndInsFilesGiveEveryOutputAndBeatDeadReckoning) {
  auto r = request("run");
  r.record_lcm_log_path = root_ + "/run.lcm";
  const auto result = sss::offline::runOffline(r);
  ASSERT_TRUE(result.ok) << result.error;
  EXPECT_EQ(result.exit_code, 0);
  for (const char* file : {"dead_reckoning.tum", "slam.tum", "navigation.csv", "navigation.nmea", "track.geojson",
                           "subframes.geojson", "coverage.yaml", "coverage_lines.u8", "coverage.png", "loop_closures.csv", "bathymetry.ply", "bathymetry_dr.ply",
                           "heightmap.yaml", "heightmap_depth.f32", "heightmap.png", "heightmap_dr.yaml", "mosaic_dr.png",
                           "mosaic_dr.yaml", "mosaic_slam.png", "mosaic_slam.yaml", "summary.json"}) {
    EXPECT_TRUE(fs::is_regular_file(r.out_dir + "/" + file)) << file;
  }
  const auto& s = result.summary;
  EXPECT_GT(s.pings, 1400u);  // 3 x 200 m + turns at 4 Hz and 2 m/s: ~1500 pings
  EXPECT_EQ(s.pings_with_pose, s.pings) << "every ping got its DR pose";
  EXPECT_EQ(s.subframes, 6u);  // 200 m lines = 2 subframes of 200 pings (100 m) each
  EXPECT_GE(s.closures_accepted, 4u);
  EXPECT_EQ(s.closures_rejected, 0u) << "no closure of a clean survey should be rejected";
  EXPECT_GT(s.seabed_points, 1000u);
  EXPECT_GT(s.real_time_factor, 1.0);
  EXPECT_EQ(s.input_faults, 0u) << "clean simulator files: no sentence or message may be lost";

  // Every ping in both trajectories, the same times.
  const auto dr = sss::eval::readTum(r.out_dir + "/dead_reckoning.tum");
  const auto slam = sss::eval::readTum(r.out_dir + "/slam.tum");
  ASSERT_TRUE(dr.ok && slam.ok);
  ASSERT_EQ(dr.poses.size(), s.pings);
  ASSERT_EQ(slam.poses.size(), s.pings);
  for (size_t i = 0; i < dr.poses.size(); ++i) ASSERT_EQ(dr.poses[i].utime_us, slam.poses[i].utime_us);

  // Measured: DR 0.57 m, SLAM 0.30 m (-47 %). A third better is the floor.
  const double ate_dr = horizontalAte(r.out_dir + "/dead_reckoning.tum");
  const double ate_slam = horizontalAte(r.out_dir + "/slam.tum");
  std::printf("horizontal ATE RMSE: DR %.3f m, SLAM %.3f m\n", ate_dr, ate_slam);
  EXPECT_GT(ate_dr, 0.3) << "the simulated DR must drift for this test to mean anything";
  EXPECT_LT(ate_slam, 0.67 * ate_dr);

  // The quasi-dense heightmap against the true seabed: every inlier of every closure is
  // re-triangulated, so it covers the overlaps (measured: ~1400 cells of 2 m), and the SLAM poses
  // make it better than the DR ones (measured MAE: DR 0.64 m, SLAM 0.33 m).
  auto heightmapMae = [&](const std::string& name, size_t& compared) {
    sss::eval::HeightmapRaster truth, estimate;
    std::string error;
    EXPECT_OK(sss::eval::readHeightmap(root_ + "/mission/seabed.yaml", truth));
    sss::eval::HeightmapReadOptions in_truth_frame;
    in_truth_frame.target_origin = truth.origin;
    EXPECT_OK(sss::eval::readHeightmap(r.out_dir + "/" + name, estimate, in_truth_frame));
    const auto result = sss::eval::compareHeightmaps(truth, estimate);
    EXPECT_TRUE(result.ok) << result.error;
    compared = result.compared_cells;
    return result.abs_error_m.mean;
  };
  size_t cells_dr = 0, cells_slam = 0;
  const double mae_dr = heightmapMae("heightmap_dr.yaml", cells_dr);
  const double mae_slam = heightmapMae("heightmap.yaml", cells_slam);
  std::printf("heightmap MAE: DR %.3f m (%zu cells), SLAM %.3f m (%zu cells)\n", mae_dr, cells_dr, mae_slam, cells_slam);
  EXPECT_GT(cells_slam, 800u);
  EXPECT_LT(mae_slam, 0.75 * mae_dr);

  // The corrected navigation for other tools: navigation.csv and navigation.nmea agree with slam.tum
  // (lat/lon to 1e-9 deg in the CSV, 1e-7 minute in GGA, heading to 0.01 deg in HDT), one row per ping.
  {
    ASSERT_TRUE(result.summary.origin);
    const sss::core::LocalTangentPlane plane(result.summary.origin->latitude_deg, result.summary.origin->longitude_deg);
    std::istringstream csv_rows(readFile(r.out_dir + "/navigation.csv"));
    std::string row;
    size_t rows = 0, corrected = 0;
    double worst_csv_m = 0.0;
    while (std::getline(csv_rows, row)) {
      if (row.empty() || row[0] == '#' || row.rfind("utc_time", 0) == 0) continue;
      std::vector<std::string> f;
      std::stringstream split(row);
      for (std::string field; std::getline(split, field, ',');) f.push_back(field);
      ASSERT_EQ(f.size(), 13u) << row;
      ASSERT_LT(rows, slam.poses.size());
      EXPECT_EQ(std::stoll(f[1]), slam.poses[rows].utime_us);
      const Eigen::Vector3d ned = plane.toNed({std::stod(f[2]), std::stod(f[3]), std::stod(f[6])});
      worst_csv_m = std::max(worst_csv_m, (ned - slam.poses[rows].T_world_body.translation).norm());
      corrected += f[12] == "SLAM";
      ++rows;
    }
    EXPECT_EQ(rows, s.pings);
    EXPECT_GT(corrected, rows / 2) << "most pings come after the first accepted closure";
    EXPECT_LT(worst_csv_m, 0.001);
    std::istringstream nmea_lines(readFile(r.out_dir + "/navigation.nmea"));
    size_t gga = 0, hdt = 0;
    double worst_gga_m = 0.0, worst_heading_deg = 0.0;
    for (std::string line; std::getline(nmea_lines, line);) {
      if (line.find("GGA,") != std::string::npos) {
        const auto fix = sss::ins::parseGga(line);
        ASSERT_TRUE(fix) << line;
        EXPECT_EQ(fix->quality, 6) << "an estimated position, never taken for a fix";
        const Eigen::Vector3d ned = plane.toNed({fix->latitude_deg, fix->longitude_deg, -fix->altitude_m});
        worst_gga_m = std::max(worst_gga_m, (ned - slam.poses[gga].T_world_body.translation).head<2>().norm());
        ++gga;
      } else if (line.rfind("$INHDT,", 0) == 0) {
        const double heading_deg = std::stod(line.substr(7));
        const double truth_deg = sss::core::eulerFromQuaternion(slam.poses[hdt].T_world_body.rotation).heading_rad * 180.0 / M_PI;
        worst_heading_deg = std::max(worst_heading_deg, std::abs(std::remainder(heading_deg - truth_deg, 360.0)));
        ++hdt;
      }
    }
    EXPECT_EQ(gga, s.pings);
    EXPECT_EQ(hdt, s.pings);
    EXPECT_LT(worst_gga_m, 0.001);
    EXPECT_LE(worst_heading_deg, 0.0051);
  }

  // Coverage: 3 lines of 200 m, 50 m apart, 75 m per side: 250 x 200 m covered (east -75..175), 150 x 200
  // m seen twice (-25..125: the overlaps of neighbours).
  std::printf("coverage: %.0f m2 covered, %.0f m2 seen from two lines\n", s.coverage_covered_m2, s.coverage_seen_twice_m2);
  EXPECT_NEAR(s.coverage_covered_m2, 250.0 * 200.0, 0.1 * 250.0 * 200.0);
  EXPECT_NEAR(s.coverage_seen_twice_m2, 150.0 * 200.0, 0.1 * 150.0 * 200.0);

  // GeoJSON for GIS: the SLAM and DR tracks, and a closed footprint per subframe that holds the SLAM
  // track along its middle and is the canonical swath wide.
  {
    const nlohmann::json tracks = nlohmann::json::parse(readFile(r.out_dir + "/track.geojson"));
    ASSERT_EQ(tracks["features"].size(), 2u);
    EXPECT_EQ(tracks["features"][0]["properties"]["name"], "SLAM");
    const auto& first = tracks["features"][0]["geometry"]["coordinates"][0];
    const sss::core::LocalTangentPlane plane(result.summary.origin->latitude_deg, result.summary.origin->longitude_deg);
    const Eigen::Vector3d first_ned = plane.toNed({first[1].get<double>(), first[0].get<double>(), 0.0});
    EXPECT_LT((first_ned - slam.poses.front().T_world_body.translation).head<2>().norm(), 0.01);
    const nlohmann::json footprints = nlohmann::json::parse(readFile(r.out_dir + "/subframes.geojson"));
    ASSERT_EQ(footprints["features"].size(), s.subframes);
    for (const auto& feature : footprints["features"]) {
      const auto& ring = feature["geometry"]["coordinates"][0];
      ASSERT_GE(ring.size(), 5u);
      EXPECT_EQ(ring.front(), ring.back()) << "a closed ring";
      std::vector<Eigen::Vector2d> corners;
      for (const auto& c : ring) corners.push_back(plane.toNed({c[1].get<double>(), c[0].get<double>(), 0.0}).head<2>());
      // The ring: starboard edge forward, port edge back (counterclockwise, RFC 7946). Its width is
      // twice the swath.
      const size_t half = (corners.size() - 1) / 2;
      EXPECT_NEAR((corners[0] - corners[corners.size() - 2]).norm(), 2.0 * feature["properties"]["swath_m"].get<double>(), 0.5);
      // The midpoint of the first starboard and port corners is the SLAM pose at the subframe's start.
      const Eigen::Vector2d middle = 0.5 * (corners[0] + corners[corners.size() - 2]);
      const int64_t start_us = [&] {
        for (const auto& p : slam.poses)
          if (sss::core::formatUtimeIso8601(p.utime_us) == feature["properties"]["start_utc"].get<std::string>()) return p.utime_us;
        return int64_t{-1};
      }();
      ASSERT_GE(start_us, 0);
      const auto at = std::find_if(slam.poses.begin(), slam.poses.end(), [&](const auto& p) { return p.utime_us == start_us; });
      EXPECT_LT((middle - at->T_world_body.translation.head<2>()).norm(), 0.05) << feature["properties"];
      EXPECT_EQ(half * 2 + 1, corners.size());
      double twice_area_deg2 = 0.0;  // shoelace on longitude (x) and latitude (y): > 0 counterclockwise
      for (size_t i = 0; i + 1 < ring.size(); ++i)
        twice_area_deg2 += ring[i][0].get<double>() * ring[i + 1][1].get<double>() -
                           ring[i + 1][0].get<double>() * ring[i][1].get<double>();
      EXPECT_GT(twice_area_deg2, 0.0) << feature["properties"];
    }
  }

  // The closures table: header + one line per closure, statuses from the optimiser.
  const std::string csv = readFile(r.out_dir + "/loop_closures.csv");
  EXPECT_NE(csv.find("subframe_id_a,subframe_id_b,utime_a_us,utime_b_us,round,status"), std::string::npos);
  EXPECT_NE(csv.find(",accepted,none,"), std::string::npos);
  // The tie report's columns: accepted closures sit closer to the solved trajectory than to DR.
  {
    std::istringstream rows(csv);
    std::string row, header;
    std::vector<std::string> names;
    double before_sq = 0.0, after_sq = 0.0;
    int accepted = 0;
    while (std::getline(rows, row)) {
      if (row.empty() || row[0] == '#') continue;
      std::vector<std::string> f;
      std::stringstream split(row);
      for (std::string field; std::getline(split, field, ',');) f.push_back(field);
      if (names.empty()) {
        names = f;
        continue;
      }
      auto column = [&](const std::string& name) {
        const auto it = std::find(names.begin(), names.end(), name);
        EXPECT_NE(it, names.end()) << name;
        return std::stod(f.at(static_cast<size_t>(it - names.begin())));
      };
      if (f.at(5) != "accepted") continue;
      ++accepted;
      before_sq += std::pow(column("before_along_m"), 2) + std::pow(column("before_across_m"), 2);
      after_sq += std::pow(column("after_along_m"), 2) + std::pow(column("after_across_m"), 2);
    }
    ASSERT_GT(accepted, 0);
    std::printf("tie report: accepted closures' horizontal offset RMS before %.3f m, after %.3f m\n",
                std::sqrt(before_sq / accepted), std::sqrt(after_sq / accepted));
    EXPECT_LT(after_sq, before_sq);
  }

  // Deterministic, and the recorded LCM log replays to the very same trajectory.
  auto replay = request("replay");
  replay.sonar_path.clear();
  replay.ins_path.clear();
  replay.lcm_log_path = r.record_lcm_log_path;
  replay.write_mosaics = false;
  const auto replayed = sss::offline::runOffline(replay);
  ASSERT_TRUE(replayed.ok) << replayed.error;
  EXPECT_EQ(replayed.summary.pings, s.pings);
  EXPECT_EQ(readFile(replay.out_dir + "/slam.tum"), readFile(r.out_dir + "/slam.tum"));
  EXPECT_EQ(readFile(replay.out_dir + "/loop_closures.csv"), csv);
}

TEST_F(OfflineRunnerTest, WrittenMatchesAreEvaluatedAgainstTheTruth) {
  // --write-matches end to end: every pair the matcher tried is in matches.csv, and the file read
  // back against the mission's truth gives the matcher's accuracy (sss-eval --matches).
  auto r = request("matches");
  r.write_matches = true;
  r.write_mosaics = false;
  const auto result = sss::offline::runOffline(r);
  ASSERT_TRUE(result.ok) << result.error;
  sss::eval::MatchFileEvaluation evaluation;
  std::string error;
  ASSERT_OK(sss::eval::evaluateMatchFile(r.out_dir + "/matches.csv", root_ + "/mission", evaluation));
  std::printf("matches.csv: %zu pair rounds, %ld matches, within 2 px %.3f, recall %.3f, EPE %.2f px\n",
              evaluation.pairs.size(), evaluation.overall.matches, evaluation.overall.withinFraction(),
              evaluation.overall.recall(), evaluation.overall.meanErrorPx());
  EXPECT_GE(evaluation.pairs.size(), result.summary.pairs_attempted);  // every attempt, any round
  EXPECT_EQ(evaluation.subframes, result.summary.subframes);
  // Adjacent lines of a lawnmower fly opposite ways: anti-parallel pairs, no crossing ones.
  EXPECT_GT(evaluation.pairs_by_type[static_cast<int>(sss::eval::PairType::kAntiParallel)], 0);
  EXPECT_EQ(evaluation.pairs_by_type[static_cast<int>(sss::eval::PairType::kCrossing)], 0);
  EXPECT_GT(evaluation.overall.evaluated, 1000);
  EXPECT_GE(evaluation.overall.withinFraction(), 0.75);
  EXPECT_GT(evaluation.overall.recall(), 0.05);

  // A matches file against a folder without the mission is refused with a reason.
  error = sss::testing::failureMessage(sss::eval::evaluateMatchFile(r.out_dir + "/matches.csv", r.out_dir, evaluation));
  EXPECT_NE(error.find("mission.yaml"), std::string::npos) << error;
}

TEST_F(OfflineRunnerTest, InjectedFalseClosuresAreAllRejectedAndSlamStillBeatsDr) {
  // The optimiser's defences: a share of the matched pairs get a relative pose 3-10 m and 2-10 deg wrong, with the
  // matcher's covariance left as it was; the optimiser's defences must keep every one of them out.
  auto r = request("false_closures");
  r.write_mosaics = false;
  r.false_closure_fraction = 0.3;
  r.false_closure_seed = 1;
  const auto result = sss::offline::runOffline(r);
  ASSERT_TRUE(result.ok) << result.error;
  const auto& s = result.summary;
  ASSERT_GT(s.false_closures_injected, 0u) << "the test needs false closures to mean anything";
  EXPECT_LT(s.false_closures_injected, s.matcher_closures);

  std::vector<sss::eval::ClosureRecord> closures;
  std::string error;
  ASSERT_OK(sss::eval::readClosureCsv(r.out_dir + "/loop_closures.csv", closures));
  const auto truth = sss::eval::readTum(root_ + "/mission/ground_truth.tum");
  ASSERT_TRUE(truth.ok);
  const auto evaluation = sss::eval::evaluateClosures(closures, truth.poses, nullptr, 1.0);
  // The matcher's own closures are within ~0.6 m of the truth; an injected one is >= 2.4 m off.
  size_t false_rows = 0, false_accepted = 0, true_accepted = 0;
  for (const auto& c : evaluation.closures) {
    ASSERT_TRUE(c.has_truth);
    const bool is_false = std::hypot(c.closure_error.along_m, c.closure_error.lateral_m) > 2.0;
    false_rows += is_false ? 1 : 0;
    false_accepted += is_false && c.closure.status == "accepted" ? 1 : 0;
    true_accepted += !is_false && c.closure.status == "accepted" ? 1 : 0;
  }
  std::printf("%llu of %llu closures made false: %zu rows off by > 2 m, %zu of them accepted; %zu true closures "
              "accepted\n",
              static_cast<unsigned long long>(s.false_closures_injected),
              static_cast<unsigned long long>(s.matcher_closures), false_rows, false_accepted, true_accepted);
  EXPECT_EQ(false_rows, s.false_closures_injected);
  EXPECT_EQ(false_accepted, 0u);
  EXPECT_GE(true_accepted, 3u);

  // Measured: DR 0.57 m, SLAM 0.24 m (clean run 0.22 m): the pairs made false are lost, not harmful.
  const double ate_dr = horizontalAte(r.out_dir + "/dead_reckoning.tum");
  const double ate_slam = horizontalAte(r.out_dir + "/slam.tum");
  std::printf("with false closures: horizontal ATE RMSE DR %.3f m, SLAM %.3f m\n", ate_dr, ate_slam);
  EXPECT_LT(ate_slam, 0.67 * ate_dr);
}

TEST_F(OfflineRunnerTest, EmbeddedNavigationOfTheSonarFileIsUsedWithoutAnInsFile) {
  auto r = request("embedded");
  r.ins_path.clear();
  r.write_mosaics = false;
  const auto result = sss::offline::runOffline(r);
  ASSERT_TRUE(result.ok) << result.error;
  EXPECT_EQ(result.summary.nav_samples, result.summary.pings);  // one nav sample per ping header
  EXPECT_EQ(result.summary.subframes, 6u);
  // JSF positions are quantised to 1e-4 arc minutes (0.19 m north): still far better than DR.
  EXPECT_LT(horizontalAte(r.out_dir + "/slam.tum"), 0.67 * horizontalAte(r.out_dir + "/dead_reckoning.tum"));
}

// No origin configured: the frame is the first fix's, said in summary.json and in every product,
// and the run is as good wherever on Earth it was recorded (here 33.9 S 151.2 E and 71 N 25.8 W,
// where the meridians converge 2.5x faster than at the equator; default mission at 59.35 N). A
// configured origin 2.5 km away is an override: the run is in that frame, and re-expressed in the
// simulator's for the evaluation it is as good.
TEST_F(OfflineRunnerTest, OriginComesFromTheDataWhereverTheMissionIs) {
  enum class Mode { kInsFile, kEmbedded, kConfiguredAway };
  // (Three runs, not six: each mode once is enough, ~8 s each.)
  for (const auto& [name, latitude, longitude, modes] :
       {std::tuple{"sydney", -33.9, 151.2, std::vector<Mode>{Mode::kInsFile, Mode::kConfiguredAway}},
        std::tuple{"greenland", 71.0, -25.8, std::vector<Mode>{Mode::kEmbedded}}}) {
    const std::string mission = std::string("mission_") + name;
    const std::string command = std::string(SSS_SIM_PATH) + " --out " + root_ + "/" + mission +
                                " --lines 3 --line-length-m 200 --line-spacing-m 50 --seed 2 --origin-latitude-deg " +
                                std::to_string(latitude) + " --origin-longitude-deg " + std::to_string(longitude) +
                                " > " + root_ + "/sim_" + name + ".log 2>&1";
    ASSERT_EQ(std::system(command.c_str()), 0) << command;
    const auto truth = sss::eval::readTum(root_ + "/" + mission + "/ground_truth.tum");
    ASSERT_TRUE(truth.ok && truth.origin) << truth.error;
    for (const Mode mode : modes) {
      const char* mode_name = mode == Mode::kInsFile ? "INS file" : mode == Mode::kEmbedded ? "embedded nav" : "configured origin";
      sss::offline::OfflineRequest r;
      r.sonar_path = root_ + "/" + mission + "/sonar.jsf";
      if (mode != Mode::kEmbedded) r.ins_path = root_ + "/" + mission + "/ins.nmea";
      r.out_dir = root_ + "/run_" + name + "_" + std::to_string(static_cast<int>(mode));
      r.write_mosaics = false;
      const double configured_latitude = latitude + 0.02, configured_longitude = longitude - 0.03;
      if (mode == Mode::kConfiguredAway) {
        r.config_path = root_ + "/origin_" + name + ".yaml";
        std::ofstream config(r.config_path);
        config.precision(12);
        config << "mission:\n  origin_latitude_deg: " << configured_latitude
               << "\n  origin_longitude_deg: " << configured_longitude << "\n";
      }
      const auto result = sss::offline::runOffline(r);
      ASSERT_TRUE(result.ok) << result.error;
      const auto& s = result.summary;
      ASSERT_TRUE(s.origin);
      const std::string summary = readFile(r.out_dir + "/summary.json");
      if (mode == Mode::kConfiguredAway) {
        EXPECT_EQ(s.origin_source, "configured");
        EXPECT_DOUBLE_EQ(s.origin->latitude_deg, configured_latitude);
        EXPECT_DOUBLE_EQ(s.origin->longitude_deg, configured_longitude);
      } else {
        // The simulated survey starts at the simulator's origin: the first fix is there.
        EXPECT_EQ(s.origin_source, "first_fix");
        EXPECT_NEAR(s.origin->latitude_deg, latitude, 1e-5);
        EXPECT_NEAR(s.origin->longitude_deg, longitude, 1e-5);
        EXPECT_NE(summary.find("\"source\": \"first_fix\""), std::string::npos) << summary;
      }
      const auto slam = sss::eval::readTum(r.out_dir + "/slam.tum");
      ASSERT_TRUE(slam.ok && slam.origin);
      EXPECT_DOUBLE_EQ(slam.origin->latitude_deg, s.origin->latitude_deg);
      if (mode != Mode::kConfiguredAway) {
        EXPECT_LT(slam.poses.front().T_world_body.translation.head<2>().norm(), 0.5) << "the first fix is (0, 0)";
      }
      sss::eval::HeightmapRaster heightmap;
      std::string error;
      ASSERT_OK(sss::eval::readHeightmap(r.out_dir + "/heightmap.yaml", heightmap));
      ASSERT_TRUE(heightmap.origin);
      EXPECT_DOUBLE_EQ(heightmap.origin->longitude_deg, s.origin->longitude_deg);
      const std::string ply = readFile(r.out_dir + "/bathymetry.ply");
      EXPECT_NE(ply.substr(0, ply.find("end_header")).find("comment origin_latitude_deg"), std::string::npos);

      // Against the truth in the simulator's frame: DR starts at the truth, and SLAM beats DR by
      // as much as at the default origin (measured there: DR 0.57 m, SLAM 0.30 m).
      sss::eval::TumReadOptions in_truth_frame;
      in_truth_frame.target_origin = truth.origin;
      const auto dr = sss::eval::readTum(r.out_dir + "/dead_reckoning.tum", in_truth_frame);
      ASSERT_TRUE(dr.ok) << dr.error;
      EXPECT_EQ(dr.reexpressed, mode == Mode::kConfiguredAway);
      const double first_error_m =
          (dr.poses.front().T_world_body.translation - truth.poses.front().T_world_body.translation).head<2>().norm();
      const double ate_dr = horizontalAte(r.out_dir + "/dead_reckoning.tum", mission);
      const double ate_slam = horizontalAte(r.out_dir + "/slam.tum", mission);
      std::printf("%s, %s: origin %.6f %.6f, first DR pose %.3f m off the truth, ATE DR %.3f m, SLAM %.3f m\n", name,
                  mode_name, s.origin->latitude_deg, s.origin->longitude_deg, first_error_m, ate_dr, ate_slam);
      EXPECT_LT(first_error_m, 0.3) << "DR must start at the truth";
      EXPECT_GT(ate_dr, 0.3);
      EXPECT_LT(ate_slam, 0.67 * ate_dr);
    }
  }
}

// A towed fish or a vehicle without DVL: no altitude anywhere in the files. The chain tracks the
// bottom in the returns; against the true altitude (the seabed under the true position) and in
// SLAM accuracy the run stays close to the one with the DVL's altitude.
TEST_F(OfflineRunnerTest, WithoutAnyAltitudeTheBottomTrackKeepsTheAccuracy) {
  const std::string mission = root_ + "/mission_no_altitude";
  const std::string command = std::string(SSS_SIM_PATH) + " --out " + mission +
                              " --lines 3 --line-length-m 200 --line-spacing-m 50 --seed 2 --no-altitude > " + root_ +
                              "/sim_no_altitude.log 2>&1";
  ASSERT_EQ(std::system(command.c_str()), 0) << command;
  sss::offline::OfflineRequest r;
  r.sonar_path = mission + "/sonar.jsf";
  r.ins_path = mission + "/ins.nmea";
  r.out_dir = root_ + "/run_no_altitude";
  r.write_mosaics = false;
  const auto result = sss::offline::runOffline(r);
  ASSERT_TRUE(result.ok) << result.error;
  const auto& s = result.summary;
  EXPECT_EQ(s.buffer.fusion.altitude_from_nav, 0u);
  EXPECT_EQ(s.buffer.fusion.altitude_from_ping, 0u);
  EXPECT_GE(s.pings_with_pose, s.pings - 5) << "every ping but the tracker's first";
  EXPECT_EQ(s.buffer.fusion.altitude_from_bottom_track, s.pings_with_pose);
  EXPECT_EQ(s.subframes, 6u);

  // altitude.csv against the true altitude: the true seabed under the true position.
  sss::eval::HeightmapRaster seabed;
  std::string error;
  ASSERT_OK(sss::eval::readHeightmap(mission + "/seabed.yaml", seabed));
  const auto truth = sss::eval::readTum(mission + "/ground_truth.tum");
  ASSERT_TRUE(truth.ok);
  std::map<int64_t, Eigen::Vector3d> true_position;
  for (const auto& pose : truth.poses) true_position[pose.utime_us] = pose.T_world_body.translation;
  std::istringstream csv(readFile(r.out_dir + "/altitude.csv"));
  std::vector<double> errors;
  for (std::string line; std::getline(csv, line);) {
    if (line.empty() || line[0] == '#' || line[0] == 'u') continue;
    std::istringstream fields(line);
    long long utime = 0;
    double altitude = 0.0;
    char comma = 0;
    fields >> utime >> comma >> altitude;
    const auto position = true_position.find(utime);
    ASSERT_NE(position, true_position.end()) << line;
    const auto depth = seabed.sampleBilinear(position->second.x(), position->second.y());
    ASSERT_TRUE(depth);
    errors.push_back(std::abs(altitude - (*depth - position->second.z())));
  }
  ASSERT_EQ(errors.size(), s.pings_with_pose);
  std::sort(errors.begin(), errors.end());
  const double p50 = errors[errors.size() / 2], p95 = errors[errors.size() * 95 / 100];

  const double ate_without = horizontalAte(r.out_dir + "/slam.tum", "mission_no_altitude");
  auto with = request("run_with_altitude");
  with.write_mosaics = false;
  const auto with_result = sss::offline::runOffline(with);
  ASSERT_TRUE(with_result.ok) << with_result.error;
  const double ate_with = horizontalAte(with.out_dir + "/slam.tum");
  const double ate_dr = horizontalAte(with.out_dir + "/dead_reckoning.tum");
  std::printf("no altitude in the files: bottom track vs true altitude p50 %.3f m, p95 %.3f m; SLAM ATE %.3f m "
              "(with the DVL's altitude %.3f m, DR %.3f m); %llu closures accepted (with altitude %llu)\n",
              p50, p95, ate_without, ate_with, ate_dr, static_cast<unsigned long long>(s.closures_accepted),
              static_cast<unsigned long long>(with_result.summary.closures_accepted));
  // Measured: p50 0.058 m, p95 0.109 m; SLAM 0.221 m without, 0.215 m with the DVL's altitude.
  EXPECT_LT(p95, 0.25);
  EXPECT_LT(ate_without, 1.1 * ate_with);
}

TEST_F(OfflineRunnerTest, BadInputIsRefusedWithTheFileNamed) {
  auto missing = request("missing");
  missing.sonar_path = root_ + "/no_such_file.jsf";
  auto result = sss::offline::runOffline(missing);
  EXPECT_FALSE(result.ok);
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_NE(result.error.find("no_such_file.jsf"), std::string::npos) << result.error;

  // Garbage bytes with a .jsf name: no pings, refused, no crash.
  const std::string garbage = root_ + "/garbage.jsf";
  {
    std::ofstream out(garbage, std::ios::binary);
    for (int i = 0; i < 100000; ++i) out.put(static_cast<char>((i * 7919) & 0xff));
  }
  auto bad = request("garbage");
  bad.sonar_path = garbage;
  result = sss::offline::runOffline(bad);
  EXPECT_FALSE(result.ok);
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_NE(result.error.find("no usable pings"), std::string::npos) << result.error;

  // Neither or both inputs, unknown extension, no output folder.
  auto both = request("both");
  both.lcm_log_path = root_ + "/run.lcm";
  EXPECT_EQ(sss::offline::runOffline(both).exit_code, 2);
  auto unknown = request("unknown");
  unknown.sonar_path = root_ + "/mission/ins.nmea";
  result = sss::offline::runOffline(unknown);
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_NE(result.error.find("unknown sonar file type"), std::string::npos) << result.error;
  auto no_out = request("");
  no_out.out_dir.clear();
  EXPECT_EQ(sss::offline::runOffline(no_out).exit_code, 2);
}

TEST_F(OfflineRunnerTest, TruncatedSonarFileIsProcessedUpToTheCut) {
  // The first 40 % of the JSF, cut inside a message: the pings before the cut are processed.
  const std::string source = root_ + "/mission/sonar.jsf";
  const std::string cut = root_ + "/cut.jsf";
  const auto size = fs::file_size(source);
  {
    std::ifstream in(source, std::ios::binary);
    std::ofstream out(cut, std::ios::binary);
    std::string bytes(static_cast<size_t>(size * 2 / 5) + 123, '\0');
    in.read(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  }
  auto r = request("cut");
  r.sonar_path = cut;
  r.write_mosaics = false;
  const auto result = sss::offline::runOffline(r);
  ASSERT_TRUE(result.ok) << result.error;
  EXPECT_GT(result.summary.pings, 500u);
  EXPECT_LT(result.summary.pings, 700u);
}

// A survey flown as real ones are: GNSS at the surface before the dive and after the last line,
// USBL every 30 s from a ship (10 % lost, 5 % outliers 10-50 m off), and a DR that drifts
// (drift x3). Fixes bound the drift (DR + fixes beats DR), SLAM with the fixes beats both, no
// outlier is accepted, the same fixes without dates give the same run, and USBL fixes taken for
// GNSS (gnss: prefix) are ignored under water with a finding that says so.
TEST_F(OfflineRunnerTest, GnssAndUsblFixesBoundTheDriftAndNoOutlierIsAccepted) {
  const std::string command = std::string(SSS_SIM_PATH) + " --out " + root_ + "/fixes_mission --lines 3" +
                              " --line-length-m 200 --line-spacing-m 50 --seed 5 --drift-scale 3 --gnss-fixes start-end" +
                              " --usbl-period-s 30 > " + root_ + "/fixes_sim.log 2>&1";
  ASSERT_EQ(std::system(command.c_str()), 0) << "sss-sim failed, see " << root_ << "/fixes_sim.log";
  const std::string mission = root_ + "/fixes_mission";
  auto r = request("fixes_run");
  r.sonar_path = mission + "/sonar.jsf";
  r.ins_path = mission + "/ins.nmea";
  r.fix_paths = {mission + "/fixes.nmea"};
  r.write_mosaics = false;
  const auto result = sss::offline::runOffline(r);
  ASSERT_TRUE(result.ok) << result.error;
  const sss::offline::FixSummary& f = result.summary.fixes;
  // The survey's anchor is as loose as the INS said its position was at the first subframe's centre
  // (the simulated INS reports 0.5 m + 0.2 % x drift scale of the distance run), so the fixes may
  // move the start.
  EXPECT_GT(result.summary.anchor_ins_sigma_ne_m.x(), 0.5);
  EXPECT_LT(result.summary.anchor_ins_sigma_ne_m.x(), 1.5);
  EXPECT_EQ(result.summary.anchor_ins_sigma_ne_m.x(), result.summary.anchor_ins_sigma_ne_m.y());
  EXPECT_EQ(result.summary.anchor_sigma_ne_m, result.summary.anchor_ins_sigma_ne_m);  // wider than 0.1 m
  // The odometry drifts as fast as that INS says (0.6 % of the distance: through STDPOS in
  // ins.nmea, the INS bridge's parser and the odometer), not the configured fraction.
  EXPECT_GE(result.summary.odometry_drift_updates, 1u);
  EXPECT_NEAR(result.summary.odometry_drift_fraction, 0.006, 0.0002);
  EXPECT_NE(result.summary.odometry_drift_fraction_configured, result.summary.odometry_drift_fraction);
  EXPECT_EQ(f.files, 1u);
  EXPECT_GE(f.gnss, 6u);   // 20 s at the surface at either end, one every 5 s
  EXPECT_GE(f.usbl, 10u);  // ~25 of 30 s over a ~15 min dive
  EXPECT_EQ(f.read, f.gnss + f.usbl);
  EXPECT_EQ(f.below_surface, 0u);
  EXPECT_EQ(f.outside_navigation, 0u);
  EXPECT_EQ(f.fed, f.read);
  EXPECT_EQ(f.accepted + f.rejected_gate, f.fed);
  EXPECT_TRUE(fs::is_regular_file(r.out_dir + "/fixes.csv"));
  ASSERT_TRUE(fs::is_regular_file(r.out_dir + "/dead_reckoning_fixed.tum"));

  // No accepted fix lies more than 5 m from the truth (the outliers are 10-50 m off).
  const auto truth = sss::eval::readTum(mission + "/ground_truth.tum");
  ASSERT_TRUE(truth.ok);
  const auto dr = sss::eval::readTum(r.out_dir + "/dead_reckoning.tum");
  ASSERT_TRUE(dr.ok && !dr.poses.empty());
  // The run's frame is the INS's first position; the truth's the mission origin: the offset between
  // them is the first DR pose's (DR starts at the truth).
  const Eigen::Vector2d frame_offset = (dr.poses.front().T_world_body.translation - truth.poses.front().T_world_body.translation).head<2>();
  std::istringstream csv(readFile(r.out_dir + "/fixes.csv"));
  std::string line;
  int accepted_checked = 0, outliers_rejected = 0;
  while (std::getline(csv, line)) {
    if (line.empty() || line[0] == '#' || line.rfind("utime_us", 0) == 0) continue;
    std::vector<std::string> fields;
    std::stringstream split(line);
    for (std::string field; std::getline(split, field, ',');) fields.push_back(field);
    ASSERT_GE(fields.size(), 11u) << line;
    const int64_t utime = std::stoll(fields[0]);
    const auto nearest = std::min_element(truth.poses.begin(), truth.poses.end(), [&](const auto& a, const auto& b) {
      return std::llabs(a.utime_us - utime) < std::llabs(b.utime_us - utime);
    });
    const Eigen::Vector2d fix(std::stod(fields[2]), std::stod(fields[3]));
    const double error_m = (fix - frame_offset - nearest->T_world_body.translation.head<2>()).norm();
    if (fields[6] == "accepted") {
      EXPECT_LT(error_m, 5.0) << "accepted fix " << line;
      ++accepted_checked;
    } else if (error_m > 9.0) {
      ++outliers_rejected;
    }
  }
  EXPECT_EQ(accepted_checked, static_cast<int>(f.accepted));

  const double ate_dr = horizontalAte(r.out_dir + "/dead_reckoning.tum", "fixes_mission");
  const double ate_fixed = horizontalAte(r.out_dir + "/dead_reckoning_fixed.tum", "fixes_mission");
  const double ate_slam = horizontalAte(r.out_dir + "/slam.tum", "fixes_mission");
  std::printf("fixes: %llu GNSS + %llu USBL, %llu accepted, %llu rejected (%d far outliers); ATE DR %.3f, DR + fixes %.3f, "
              "SLAM + fixes %.3f m\n",
              static_cast<unsigned long long>(f.gnss), static_cast<unsigned long long>(f.usbl),
              static_cast<unsigned long long>(f.accepted), static_cast<unsigned long long>(f.rejected_gate),
              outliers_rejected, ate_dr, ate_fixed, ate_slam);
  EXPECT_LT(ate_fixed, 0.7 * ate_dr);
  EXPECT_LT(ate_slam, ate_fixed);

  // The same fixes without ZDA: dated from the navigation's day, the same run.
  {
    std::istringstream in(readFile(mission + "/fixes.nmea"));
    std::ofstream out(root_ + "/undated.nmea");
    for (std::string sentence; std::getline(in, sentence);)
      if (sentence.find("ZDA") == std::string::npos) out << sentence << "\n";
  }
  auto undated = r;
  undated.out_dir = root_ + "/fixes_undated";
  undated.fix_paths = {root_ + "/undated.nmea"};
  const auto undated_result = sss::offline::runOffline(undated);
  ASSERT_TRUE(undated_result.ok) << undated_result.error;
  EXPECT_EQ(undated_result.summary.fixes.accepted, f.accepted);
  EXPECT_EQ(readFile(undated.out_dir + "/slam.tum"), readFile(r.out_dir + "/slam.tum"));

  // USBL taken for GNSS: every one under water, ignored, and the finding names the cause.
  {
    std::istringstream in(readFile(mission + "/fixes.nmea"));
    std::ofstream out(root_ + "/usbl_only.nmea");
    for (std::string sentence; std::getline(in, sentence);)
      if (sentence.rfind("$II", 0) == 0) out << sentence << "\n";
  }
  auto as_gnss = r;
  as_gnss.out_dir = root_ + "/fixes_as_gnss";
  as_gnss.fix_paths = {"gnss:" + root_ + "/usbl_only.nmea"};
  const auto as_gnss_result = sss::offline::runOffline(as_gnss);
  ASSERT_TRUE(as_gnss_result.ok) << as_gnss_result.error;
  EXPECT_EQ(as_gnss_result.summary.fixes.below_surface, as_gnss_result.summary.fixes.read);
  EXPECT_EQ(as_gnss_result.summary.fixes.fed, 0u);
  bool named = false;
  for (const std::string& finding : as_gnss_result.summary.findings)
    named = named || finding.find("gnss_max_depth_m") != std::string::npos;
  EXPECT_TRUE(named) << "a finding must say why the GNSS fixes were ignored";

  // A fix file that does not exist is bad input, named.
  auto missing = r;
  missing.out_dir = root_ + "/fixes_missing";
  missing.fix_paths = {root_ + "/no_such_fixes.nmea"};
  const auto missing_result = sss::offline::runOffline(missing);
  EXPECT_EQ(missing_result.exit_code, 2);
  EXPECT_NE(missing_result.error.find("no_such_fixes.nmea"), std::string::npos) << missing_result.error;
}

}  // namespace
