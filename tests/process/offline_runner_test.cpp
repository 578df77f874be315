// sss-process's runner on a short simulated survey (3 lines of 200 m, 50 m apart, drifting DR):
// the outputs exist and are consistent, SLAM beats DR against the simulator's truth, a run is
// bit-for-bit repeatable and its recorded LCM log replays to the same trajectory, the sonar
// file's embedded navigation works without an INS file, and bad input is refused cleanly.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include "tools/eval/closure_metrics.hpp"
#include "tools/eval/heightmap_metrics.hpp"
#include "tools/eval/match_metrics.hpp"
#include "tools/eval/trajectory_io.hpp"
#include "tools/eval/trajectory_metrics.hpp"
#include "tools/process/offline_runner.hpp"
#include "pipeline/core/geodesy.hpp"
#include "drivers/xtf/xtf_reader.hpp"
#include "drivers/xtf/xtf_writer.hpp"
#include "drivers/edgetech/jsf_format.hpp"
#include "drivers/ins/ixblue_nmea.hpp"
#include "drivers/ins/nmea_gga.hpp"
#include "pipeline/core/time.hpp"

#include <nlohmann/json.hpp>

namespace fs = std::filesystem;

namespace {

// Both channels of a synthetic XTF ping: `samples` samples `spacing_m` apart (sample 0 at the
// sonar), a dark water column down to the seabed at `altitude_m`, then seabed falling off as
// 1/range, all with one-look (exponential) speckle.
void addSeabedChannels(sss::xtf::XtfPingInput& ping, int samples, double spacing_m, double altitude_m,
                       std::mt19937& random) {
  std::exponential_distribution<double> speckle(1.0);
  for (uint16_t channel = 0; channel < 2; ++channel) {
    sss::xtf::XtfChannelData data;
    data.channel_number = channel;
    data.slant_range_m = static_cast<float>(samples * spacing_m);
    for (int k = 0; k < samples; ++k) {
      const double r = k * spacing_m;
      data.samples.push_back(static_cast<float>((r < altitude_m ? 20.0 : 4000.0 * altitude_m / r) * speckle(random)));
    }
    ping.channels.push_back(std::move(data));
  }
}

std::string readFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

class OfflineRunnerTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    root_ = (fs::temp_directory_path() / ("sss_offline_test_" + std::to_string(getpid()))).string();
    fs::create_directories(root_);
    const std::string command = std::string(SSS_SIM_PATH) + " --out " + root_ + "/mission --lines 3 --line-length-m 200" +
                                " --line-spacing-m 50 --seed 2 > " + root_ + "/sim.log 2>&1";
    ASSERT_EQ(std::system(command.c_str()), 0) << "sss-sim failed, see " << root_ << "/sim.log";
  }
  static void TearDownTestSuite() { fs::remove_all(root_); }

  static sss::offline::OfflineRequest request(const std::string& out) {
    sss::offline::OfflineRequest r;
    r.sonar_path = root_ + "/mission/sonar.jsf";
    r.ins_path = root_ + "/mission/ins.nmea";
    r.out_dir = root_ + "/" + out;
    return r;
  }

  // A run on a sonar file alone (the navigation in its headers or packets), without mosaics.
  static sss::offline::OfflineResult runSonarFileOnly(const std::string& sonar_path, const std::string& out_dir) {
    sss::offline::OfflineRequest r;
    r.sonar_path = sonar_path;
    r.out_dir = out_dir;
    r.write_mosaics = false;
    return sss::offline::runOffline(r);
  }

  // Horizontal ATE RMSE of a TUM file against the mission's truth, in the truth's frame (runs
  // without a configured origin take theirs from the first fix).
  static double horizontalAte(const std::string& path, const std::string& mission = "mission") {
    const auto truth = sss::eval::readTum(root_ + "/" + mission + "/ground_truth.tum");
    sss::eval::TumReadOptions in_truth_frame;
    in_truth_frame.target_origin = truth.origin;
    const auto estimate = sss::eval::readTum(path, in_truth_frame);
    EXPECT_TRUE(truth.ok && estimate.ok) << truth.error << estimate.error;
    const auto evaluation =
        sss::eval::evaluateTrajectory(truth.poses, estimate.poses, sss::eval::segmentSurveyLines(truth.poses));
    EXPECT_TRUE(evaluation.ok) << evaluation.error;
    return evaluation.ate.horizontal_m.rmse;
  }

  static std::string root_;
};
std::string OfflineRunnerTest::root_;

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
    EXPECT_TRUE(sss::eval::readHeightmap(root_ + "/mission/seabed.yaml", truth, error)) << error;
    sss::eval::HeightmapReadOptions in_truth_frame;
    in_truth_frame.target_origin = truth.origin;
    EXPECT_TRUE(sss::eval::readHeightmap(r.out_dir + "/" + name, estimate, error, in_truth_frame)) << error;
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
      // The ring: port edge forward, starboard edge back. Its width is twice the swath.
      const size_t half = (corners.size() - 1) / 2;
      EXPECT_NEAR((corners[0] - corners[corners.size() - 2]).norm(), 2.0 * feature["properties"]["swath_m"].get<double>(), 0.5);
      // The midpoint of the first port and starboard corners is the SLAM pose at the subframe's start.
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
  ASSERT_TRUE(sss::eval::evaluateMatchFile(r.out_dir + "/matches.csv", root_ + "/mission", evaluation, error)) << error;
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
  EXPECT_FALSE(sss::eval::evaluateMatchFile(r.out_dir + "/matches.csv", r.out_dir, evaluation, error));
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
  ASSERT_TRUE(sss::eval::readClosureCsv(r.out_dir + "/loop_closures.csv", closures, error)) << error;
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
      ASSERT_TRUE(sss::eval::readHeightmap(r.out_dir + "/heightmap.yaml", heightmap, error)) << error;
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
  ASSERT_TRUE(sss::eval::readHeightmap(mission + "/seabed.yaml", seabed, error)) << error;
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

