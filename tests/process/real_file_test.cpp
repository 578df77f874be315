// The real XTF in ../shared/data/real (an Iver2 AUV's Marine Sonic record past the Scotsman wreck,
// see its README) through what a user runs: sss-process with no configuration, and the bottom
// tracker against the altitude the vehicle recorded. Checks what a person would: every ping, a
// frame at the file's first fix, positions inside the file's own lat/lon box, plausible
// altitudes, subframes and a mosaic in which the wreck stands out. Skipped when the file is absent.
#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "drivers/xtf/xtf_reader.hpp"
#include "pipeline/core/geodesy.hpp"
#include "pipeline/subframe/bottom_tracker.hpp"
#include "tests/support/geotiff_read.hpp"
#include "tools/eval/trajectory_io.hpp"
#include "tools/process/offline_runner.hpp"

namespace fs = std::filesystem;

namespace {

const std::string kRealFile = std::string(SSS_REAL_DATA_DIR) + "/scotsman-iver2.xtf";

#define SKIP_WITHOUT_REAL_FILE()                                                                       \
  if (!fs::is_regular_file(kRealFile)) {                                                               \
    GTEST_SKIP() << kRealFile << " is absent: the real-data tests need ../shared/data/real beside the " \
                    "repository";                                                                      \
  }

std::string readFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

struct FileFacts {
  size_t pings = 0;
  double latitude_min = 90, latitude_max = -90, longitude_min = 180, longitude_max = -180;
  std::vector<double> header_altitude_m, tracked_altitude_m;
};

// The file as the reader gives it, with the bottom tracker run over every ping.
FileFacts readFacts() {
  FileFacts facts;
  sss::xtf::XtfReader reader(kRealFile);
  EXPECT_TRUE(reader.isOpen()) << reader.error();
  sss::subframe::BottomTracker tracker;
  sss::sonar::DriverPing ping;
  while (reader.next(ping)) {
    ++facts.pings;
    const auto& side = ping.ping.port ? *ping.ping.port : *ping.ping.starboard;
    if (side.latitude_deg != 0.0 || side.longitude_deg != 0.0) {
      facts.latitude_min = std::min(facts.latitude_min, side.latitude_deg);
      facts.latitude_max = std::max(facts.latitude_max, side.latitude_deg);
      facts.longitude_min = std::min(facts.longitude_min, side.longitude_deg);
      facts.longitude_max = std::max(facts.longitude_max, side.longitude_deg);
    }
    if (!ping.ping.port || !ping.ping.starboard) continue;
    const auto& port = *ping.ping.port;
    const double spacing_m = 0.5 * port.sound_speed_m_s * port.sample_interval_s;
    const auto track = tracker.track(port.samples, ping.ping.starboard->samples, 0.0, spacing_m);
    if (track.valid && port.altitude_m > 0.0) {
      facts.header_altitude_m.push_back(port.altitude_m);
      facts.tracked_altitude_m.push_back(track.altitude_m);
    }
  }
  return facts;
}

double percentile(std::vector<double> values, double fraction) {
  std::sort(values.begin(), values.end());
  return values[std::min(values.size() - 1, static_cast<size_t>(fraction * static_cast<double>(values.size())))];
}

// The Marine Sonic's first strong return lies 10-20 % beyond the DVL's altitude (its beam does not
// reach nadir: the first return comes from the beam's inner edge). The fusion learns that ratio
// while both exist and scales the bottom track by it when the DVL's altitude stops; here the
// ratio of the first 200 pings is applied to the remaining 260, as after a DVL dropout.
TEST(RealFile, BottomTrackFollowsTheAltitudeTheVehicleRecorded) {
  SKIP_WITHOUT_REAL_FILE();
  const FileFacts facts = readFacts();
  ASSERT_EQ(facts.pings, 461u);
  ASSERT_GT(facts.header_altitude_m.size(), 430u) << "the tracker must find the seabed in nearly every ping";
  const size_t n = facts.header_altitude_m.size();
  std::vector<double> raw_errors, ratios, calibrated_errors;
  for (size_t i = 0; i < n; ++i) {
    raw_errors.push_back(std::abs(facts.tracked_altitude_m[i] - facts.header_altitude_m[i]));
    if (i < 200) ratios.push_back(facts.header_altitude_m[i] / facts.tracked_altitude_m[i]);
  }
  const double scale = percentile(ratios, 0.5);
  for (size_t i = 200; i < n; ++i) {
    calibrated_errors.push_back(std::abs(scale * facts.tracked_altitude_m[i] - facts.header_altitude_m[i]));
  }
  std::printf("real file: header altitude %.2f-%.2f m; bottom track - header: p50 %.2f m, p95 %.2f m over %zu pings; "
              "scale %.3f learned over 200 pings, then p50 %.2f m, p95 %.2f m over %zu\n",
              *std::min_element(facts.header_altitude_m.begin(), facts.header_altitude_m.end()),
              *std::max_element(facts.header_altitude_m.begin(), facts.header_altitude_m.end()),
              percentile(raw_errors, 0.5), percentile(raw_errors, 0.95), n, scale, percentile(calibrated_errors, 0.5),
              percentile(calibrated_errors, 0.95), calibrated_errors.size());
  EXPECT_GT(scale, 0.75);  // the first return beyond nadir, within a 40 deg inner beam edge
  EXPECT_LT(scale, 1.0);
  EXPECT_LT(percentile(raw_errors, 0.95), 2.5);
  EXPECT_LT(percentile(calibrated_errors, 0.5), 0.25);
  EXPECT_LT(percentile(calibrated_errors, 0.95), 0.5);
}

TEST(RealFile, SssProcessWithoutConfigGivesATrajectoryInTheFilesBoxAndAMosaicOfTheWreck) {
  SKIP_WITHOUT_REAL_FILE();
  const FileFacts facts = readFacts();
  sss::offline::OfflineRequest request;
  request.sonar_path = kRealFile;
  request.out_dir = (fs::temp_directory_path() / ("sss_real_file_test_" + std::to_string(getpid()))).string();
  const auto result = sss::offline::runOffline(request);
  ASSERT_TRUE(result.ok) << result.error;
  const auto& s = result.summary;
  EXPECT_EQ(s.pings, 461u);
  EXPECT_GE(s.pings_with_pose, 438u) << "95 % of the pings";
  EXPECT_GE(s.subframes, 1u);
  EXPECT_EQ(s.buffer.fusion.altitude_from_nav, s.pings_with_pose) << "the file's own altitudes are used";
  // One line past the wreck: DR only, and the run says why.
  ASSERT_EQ(s.findings.size(), 1u);
  EXPECT_NE(s.findings[0].find("one survey line"), std::string::npos) << s.findings[0];

  // The frame is the file's first fix, and every pose lies inside the file's own lat/lon box.
  ASSERT_TRUE(s.origin);
  EXPECT_EQ(s.origin_source, "first_fix");
  EXPECT_GE(s.origin->latitude_deg, facts.latitude_min);
  EXPECT_LE(s.origin->latitude_deg, facts.latitude_max);
  const auto slam = sss::eval::readTum(request.out_dir + "/slam.tum");
  ASSERT_TRUE(slam.ok && slam.origin) << slam.error;
  const sss::core::LocalTangentPlane plane(slam.origin->latitude_deg, slam.origin->longitude_deg);
  const double margin_deg = 1e-6;  // 0.1 m
  for (const auto& pose : slam.poses) {
    const auto geodetic = plane.toGeodetic(pose.T_world_body.translation);
    ASSERT_GE(geodetic.latitude_deg, facts.latitude_min - margin_deg);
    ASSERT_LE(geodetic.latitude_deg, facts.latitude_max + margin_deg);
    ASSERT_GE(geodetic.longitude_deg, facts.longitude_min - margin_deg);
    ASSERT_LE(geodetic.longitude_deg, facts.longitude_max + margin_deg);
  }
  // The recorder stamps each ping with its newest fix (220 positions over 461 pings, repeated for
  // 2-6 pings): the repeats are placed between the fixes in time, so the track advances at every
  // ping instead of standing still and jumping a few decimetres.
  EXPECT_GT(s.nav_positions_interpolated, 200u);
  const auto dr = sss::eval::readTum(request.out_dir + "/dead_reckoning.tum");
  ASSERT_TRUE(dr.ok) << dr.error;
  std::vector<double> steps_m;
  for (size_t i = 1; i < dr.poses.size(); ++i)
    steps_m.push_back((dr.poses[i].T_world_body.translation - dr.poses[i - 1].T_world_body.translation).head<2>().norm());
  ASSERT_GT(steps_m.size(), 400u);
  const double step_median_m = percentile(steps_m, 0.5);
  std::printf("real file DR: step between pings p2 %.3f m, median %.3f m, p98 %.3f m\n", percentile(steps_m, 0.02),
              step_median_m, percentile(steps_m, 0.98));
  EXPECT_GT(percentile(steps_m, 0.02), 0.3 * step_median_m) << "no ping stands still";
  EXPECT_LT(percentile(steps_m, 0.98), 3.0 * step_median_m) << "no jump of several pings' travel";
  const std::string mosaic_yaml = readFile(request.out_dir + "/mosaic_dr.yaml");
  EXPECT_NE(mosaic_yaml.find("origin_latitude_deg"), std::string::npos) << mosaic_yaml;

  // The wreck stands out of the seabed: the brightest 4 m blocks of the mosaic (its hull and the
  // edge of its shadow) far above the typical block, and the darkest (the shadow) far below.
  const cv::Mat mosaic = cv::imread(request.out_dir + "/mosaic_dr.png", cv::IMREAD_GRAYSCALE);
  ASSERT_FALSE(mosaic.empty());
  std::vector<double> blocks;
  constexpr int kBlock = 8;  // 8 x 0.5 m
  for (int r = 0; r + kBlock <= mosaic.rows; r += kBlock / 2) {
    for (int c = 0; c + kBlock <= mosaic.cols; c += kBlock / 2) {
      const cv::Mat block = mosaic(cv::Rect(c, r, kBlock, kBlock));
      if (cv::countNonZero(block) < kBlock * kBlock) continue;  // no data at the edges
      blocks.push_back(cv::mean(block)[0]);
    }
  }
  ASSERT_GT(blocks.size(), 50u);
  const double median = percentile(blocks, 0.5), bright = percentile(blocks, 0.99), dark = percentile(blocks, 0.01);
  std::printf("real file mosaic: %zu full 4 m blocks, grey p1 %.0f, median %.0f, p99 %.0f\n", blocks.size(), dark,
              median, bright);
  EXPECT_GT(bright, 1.6 * median);
  EXPECT_LT(dark, 0.5 * median);
  fs::remove_all(request.out_dir);
}

// The survey products of the real file: GeoTIFF mosaics in its UTM zone (the Scotsman lies at
// 48.4 N 68.8 W: zone 19N) holding the PNG's pixels, and a corrected copy of the XTF that the reader
// gives back as slam.tum, with every byte outside the pings' navigation fields as recorded.
TEST(RealFile, GeoTiffsInItsUtmZoneAndACorrectedCopyThatReadsBackAsSlam) {
  SKIP_WITHOUT_REAL_FILE();
  sss::offline::OfflineRequest request;
  request.sonar_path = kRealFile;
  request.out_dir = (fs::temp_directory_path() / ("sss_real_products_test_" + std::to_string(getpid()))).string();
  request.corrected_dir = request.out_dir + "/corrected";
  const auto result = sss::offline::runOffline(request);
  ASSERT_TRUE(result.ok) << result.error;
  const auto& s = result.summary;
  EXPECT_EQ(s.geotiff_epsg, 32619);
  const auto tif = sss::test::readGeoTiff(request.out_dir + "/mosaic_dr.tif");
  ASSERT_TRUE(tif.ok) << tif.error;
  EXPECT_EQ(tif.epsg, 32619);
  EXPECT_EQ(tif.nodata, 0.0);
  const cv::Mat png = cv::imread(request.out_dir + "/mosaic_dr.png", cv::IMREAD_GRAYSCALE);
  ASSERT_FALSE(png.empty());
  const double png_pixels = cv::countNonZero(png);
  const double tif_pixels = static_cast<double>(std::count_if(tif.values.begin(), tif.values.end(), [](double v) { return v != 0.0; }));
  EXPECT_NEAR(tif_pixels, png_pixels, 0.05 * png_pixels) << "the same cells, warped by the 0.8 deg grid convergence";

  // The corrected copy: every ping with a pose rewritten (the first ping precedes the first fix).
  const std::string copy = request.corrected_dir + "/scotsman-iver2.xtf";
  EXPECT_EQ(s.corrected_copy, copy);
  EXPECT_EQ(s.corrected_records, s.pings_with_pose);
  EXPECT_EQ(s.corrected_records + s.corrected_records_without_pose, 461u);
  const auto slam = sss::eval::readTum(request.out_dir + "/slam.tum");
  ASSERT_TRUE(slam.ok && slam.origin) << slam.error;
  const sss::core::LocalTangentPlane plane(slam.origin->latitude_deg, slam.origin->longitude_deg);
  std::map<int64_t, Eigen::Vector3d> slam_at;
  for (const auto& pose : slam.poses) slam_at[pose.utime_us] = pose.T_world_body.translation;
  sss::xtf::XtfReader reader(copy);
  ASSERT_TRUE(reader.isOpen()) << reader.error();
  sss::sonar::DriverPing ping;
  std::vector<uint64_t> offsets;
  size_t compared = 0;
  double worst_m = 0.0;
  while (reader.next(ping)) {
    offsets.push_back(reader.lastPingOffset());
    const auto found = slam_at.find(ping.utime_us);
    if (found == slam_at.end()) continue;
    const auto& side = ping.ping.port ? *ping.ping.port : *ping.ping.starboard;
    const Eigen::Vector3d read_back = plane.toNed({side.latitude_deg, side.longitude_deg, side.depth_m});
    worst_m = std::max(worst_m, (read_back - found->second).head<2>().norm());
    ++compared;
  }
  EXPECT_EQ(compared, s.pings_with_pose);
  EXPECT_LT(worst_m, 1e-3) << "XTF stores doubles: slam.tum's 0.1 mm rounding";
  const std::string before = readFile(kRealFile), after = readFile(copy);
  ASSERT_EQ(before.size(), after.size());
  size_t outside = 0;
  for (size_t i = 0; i < before.size(); ++i) {
    if (before[i] == after[i]) continue;
    const auto packet = std::upper_bound(offsets.begin(), offsets.end(), static_cast<uint64_t>(i));
    const uint64_t at = packet == offsets.begin() ? 0 : i - *(packet - 1);  // 0: the file header
    const bool navigation = (at >= 160 && at < 176) || (at >= 192 && at < 196) || (at >= 204 && at < 216);
    outside += navigation ? 0 : 1;
  }
  EXPECT_EQ(outside, 0u) << "bytes outside the pings' navigation fields changed";
  fs::remove_all(request.out_dir);
}

TEST(RealFile, BottomTrackedAltitudeAloneGivesTheSameSubframes) {
  SKIP_WITHOUT_REAL_FILE();
  // As a towed fish without altitude would be processed: the returns only.
  const std::string dir = (fs::temp_directory_path() / ("sss_real_file_bt_" + std::to_string(getpid()))).string();
  fs::create_directories(dir);
  {
    std::ofstream config(dir + "/config.yaml");
    config << "subframe_buffer:\n  fusion:\n    altitude_source: bottom_track\n";
  }
  sss::offline::OfflineRequest request;
  request.sonar_path = kRealFile;
  request.config_path = dir + "/config.yaml";
  request.out_dir = dir + "/run";
  request.write_mosaics = false;
  const auto result = sss::offline::runOffline(request);
  ASSERT_TRUE(result.ok) << result.error;
  const auto& s = result.summary;
  EXPECT_GE(s.pings_with_pose, 438u);
  EXPECT_GE(s.buffer.fusion.altitude_from_bottom_track, 438u);
  EXPECT_EQ(s.buffer.fusion.altitude_from_nav, 0u);
  EXPECT_GE(s.subframes, 1u);
  fs::remove_all(dir);
}

}  // namespace