// An XTF with its navigation in projected metres (NavUnits 0, as Isis writes it) and no altitude
// (a towed fish), with attitude packets between the pings, built from the public layout: it is
// processed in the file's own grid (north = northing - N0 of the first fix), says so, and tracks
// the bottom; and a multibeam-only file is refused in one line.
TEST_F(OfflineRunnerTest, XtfInProjectedMetresWithoutAltitudeIsProcessedInItsGrid) {
  sss::xtf::XtfWriterOptions options;
  options.nav_units = sss::xtf::kNavUnitsMetres;
  sss::xtf::XtfWriterChannel port, starboard;
  starboard.type_of_channel = sss::xtf::kChannelStarboard;
  starboard.name = "Starboard";
  options.channels = {port, starboard};
  const std::string path = root_ + "/projected.xtf";
  {
    sss::xtf::XtfWriter writer(path, options);
    ASSERT_TRUE(writer.isOpen());
    std::mt19937 random(3);
    const double heading_rad = 30.0 * M_PI / 180.0, speed_m_s = 2.0, altitude_m = 15.0, spacing_m = 0.03;
    for (int i = 0; i < 600; ++i) {  // 150 s at 4 Hz: 300 m
      sss::xtf::XtfPingInput ping;
      ping.ping_number = static_cast<uint32_t>(i);
      ping.ping_time_us = 1780300800000000LL + i * 250000LL;
      ping.sound_velocity = 750.0f;
      ping.sensor_x = 650123.0 + speed_m_s * 0.25 * i * std::sin(heading_rad);   // easting
      ping.sensor_y = 6580456.0 + speed_m_s * 0.25 * i * std::cos(heading_rad);  // northing
      ping.depth_m = 30.0f;
      ping.heading_deg = 30.0f;
      addSeabedChannels(ping, 2500, spacing_m, altitude_m, random);
      ASSERT_TRUE(writer.write(ping));
      ASSERT_TRUE(writer.writeBytes(sss::xtf::encodeOtherPacket(3, 64)));  // an attitude packet
    }
  }
  const std::string out_dir = root_ + "/run_projected";
  const auto result = runSonarFileOnly(path, out_dir);
  ASSERT_TRUE(result.ok) << result.error;
  const auto& s = result.summary;
  EXPECT_EQ(s.pings, 600u);
  EXPECT_GE(s.pings_with_pose, 570u) << "95 % of the pings";
  EXPECT_GE(s.subframes, 2u);
  EXPECT_EQ(s.buffer.fusion.altitude_from_bottom_track, s.pings_with_pose);
  EXPECT_EQ(s.origin_source, "projected_first_fix");
  EXPECT_FALSE(s.origin);
  EXPECT_DOUBLE_EQ(s.projected_origin_easting_m, 650123.0);
  EXPECT_DOUBLE_EQ(s.projected_origin_northing_m, 6580456.0);
  const std::string summary = readFile(out_dir + "/summary.json");
  EXPECT_NE(summary.find("projected_northing_m"), std::string::npos) << summary;
  const auto slam = sss::eval::readTum(out_dir + "/slam.tum");
  ASSERT_TRUE(slam.ok) << slam.error;
  EXPECT_FALSE(slam.origin);
  EXPECT_NE(readFile(out_dir + "/slam.tum").find("north = northing - 6580456.000"), std::string::npos);
  // The last pose: 299.5 m along 30 deg from the first fix, in the grid.
  const Eigen::Vector3d last = slam.poses.back().T_world_body.translation;
  const double along_m = 2.0 * 0.25 * 599;
  EXPECT_NEAR(last.x(), along_m * std::cos(30.0 * M_PI / 180.0), 3.0);
  EXPECT_NEAR(last.y(), along_m * std::sin(30.0 * M_PI / 180.0), 3.0);
  std::istringstream altitudes(readFile(out_dir + "/altitude.csv"));
  size_t near_truth = 0, rows = 0;
  for (std::string line; std::getline(altitudes, line);) {
    if (line.empty() || line[0] == '#' || line[0] == 'u') continue;
    ++rows;
    near_truth += std::abs(std::stod(line.substr(line.find(',') + 1)) - 15.0) < 0.2 ? 1 : 0;
  }
  EXPECT_GE(near_truth, rows * 95 / 100) << "bottom-tracked altitude within 0.2 m of the 15 m";
  EXPECT_FALSE(s.geotiffs.empty()) << "the heightmap and coverage in the grid's coordinates";
  EXPECT_EQ(s.geotiff_crs, "") << "no CRS is guessed for a grid the file does not name";
  EXPECT_NE(std::find_if(s.findings.begin(), s.findings.end(),
                         [](const std::string& f) { return f.find("products.projected_crs") != std::string::npos; }),
            s.findings.end())
      << "a projected input without a CRS is told how to name it";

  // With the grid's CRS named: GeoTIFFs in the file's grid, and a corrected copy of the XTF whose
  // pings hold slam.tum plus the grid offsets (f64 in XTF: the TUM file's 0.1 mm rounding).
  {
    // A CRS GDAL does not know is refused before any processing, with the key named (exit 2).
    const std::string bad_config = root_ + "/projected_bad_crs.yaml";
    std::ofstream(bad_config) << "products:\n  projected_crs: EPSG:99999999\n";
    sss::offline::OfflineRequest bad;
    bad.sonar_path = path;
    bad.out_dir = root_ + "/run_projected_bad_crs";
    bad.config_path = bad_config;
    const auto refused = sss::offline::runOffline(bad);
    EXPECT_EQ(refused.exit_code, 2);
    EXPECT_NE(refused.error.find("products.projected_crs"), std::string::npos) << refused.error;

    const std::string config_path = root_ + "/projected_products.yaml";
    std::ofstream(config_path) << "products:\n  projected_crs: EPSG:32633\n";
    sss::offline::OfflineRequest products;
    products.sonar_path = path;
    products.out_dir = root_ + "/run_projected_products";
    products.config_path = config_path;
    products.corrected_dir = products.out_dir + "/corrected";
    const auto run = sss::offline::runOffline(products);
    ASSERT_TRUE(run.ok) << run.error;
    EXPECT_EQ(run.summary.geotiff_epsg, 32633);
    EXPECT_EQ(run.summary.geotiff_crs, "WGS 84 / UTM zone 33N");
    EXPECT_NE(std::find(run.summary.geotiffs.begin(), run.summary.geotiffs.end(), "mosaic_slam.tif"),
              run.summary.geotiffs.end());
    EXPECT_EQ(run.summary.corrected_records, run.summary.pings_with_pose);
    const auto corrected_slam = sss::eval::readTum(products.out_dir + "/slam.tum");
    ASSERT_TRUE(corrected_slam.ok) << corrected_slam.error;
    std::map<int64_t, Eigen::Vector3d> slam_at;
    for (const auto& p : corrected_slam.poses) slam_at[p.utime_us] = p.T_world_body.translation;
    sss::xtf::XtfReader reader(products.corrected_dir + "/projected.xtf");
    ASSERT_TRUE(reader.isOpen()) << reader.error();
    sss::edgetech::DriverPing ping;
    size_t compared = 0;
    double worst_m = 0.0;
    while (reader.next(ping)) {
      const auto found = slam_at.find(ping.utime_us);
      if (found == slam_at.end()) continue;  // a ping the chain dropped keeps its recorded navigation
      const auto& side = *ping.ping.port;
      worst_m = std::max(worst_m, std::hypot(side.easting_m - 650123.0 - found->second.y(),
                                             side.northing_m - 6580456.0 - found->second.x()));
      ++compared;
    }
    EXPECT_EQ(compared, run.summary.pings_with_pose);
    EXPECT_LT(worst_m, 1e-3);
  }

  // A multibeam-only XTF: refused with the reason, exit 2.
  sss::xtf::XtfWriterOptions multibeam;
  sss::xtf::XtfWriterChannel bathymetry;
  bathymetry.type_of_channel = 3;  // bathymetry
  bathymetry.name = "Bathy";
  multibeam.channels = {bathymetry};
  const std::string multibeam_path = root_ + "/multibeam.xtf";
  {
    sss::xtf::XtfWriter writer(multibeam_path, multibeam);
    ASSERT_TRUE(writer.writeBytes(sss::xtf::encodeOtherPacket(2, 256)));
  }
  sss::offline::OfflineRequest mb;
  mb.sonar_path = multibeam_path;
  mb.out_dir = root_ + "/run_multibeam";
  const auto refused = sss::offline::runOffline(mb);
  EXPECT_FALSE(refused.ok);
  EXPECT_EQ(refused.exit_code, 2);
  EXPECT_NE(refused.error.find("no side-scan channel"), std::string::npos) << refused.error;
}

// XTF pings without a sensor position: navigation from raw-position packets (type 107, 4 Hz,
// latitude/longitude with attitude) between the pings, or the vessel's ShipY/X in the ping header.
TEST_F(OfflineRunnerTest, XtfNavigationPacketsOrShipCoordinatesPositionPingsWithoutSensorPosition) {
  for (const bool ship : {false, true}) {
    sss::xtf::XtfWriterOptions options;
    options.nav_units = sss::xtf::kNavUnitsLatLon;
    sss::xtf::XtfWriterChannel port, starboard;
    starboard.type_of_channel = sss::xtf::kChannelStarboard;
    options.channels = {port, starboard};
    const std::string path = root_ + (ship ? "/ship.xtf" : "/packets.xtf");
    const sss::core::LocalTangentPlane plane(43.0, 5.0);
    const double heading_rad = 100.0 * M_PI / 180.0;
    auto positionAt = [&](double t_s) {
      return plane.toGeodetic(Eigen::Vector3d(2.0 * t_s * std::cos(heading_rad), 2.0 * t_s * std::sin(heading_rad), 0.0));
    };
    {
      sss::xtf::XtfWriter writer(path, options);
      ASSERT_TRUE(writer.isOpen());
      std::mt19937 random(5);
      for (int i = 0; i < 600; ++i) {  // 150 s at 4 Hz
        const double t_s = 0.25 * i;
        const int64_t utime_us = 1780300800000000LL + i * 250000LL;
        if (!ship) {
          for (int k = 0; k < (i == 0 ? 2 : 1); ++k) {  // a 107 packet 50 ms before every ping (4 Hz)
            const double packet_s = t_s - 0.05 + 0.2 * k;
            if (packet_s < 0.0) continue;
            std::vector<uint8_t> packet = sss::xtf::encodeOtherPacket(sss::xtf::kHeaderPosRawNavigation, 64);
            const int64_t packet_us = 1780300800000000LL + static_cast<int64_t>(std::llround(packet_s * 1e6));
            const int64_t seconds = packet_us / 1000000;
            // 2026-06-01T08:00:00Z + seconds
            const int64_t of_day = seconds % 86400;
            sss::xtf::writeU16(packet.data(), 14, 2026);
            packet[16] = 6;
            packet[17] = 1;
            packet[18] = static_cast<uint8_t>(of_day / 3600);
            packet[19] = static_cast<uint8_t>(of_day / 60 % 60);
            packet[20] = static_cast<uint8_t>(of_day % 60);
            sss::xtf::writeU16(packet.data(), 21, static_cast<uint16_t>((packet_us % 1000000) / 100));
            const auto geo = positionAt(packet_s);
            sss::xtf::writeF64(packet.data(), 23, geo.latitude_deg);
            sss::xtf::writeF64(packet.data(), 31, geo.longitude_deg);
            sss::xtf::writeF32(packet.data(), 59, 100.0f);  // heading
            ASSERT_TRUE(writer.writeBytes(packet));
          }
        }
        sss::xtf::XtfPingInput ping;
        ping.ping_number = static_cast<uint32_t>(i);
        ping.ping_time_us = utime_us;
        ping.depth_m = 30.0f;
        ping.altitude_m = 15.0f;
        ping.heading_deg = 100.0f;
        addSeabedChannels(ping, 2500, 0.03, 15.0, random);
        std::vector<uint8_t> packet = sss::xtf::encodeSonarPacket(options, ping);
        if (ship) {  // SensorY/X stay 0: the vessel's position only
          const auto geo = positionAt(t_s);
          sss::xtf::writeF64(packet.data(), 128, geo.latitude_deg);
          sss::xtf::writeF64(packet.data(), 136, geo.longitude_deg);
        }
        ASSERT_TRUE(writer.writeBytes(packet));
      }
    }
    const std::string out_dir = root_ + (ship ? "/run_ship" : "/run_packets");
    const auto result = runSonarFileOnly(path, out_dir);
    ASSERT_TRUE(result.ok) << result.error;
    const auto& s = result.summary;
    EXPECT_GE(s.pings_with_pose, 570u) << (ship ? "ship" : "packets") << ": 95 % of the pings";
    EXPECT_GE(s.subframes, 2u);
    if (!ship) {
      EXPECT_GE(s.nav_from_packets, 600u);
      EXPECT_EQ(s.pings_without_position, 600u);
    } else {
      EXPECT_EQ(s.nav_from_packets, 0u);
      EXPECT_EQ(s.pings_without_position, 0u);
    }
    ASSERT_TRUE(s.origin);
    EXPECT_NEAR(s.origin->latitude_deg, 43.0, 1e-4);
    const auto slam = sss::eval::readTum(out_dir + "/slam.tum");
    ASSERT_TRUE(slam.ok) << slam.error;
    const double t_last_s = 1e-6 * static_cast<double>(slam.poses.back().utime_us - 1780300800000000LL);
    const Eigen::Vector3d last = slam.poses.back().T_world_body.translation;
    EXPECT_NEAR(last.x(), 2.0 * t_last_s * std::cos(heading_rad), 1.0);
    EXPECT_NEAR(last.y(), 2.0 * t_last_s * std::sin(heading_rad), 1.0);
  }
}

// A JSF whose type 80 pings carry no position (no lat/lon bit) with 2090 situation messages
// between them (latitude, longitude, depth, heading at 4 Hz, as the sonar's own INS sends), or
// 2002 NMEA messages with GGA sentences: those messages are the navigation.
TEST_F(OfflineRunnerTest, JsfSituationOrNmeaMessagesPositionPingsWithoutPosition) {
 for (const bool nmea : {false, true}) {
  const std::string path = root_ + (nmea ? "/nmea.jsf" : "/situation.jsf");
  const sss::core::LocalTangentPlane plane(-12.5, 130.8);
  const double heading_rad = 250.0 * M_PI / 180.0;
  {
    std::ofstream out(path, std::ios::binary);
    std::mt19937 random(8);
    std::exponential_distribution<double> speckle(1.0);
    uint8_t sequence = 0;
    for (int i = 0; i < 600; ++i) {
      const double t_s = 0.25 * i;
      const int64_t utime_us = 1780300800000000LL + i * 250000LL;
      // 2090, 50 ms before the ping.
      std::vector<uint8_t> body(276, 0);
      const int64_t nav_us = utime_us - 50000;
      const int32_t seconds = static_cast<int32_t>(nav_us / 1000000);
      const int32_t milliseconds = static_cast<int32_t>(nav_us / 1000 % 1000);
      std::memcpy(body.data() + 0, &seconds, 4);
      std::memcpy(body.data() + 4, &milliseconds, 4);
      const uint32_t validity = 0x7Fu;
      std::memcpy(body.data() + 12, &validity, 4);
      const uint64_t microseconds = static_cast<uint64_t>(nav_us);
      std::memcpy(body.data() + 20, &microseconds, 8);
      const double nav_s = std::max(0.0, t_s - 0.05);
      const auto geo = plane.toGeodetic(Eigen::Vector3d(2.0 * nav_s * std::cos(heading_rad), 2.0 * nav_s * std::sin(heading_rad), 0.0));
      const double fields[] = {geo.latitude_deg, geo.longitude_deg, 30.0, 250.0, 0.0, 0.0};
      for (int f = 0; f < 6; ++f) std::memcpy(body.data() + 28 + 8 * f, &fields[f], 8);
      sss::edgetech::JsfMessageHeader header;
      header.message_type = sss::edgetech::kJsfSituation;
      if (nmea) {  // the same fix as a GGA sentence from byte 12 (ddmm.mmmmmm, S and E)
        const double lat = -geo.latitude_deg, lon = geo.longitude_deg;
        char sentence[128];
        std::snprintf(sentence, sizeof sentence, "GPGGA,080000.00,%02d%09.6f,S,%03d%09.6f,E,1,10,0.8,0.0,M,,M,,",
                      static_cast<int>(lat), (lat - static_cast<int>(lat)) * 60.0, static_cast<int>(lon),
                      (lon - static_cast<int>(lon)) * 60.0);
        const std::string text = sss::ins::frameSentence(sentence);
        body.assign(12, 0);
        std::memcpy(body.data() + 0, &seconds, 4);
        std::memcpy(body.data() + 4, &milliseconds, 4);
        body.insert(body.end(), text.begin(), text.end());
        header.message_type = sss::edgetech::kJsfNmea;
      }
      header.byte_count = static_cast<int32_t>(body.size());
      uint8_t header_bytes[16];
      sss::edgetech::encodeHeader(header, header_bytes);
      out.write(reinterpret_cast<const char*>(header_bytes), 16);
      out.write(reinterpret_cast<const char*>(body.data()), static_cast<std::streamsize>(body.size()));
      for (uint8_t channel : {sss::edgetech::kChannelPort, sss::edgetech::kChannelStarboard}) {
        sss::edgetech::SonarChannelRecord record;
        record.channel = channel;
        record.ping_time_us = utime_us;
        record.ping_number = static_cast<uint32_t>(i);
        record.sample_interval_s = 4e-5;  // 3 cm
        record.validity = sss::edgetech::kValidHeading | sss::edgetech::kValidSoundSpeed;  // no position, no altitude
        record.heading_rad = heading_rad;
        std::vector<float> magnitudes;
        for (int k = 0; k < 2500; ++k) {
          const double r = k * 0.03;
          magnitudes.push_back(static_cast<float>((r < 15.0 ? 2.0 : 400.0 * 15.0 / r) * speckle(random)));
        }
        int16_t weighting = 0;
        const auto codes = sss::edgetech::quantiseEnvelope(magnitudes, weighting);
        record.weighting_factor = weighting;
        const auto bytes = sss::edgetech::encodeSonarData(record, codes, sequence++);
        out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
      }
    }
  }
  const std::string out_dir = root_ + (nmea ? "/run_nmea" : "/run_situation");
  const auto result = runSonarFileOnly(path, out_dir);
  ASSERT_TRUE(result.ok) << result.error;
  const auto& s = result.summary;
  EXPECT_EQ(s.pings, 600u);
  EXPECT_GE(s.pings_with_pose, 570u) << "95 % of the pings";
  EXPECT_GE(s.nav_from_packets, 600u);
  EXPECT_GE(s.subframes, 2u);
  ASSERT_TRUE(s.origin);
  EXPECT_NEAR(s.origin->latitude_deg, -12.5, 1e-4);
  const auto slam = sss::eval::readTum(out_dir + "/slam.tum");
  ASSERT_TRUE(slam.ok) << slam.error;
  const double t_last_s = 1e-6 * static_cast<double>(slam.poses.back().utime_us - 1780300800000000LL);
  const Eigen::Vector3d last = slam.poses.back().T_world_body.translation;
  EXPECT_NEAR(last.x(), 2.0 * t_last_s * std::cos(heading_rad), 1.0);
  EXPECT_NEAR(last.y(), 2.0 * t_last_s * std::sin(heading_rad), 1.0);
  if (!nmea) {
    EXPECT_NEAR(last.z(), 30.0, 0.1) << "the depth of the situation messages";
  }
 }
}

// The towed record of the real-file issue, rebuilt: an XTF in latitude/longitude with altitude and
// depth 0 in every ping, 1446 pings along a 311 m line that curves through 30 degrees. Every ping
// gets a pose, the bottom track gives the altitude, and the curve still makes subframes.
TEST_F(OfflineRunnerTest, TowedCurvedLineWithoutAltitudeOrDepthGivesSubframes) {
  sss::xtf::XtfWriterOptions options;
  sss::xtf::XtfWriterChannel port, starboard;
  starboard.type_of_channel = sss::xtf::kChannelStarboard;
  options.channels = {port, starboard};
  const std::string path = root_ + "/towed_curve.xtf";
  const sss::core::LocalTangentPlane plane(51.2, 2.9);
  constexpr int kPings = 1446;
  const double length_m = 311.0, turn_rad = 30.0 * M_PI / 180.0, radius_m = length_m / turn_rad;
  const double period_s = 0.143;  // 7 Hz at 1.5 m/s
  {
    sss::xtf::XtfWriter writer(path, options);
    ASSERT_TRUE(writer.isOpen());
    std::mt19937 random(12);
    for (int i = 0; i < kPings; ++i) {
      const double s_m = length_m * i / (kPings - 1), angle = s_m / radius_m;  // heading from north, turning right
      const Eigen::Vector3d ned(radius_m * std::sin(angle), radius_m * (1.0 - std::cos(angle)), 0.0);
      const auto geo = plane.toGeodetic(ned);
      sss::xtf::XtfPingInput ping;
      ping.ping_number = static_cast<uint32_t>(i);
      ping.ping_time_us = 1780300800000000LL + static_cast<int64_t>(std::llround(i * period_s * 1e6));
      ping.sensor_y = geo.latitude_deg;
      ping.sensor_x = geo.longitude_deg;
      ping.heading_deg = static_cast<float>(angle * 180.0 / M_PI);  // depth and altitude stay 0
      addSeabedChannels(ping, 1600, 0.03125, 9.0, random);
      ASSERT_TRUE(writer.write(ping));
    }
  }
  sss::offline::OfflineRequest r;
  r.sonar_path = path;
  r.out_dir = root_ + "/run_towed_curve";
  const auto result = sss::offline::runOffline(r);
  ASSERT_TRUE(result.ok) << result.error;
  const auto& s = result.summary;
  std::printf("towed curved line: %llu of %llu pings with a pose, %llu subframes, %llu lines, %llu bottom-tracked\n",
              static_cast<unsigned long long>(s.pings_with_pose), static_cast<unsigned long long>(s.pings),
              static_cast<unsigned long long>(s.subframes), static_cast<unsigned long long>(s.survey_lines),
              static_cast<unsigned long long>(s.buffer.fusion.altitude_from_bottom_track));
  EXPECT_EQ(s.pings, static_cast<uint64_t>(kPings));
  EXPECT_GE(s.pings_with_pose, static_cast<uint64_t>(0.95 * kPings));
  EXPECT_EQ(s.buffer.fusion.altitude_from_bottom_track, s.pings_with_pose);
  EXPECT_GE(s.subframes, 1u);
  EXPECT_TRUE(fs::is_regular_file(r.out_dir + "/mosaic_dr.png"));
  // DR only, and the run says why: one pass, not lines too far apart for the swath.
  ASSERT_EQ(s.findings.size(), 1u);
  EXPECT_NE(s.findings[0].find("follow one another along one track"), std::string::npos) << s.findings[0];
  std::printf("towed curved line: %llu pairs tried, %llu closures; %s\n", static_cast<unsigned long long>(s.pairs_attempted),
              static_cast<unsigned long long>(s.matcher_closures), s.findings.empty() ? "" : s.findings[0].c_str());
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
