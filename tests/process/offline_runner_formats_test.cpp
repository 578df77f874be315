// sss-process's runner on files from other sonars and set-ups, built from the formats' public
// layouts: XTF in projected metres without altitude, XTF navigation packets or ship coordinates,
// JSF situation or NMEA messages as the only navigation, a towed fish on a curved line.
#include "tests/process/offline_runner_fixture.hpp"
#include "tests/xtf/xtf_test_data.hpp"
#include "drivers/edgetech/jsf_file_reader.hpp"

namespace {

// One JSF sonar data message of a seabed at altitude_m (3 cm samples, 1/range fall-off, one-look
// speckle) with the record's header fields, appended to the file: type 80, or the older type 82.
void writeJsfSeabedRecord(std::ofstream& out, sss::sonar::SonarChannelRecord record, double altitude_m,
                          std::mt19937& random, uint8_t& sequence, bool old_message = false) {
  std::exponential_distribution<double> speckle(1.0);
  record.sample_interval_s = 4e-5;  // 3 cm
  std::vector<float> magnitudes;
  for (int k = 0; k < 2500; ++k) {
    const double r = k * 0.03;
    magnitudes.push_back(static_cast<float>((r < altitude_m ? 2.0 : 400.0 * altitude_m / r) * speckle(random)));
  }
  int16_t weighting = 0;
  const auto codes = sss::edgetech::quantiseEnvelope(magnitudes, weighting);
  record.weighting_factor = weighting;
  const auto bytes = old_message ? sss::edgetech::encodeOldSideScanData(record, codes, sequence++)
                                 : sss::edgetech::encodeSonarData(record, codes, sequence++);
  out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
}

// The largest difference between the poses' heading and course_rad, in degrees.
template <typename Poses>
double worstHeadingErrorDeg(const Poses& poses, double course_rad) {
  double worst_deg = 0.0;
  for (const auto& pose : poses) {
    const Eigen::Matrix3d r = pose.T_world_body.rotation.toRotationMatrix();
    worst_deg = std::max(worst_deg, std::abs(std::remainder(std::atan2(r(1, 0), r(0, 0)) - course_rad, 2.0 * M_PI)) *
                                        180.0 / M_PI);
  }
  return worst_deg;
}

// The worst distance of a run's DR poses from a straight track flown from the first recorded
// position along `along` at step_m per 4 Hz ping from 1780300800 s, moved back by back_m (a
// towfish's layback).
double worstFromTrack(const std::string& dir, const Eigen::Vector2d& along, double step_m, double back_m) {
  const auto dr = sss::eval::readTum(dir + "/dead_reckoning.tum");
  EXPECT_TRUE(dr.ok) << dr.error;
  EXPECT_GT(dr.poses.size(), 300u);
  double worst_m = 0.0;
  for (const auto& pose : dr.poses) {
    const double i = static_cast<double>(pose.utime_us - 1780300800000000LL) / 250000.0;
    const Eigen::Vector2d expected = (step_m * i - back_m) * along;
    worst_m = std::max(worst_m, (pose.T_world_body.translation.head<2>() - expected).norm());
  }
  return worst_m;
}

// True when one of the run's findings contains text.
bool hasFinding(const sss::offline::OfflineResult& result, const std::string& text) {
  return std::any_of(result.summary.findings.begin(), result.summary.findings.end(),
                     [&](const std::string& f) { return f.find(text) != std::string::npos; });
}

// A recorder that stamps every ping with its newest GPS fix: a 1 Hz GPS under a 4 Hz sonar repeats
// each position for four pings, then jumps 2 m (the real Iver2 XTF repeats its fixes for 2-6 pings).
// The repeats are no new fixes: they are placed between the fixes in time, so the track advances
// every ping, on the straight line flown, instead of a staircase of 2 m steps.
TEST_F(OfflineRunnerTest, PositionsRepeatedUntilTheNextGpsFixArePlacedBetweenTheFixes) {
  const sss::xtf::XtfWriterOptions options = sss::test::makeXtfOptions({100.0f}, 2, sss::xtf::kNavUnitsMetres);
  const std::string path = root_ + "/gps_1hz.xtf";
  const double heading_rad = 30.0 * M_PI / 180.0, speed_m_s = 2.0, altitude_m = 15.0, spacing_m = 0.03;
  {
    sss::xtf::XtfWriter writer(path, options);
    ASSERT_TRUE(writer.isOpen());
    std::mt19937 random(5);
    for (int i = 0; i < 400; ++i) {  // 100 s at 4 Hz
      const double fix_s = std::floor(0.25 * i);  // the newest whole-second fix
      sss::xtf::XtfPingInput ping;
      ping.ping_number = static_cast<uint32_t>(i);
      ping.ping_time_us = 1780300800000000LL + i * 250000LL;
      ping.sound_velocity = 750.0f;
      ping.sensor_x = 650123.0 + speed_m_s * fix_s * std::sin(heading_rad);   // easting
      ping.sensor_y = 6580456.0 + speed_m_s * fix_s * std::cos(heading_rad);  // northing
      ping.depth_m = 30.0f;
      ping.heading_deg = 30.0f;
      ping.altitude_m = static_cast<float>(altitude_m);
      addSeabedChannels(ping, 2500, spacing_m, altitude_m, random);
      ASSERT_TRUE(writer.write(ping));
    }
  }
  const std::string out_dir = root_ + "/run_gps_1hz";
  const auto result = runSonarFileOnly(path, out_dir);
  ASSERT_TRUE(result.ok) << result.error;
  const auto& s = result.summary;
  EXPECT_EQ(s.pings, 400u);
  EXPECT_EQ(s.nav_positions_interpolated, 99u * 3u) << "three repeats a second between the first and the last fix";
  EXPECT_NE(readFile(out_dir + "/summary.json").find("\"positions_interpolated\": 297"), std::string::npos);
  const auto dr = sss::eval::readTum(out_dir + "/dead_reckoning.tum");
  ASSERT_TRUE(dr.ok) << dr.error;
  ASSERT_GT(dr.poses.size(), 300u);
  double worst_m = 0.0;
  size_t checked = 0;
  for (const auto& pose : dr.poses) {
    const double t_s = 1e-6 * static_cast<double>(pose.utime_us - 1780300800000000LL);
    if (t_s > 99.0) continue;  // after the last fix the position is held (nothing follows it)
    const Eigen::Vector2d truth = speed_m_s * t_s * Eigen::Vector2d(std::cos(heading_rad), std::sin(heading_rad));
    worst_m = std::max(worst_m, (pose.T_world_body.translation.head<2>() - truth).norm());
    ++checked;
  }
  std::printf("1 Hz GPS under 4 Hz pings: %zu poses, worst %.3f m off the line flown\n", checked, worst_m);
  EXPECT_GT(checked, 300u);
  EXPECT_LT(worst_m, 0.01) << "held positions were up to 1.5 m behind the vehicle";
}

// An XTF whose header says projected metres (NavUnits 0) while its pings hold latitude and
// longitude: read as metres, a 300 m line moves 3 mm. The run says what the positions look like and
// names the key; with sonar_driver.xtf_nav_units: latlon the file is read in degrees.
TEST_F(OfflineRunnerTest, DegreesInAFileDeclaredMetresAreNamedAndReadWithTheOverride) {
  const sss::xtf::XtfWriterOptions options = sss::test::makeXtfOptions({100.0f}, 2, sss::xtf::kNavUnitsMetres);
  const std::string path = root_ + "/degrees_as_metres.xtf";
  const sss::core::LocalTangentPlane plane(57.7, 11.9);
  const double heading_rad = 30.0 * M_PI / 180.0;
  {
    sss::xtf::XtfWriter writer(path, options);
    ASSERT_TRUE(writer.isOpen());
    std::mt19937 random(4);
    for (int i = 0; i < 600; ++i) {  // 150 s at 4 Hz, 2 m/s
      const auto geo = plane.toGeodetic(0.5 * i * Eigen::Vector3d(std::cos(heading_rad), std::sin(heading_rad), 0.0));
      sss::xtf::XtfPingInput ping;
      ping.ping_number = static_cast<uint32_t>(i);
      ping.ping_time_us = 1780300800000000LL + i * 250000LL;
      ping.sound_velocity = 750.0f;
      ping.sensor_y = geo.latitude_deg;
      ping.sensor_x = geo.longitude_deg;
      ping.depth_m = 30.0f;
      ping.altitude_m = 15.0f;
      ping.heading_deg = 30.0f;
      addSeabedChannels(ping, 2500, 0.03, 15.0, random);
      ASSERT_TRUE(writer.write(ping));
    }
  }
  const auto as_declared = runSonarFileOnly(path, root_ + "/run_degrees_as_metres");
  ASSERT_TRUE(as_declared.ok) << as_declared.error;
  EXPECT_LT(as_declared.summary.projected_track_m, 0.01);
  EXPECT_NE(std::find_if(as_declared.summary.findings.begin(), as_declared.summary.findings.end(),
                         [](const std::string& f) { return f.find("xtf_nav_units: latlon") != std::string::npos; }),
            as_declared.summary.findings.end());

  const std::string config = root_ + "/nav_units_latlon.yaml";
  std::ofstream(config) << "sonar_driver:\n  xtf_nav_units: latlon\n";
  sss::offline::OfflineRequest forced;
  forced.sonar_path = path;
  forced.config_path = config;
  forced.out_dir = root_ + "/run_degrees_forced";
  forced.write_mosaics = false;
  const auto result = sss::offline::runOffline(forced);
  ASSERT_TRUE(result.ok) << result.error;
  ASSERT_TRUE(result.summary.origin);
  EXPECT_NEAR(result.summary.origin->latitude_deg, 57.7, 1e-6);
  EXPECT_EQ(result.summary.projected_track_m, -1.0);
  const auto dr = sss::eval::readTum(forced.out_dir + "/dead_reckoning.tum");
  ASSERT_TRUE(dr.ok) << dr.error;
  const Eigen::Vector3d last = dr.poses.back().T_world_body.translation;
  const double along_m = 0.5 * 599;
  EXPECT_NEAR(last.x(), along_m * std::cos(heading_rad), 0.5);
  EXPECT_NEAR(last.y(), along_m * std::sin(heading_rad), 0.5);
  for (const std::string& f : result.summary.findings) EXPECT_EQ(f.find("xtf_nav_units"), std::string::npos) << f;
}

// An XTF with its navigation in projected metres (NavUnits 0, as Isis writes it) and no altitude
// (a towed fish), with attitude packets between the pings, built from the public layout: it is
// processed in the file's own grid (north = northing - N0 of the first fix), says so, and tracks
// the bottom; and a multibeam-only file is refused in one line.
TEST_F(OfflineRunnerTest, XtfInProjectedMetresWithoutAltitudeIsProcessedInItsGrid) {
  // One 100 kHz port/starboard pair of 16-bit samples, navigation in projected metres.
  const sss::xtf::XtfWriterOptions options = sss::test::makeXtfOptions({100.0f}, 2, sss::xtf::kNavUnitsMetres);
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
    sss::sonar::DriverPing ping;
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
 // Situation (2090) or NMEA (2002) messages with type 80 side-scan; and NMEA with the older
 // side-scan message 82, which has no position field at all.
 for (const int mode : {0, 1, 2}) {
  const bool nmea = mode >= 1, old_side_scan = mode == 2;
  const std::string path = root_ + (old_side_scan ? "/old_side_scan.jsf" : nmea ? "/nmea.jsf" : "/situation.jsf");
  const sss::core::LocalTangentPlane plane(-12.5, 130.8);
  const double heading_rad = 250.0 * M_PI / 180.0;
  {
    std::ofstream out(path, std::ios::binary);
    std::mt19937 random(8);
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
      for (uint8_t channel : {sss::sonar::kChannelPort, sss::sonar::kChannelStarboard}) {
        sss::sonar::SonarChannelRecord record;
        record.channel = channel;
        record.ping_time_us = utime_us;
        record.ping_number = static_cast<uint32_t>(i);
        record.validity = sss::sonar::kValidHeading | sss::sonar::kValidSoundSpeed;  // no position, no altitude
        record.heading_rad = heading_rad;
        writeJsfSeabedRecord(out, record, 15.0, random, sequence, old_side_scan);
      }
    }
  }
  const std::string out_dir = root_ + (old_side_scan ? "/run_old_side_scan" : nmea ? "/run_nmea" : "/run_situation");
  SCOPED_TRACE(out_dir);
  const auto result = runSonarFileOnly(path, out_dir);
  ASSERT_TRUE(result.ok) << result.error;
  const auto& s = result.summary;
  EXPECT_EQ(s.pings, 600u);
  EXPECT_EQ(s.jsf_old_side_scan_messages, old_side_scan ? 1200u : 0u);
  if (old_side_scan) {
    // Message 82 has no position field: a corrected copy cannot hold the track, and says so.
    sss::offline::OfflineRequest copy;
    copy.sonar_path = path;
    copy.out_dir = out_dir + "_copy";
    copy.write_mosaics = false;
    copy.corrected_dir = copy.out_dir + "/corrected";
    const auto copied = sss::offline::runOffline(copy);
    ASSERT_TRUE(copied.ok) << copied.error;
    EXPECT_EQ(copied.summary.corrected_records_without_position_field, 1200u);
    EXPECT_TRUE(hasFinding(copied, "no position field"));
  }
  const auto dr = sss::eval::readTum(out_dir + "/dead_reckoning.tum");
  ASSERT_TRUE(dr.ok) << dr.error;
  EXPECT_LT(worstHeadingErrorDeg(dr.poses, heading_rad), 0.02) << "the ping headers' heading";
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

// A towfish without a compass: its JSF ping headers carry the position (1 Hz GPS, repeated in
// between) but the heading validity bit is clear and the heading field 0. Taken as recorded, every
// image would be turned to north while the fish runs at 60 deg. With the recorded course over
// ground (validity bit 1) that stands in; without it, the track's own direction does. Either way
// the run says so.
TEST_F(OfflineRunnerTest, JsfWithoutAValidHeadingTakesTheCourseOverGround) {
  for (const bool course_recorded : {true, false}) {
    SCOPED_TRACE(course_recorded ? "course recorded" : "course from the track");
    const std::string path = root_ + (course_recorded ? "/no_heading_course.jsf" : "/no_heading.jsf");
    const sss::core::LocalTangentPlane plane(43.1, 5.9);
    const double course_rad = 60.0 * M_PI / 180.0;
    {
      std::ofstream out(path, std::ios::binary);
      std::mt19937 random(9);
      uint8_t sequence = 0;
      for (int i = 0; i < 600; ++i) {  // 150 s at 4 Hz, 1.5 m/s
        const double fix_s = std::floor(0.25 * i);
        const auto geo = plane.toGeodetic(1.5 * fix_s * Eigen::Vector3d(std::cos(course_rad), std::sin(course_rad), 0.0));
        for (uint8_t channel : {sss::sonar::kChannelPort, sss::sonar::kChannelStarboard}) {
          sss::sonar::SonarChannelRecord record;
          record.channel = channel;
          record.ping_time_us = 1780300800000000LL + i * 250000LL;
          record.ping_number = static_cast<uint32_t>(i);
          record.validity = sss::sonar::kValidLatLon | sss::sonar::kValidAltitude | sss::sonar::kValidDepth |
                            sss::sonar::kValidSoundSpeed | (course_recorded ? sss::sonar::kValidCourse : 0);
          record.latitude_deg = geo.latitude_deg;
          record.longitude_deg = geo.longitude_deg;
          record.depth_m = 20.0;
          record.altitude_m = 12.0;
          record.heading_rad = 0.0;  // no compass: the field is left 0
          record.course_rad = course_rad;
          writeJsfSeabedRecord(out, record, 12.0, random, sequence);
        }
      }
    }
    const std::string out_dir = root_ + (course_recorded ? "/run_no_heading_course" : "/run_no_heading");
    const auto result = runSonarFileOnly(path, out_dir);
    ASSERT_TRUE(result.ok) << result.error;
    const auto& s = result.summary;
    EXPECT_GE(s.pings_with_pose, 570u);
    if (course_recorded) {
      EXPECT_EQ(s.nav_headings_from_course, 600u);
      EXPECT_EQ(s.nav_headings_from_track, 0u);
    } else {
      EXPECT_EQ(s.nav_headings_from_course, 0u);
      EXPECT_EQ(s.nav_headings_from_track, 600u) << "the first 10 m wait for the track's direction";
    }
    EXPECT_EQ(s.nav_headings_unknown, 0u);
    EXPECT_NE(std::find_if(s.findings.begin(), s.findings.end(),
                           [](const std::string& f) { return f.find("no valid heading") != std::string::npos; }),
              s.findings.end());
    const auto dr = sss::eval::readTum(out_dir + "/dead_reckoning.tum");
    ASSERT_TRUE(dr.ok) << dr.error;
    ASSERT_GT(dr.poses.size(), 500u);
    const double worst_deg = worstHeadingErrorDeg(dr.poses, course_rad);
    std::printf("no compass, %s: heading worst %.2f deg off the 60 deg run\n",
                course_recorded ? "course recorded" : "course from the track", worst_deg);
    // The recorded course: 60 in whole degrees. The track's: a JSF position is quantised to 1e-4 arc
    // minute (0.19 m north, 0.14 m east here), which turns a 10 m base by up to ~0.9 deg.
    EXPECT_LT(worst_deg, course_recorded ? 0.01 : 1.0);
  }
}

// A towed JSF whose headers carry a 25 m layback (bytes 228-231). JSF does not say whether the
// header's position is the ship's GPS or the fish's: by default the positions are used as recorded
// and the run names the layback and the key; with sonar_driver.jsf_layback: apply the fish is put
// 25 m back along its heading, and the corrected copy holds that position with layback 0.
TEST_F(OfflineRunnerTest, JsfLaybackIsNamedAndAppliedOnRequest) {
  const sss::core::LocalTangentPlane plane(43.1, 5.9);
  const double heading_rad = 120.0 * M_PI / 180.0, layback_m = 25.0;
  const Eigen::Vector2d along(std::cos(heading_rad), std::sin(heading_rad));
  const std::string path = root_ + "/towed_layback.jsf";
  {
    std::ofstream out(path, std::ios::binary);
    std::mt19937 random(12);
    uint8_t sequence = 0;
    for (int i = 0; i < 400; ++i) {  // 100 s at 4 Hz, 1.5 m/s
      const Eigen::Vector2d ship = 0.375 * i * along;
      const auto geo = plane.toGeodetic(Eigen::Vector3d(ship.x(), ship.y(), 0.0));
      for (uint8_t channel : {sss::sonar::kChannelPort, sss::sonar::kChannelStarboard}) {
        sss::sonar::SonarChannelRecord record;
        record.channel = channel;
        record.ping_time_us = 1780300800000000LL + i * 250000LL;
        record.ping_number = static_cast<uint32_t>(i);
        record.validity = sss::sonar::kValidLatLon | sss::sonar::kValidAltitude | sss::sonar::kValidDepth |
                          sss::sonar::kValidSoundSpeed | sss::sonar::kValidHeading;
        record.latitude_deg = geo.latitude_deg;
        record.longitude_deg = geo.longitude_deg;
        record.depth_m = 20.0;
        record.altitude_m = 12.0;
        record.heading_rad = heading_rad;
        record.layback_m = layback_m;
        writeJsfSeabedRecord(out, record, 12.0, random, sequence);
      }
    }
  }
  const auto as_recorded = runSonarFileOnly(path, root_ + "/run_jsf_layback_ignored");
  ASSERT_TRUE(as_recorded.ok) << as_recorded.error;
  EXPECT_EQ(as_recorded.summary.jsf_records_with_layback, 800u);
  EXPECT_DOUBLE_EQ(as_recorded.summary.jsf_max_layback_m, layback_m);
  EXPECT_EQ(as_recorded.summary.nav_laybacks_applied, 0u);
  EXPECT_TRUE(hasFinding(as_recorded, "jsf_layback: apply"));
  // JSF positions: 1e-4 arc minute.
  EXPECT_LT(worstFromTrack(root_ + "/run_jsf_layback_ignored", along, 0.375, 0.0), 0.3);

  const std::string config = root_ + "/jsf_layback_apply.yaml";
  std::ofstream(config) << "sonar_driver:\n  jsf_layback: apply\n";
  sss::offline::OfflineRequest apply;
  apply.sonar_path = path;
  apply.config_path = config;
  apply.out_dir = root_ + "/run_jsf_layback_applied";
  apply.write_mosaics = false;
  apply.corrected_dir = apply.out_dir + "/corrected";
  const auto applied = sss::offline::runOffline(apply);
  ASSERT_TRUE(applied.ok) << applied.error;
  EXPECT_GE(applied.summary.nav_laybacks_applied, 390u);
  EXPECT_TRUE(hasFinding(applied, "jsf_layback: ignore"));
  EXPECT_LT(worstFromTrack(apply.out_dir, along, 0.375, layback_m), 0.3);
  // The corrected copy: layback 0 in every record it patched.
  sss::edgetech::JsfFileReader copy(apply.corrected_dir + "/towed_layback.jsf");
  ASSERT_TRUE(copy.isOpen()) << copy.error();
  sss::edgetech::JsfMessage message;
  size_t patched = 0, with_layback = 0;
  while (copy.next(message)) {
    if (message.header.message_type != sss::edgetech::kJsfSonarData) continue;
    const auto record = sss::edgetech::decodeSonarData(message.header, message.body.data(), message.body.size());
    ASSERT_TRUE(record.ok()) << record.message();
    if (record->layback_m > 0.0) ++with_layback;
    ++patched;
  }
  EXPECT_EQ(patched, 800u);
  EXPECT_EQ(with_layback, 800u - applied.summary.corrected_records);
}

// A JSF of the high frequency only (subsystem 21, the configuration's 20) is processed, and the
// run says which subsystem it took; one holding two other frequencies (21 and 22) is not guessed
// between: no pings, and the error names the records ignored and the key to set.
TEST_F(OfflineRunnerTest, JsfOfAnotherFrequencyIsTakenAndTwoOthersAreNamed) {
  const sss::core::LocalTangentPlane plane(43.1, 5.9);
  auto write = [&](const std::string& path, const std::vector<uint8_t>& subsystems) {
    std::ofstream out(path, std::ios::binary);
    std::mt19937 random(10);
    uint8_t sequence = 0;
    for (int i = 0; i < 400; ++i) {  // 100 s at 4 Hz, 1.5 m/s east
      const auto geo = plane.toGeodetic(Eigen::Vector3d(0.0, 0.375 * i, 0.0));
      for (const uint8_t subsystem : subsystems) {
        for (uint8_t channel : {sss::sonar::kChannelPort, sss::sonar::kChannelStarboard}) {
          sss::sonar::SonarChannelRecord record;
          record.subsystem = subsystem;
          record.channel = channel;
          record.ping_time_us = 1780300800000000LL + i * 250000LL;
          record.ping_number = static_cast<uint32_t>(i);
          record.validity = sss::sonar::kValidLatLon | sss::sonar::kValidHeading | sss::sonar::kValidAltitude |
                            sss::sonar::kValidSoundSpeed;
          record.latitude_deg = geo.latitude_deg;
          record.longitude_deg = geo.longitude_deg;
          record.altitude_m = 12.0;
          record.heading_rad = 0.5 * M_PI;
          writeJsfSeabedRecord(out, record, 12.0, random, sequence);
        }
      }
    }
  };
  const std::string high = root_ + "/high_only.jsf", two = root_ + "/two_others.jsf";
  write(high, {sss::sonar::kSubsystemSideScanHigh});
  write(two, {sss::sonar::kSubsystemSideScanHigh, sss::sonar::kSubsystemSideScanHigh + 1});
  const auto taken = runSonarFileOnly(high, root_ + "/run_high_only");
  ASSERT_TRUE(taken.ok) << taken.error;
  EXPECT_EQ(taken.summary.pings, 400u);
  EXPECT_EQ(taken.summary.jsf_adopted_subsystem, sss::sonar::kSubsystemSideScanHigh);
  EXPECT_NE(std::find_if(taken.summary.findings.begin(), taken.summary.findings.end(),
                         [](const std::string& f) { return f.find("only of subsystem 21") != std::string::npos; }),
            taken.summary.findings.end());
  const auto refused = runSonarFileOnly(two, root_ + "/run_two_others");
  EXPECT_FALSE(refused.ok);
  EXPECT_NE(refused.error.find("1600 sonar records of other subsystems"), std::string::npos) << refused.error;
  EXPECT_NE(refused.error.find("set sonar_driver.subsystem"), std::string::npos) << refused.error;
}

// The same fish in an XTF, which has no validity flags: its SensorHeading is 0 in every ping.
// Exactly 0 is taken as no heading, and the track's direction stands in.
TEST_F(OfflineRunnerTest, XtfWithHeadingZeroInEveryPingTakesTheTracksDirection) {
  const sss::xtf::XtfWriterOptions options = sss::test::makeXtfOptions({100.0f}, 2, sss::xtf::kNavUnitsMetres);
  const std::string path = root_ + "/no_compass.xtf";
  const double course_rad = 60.0 * M_PI / 180.0;
  {
    sss::xtf::XtfWriter writer(path, options);
    ASSERT_TRUE(writer.isOpen());
    std::mt19937 random(6);
    for (int i = 0; i < 400; ++i) {  // 100 s at 4 Hz, 1.5 m/s
      sss::xtf::XtfPingInput ping;
      ping.ping_number = static_cast<uint32_t>(i);
      ping.ping_time_us = 1780300800000000LL + i * 250000LL;
      ping.sound_velocity = 750.0f;
      ping.sensor_x = 650123.0 + 1.5 * 0.25 * i * std::sin(course_rad);
      ping.sensor_y = 6580456.0 + 1.5 * 0.25 * i * std::cos(course_rad);
      ping.depth_m = 20.0f;
      ping.altitude_m = 12.0f;
      ping.heading_deg = 0.0f;
      addSeabedChannels(ping, 2500, 0.03, 12.0, random);
      ASSERT_TRUE(writer.write(ping));
    }
  }
  const auto result = runSonarFileOnly(path, root_ + "/run_no_compass_xtf");
  ASSERT_TRUE(result.ok) << result.error;
  EXPECT_EQ(result.summary.nav_headings_from_track, 400u);
  const auto dr = sss::eval::readTum(root_ + "/run_no_compass_xtf/dead_reckoning.tum");
  ASSERT_TRUE(dr.ok) << dr.error;
  EXPECT_LT(worstHeadingErrorDeg(dr.poses, course_rad), 0.01);
}

// A towfish 40 m behind the ship, recorded as Isis records a tow: SensorY/X are the ship's GPS
// (equal to ShipY/X) and Layback says how far back the fish is. Every pose is the fish's, 40 m
// back along the heading, and the run says so; with sonar_driver.xtf_layback: ignore the poses stay
// on the ship's positions; a file whose writer already put the fish apart from the ship is not
// moved a second time; the corrected copy holds the fish's position with Layback 0, so that a
// reader following Isis does not move it back again.
TEST_F(OfflineRunnerTest, TowfishLaybackOverTheShipsPositionPutsTheFishBehindTheShip) {
  const sss::xtf::XtfWriterOptions options = sss::test::makeXtfOptions({100.0f}, 2, sss::xtf::kNavUnitsMetres);
  const double course_rad = 60.0 * M_PI / 180.0, layback_m = 40.0, step_m = 1.5 * 0.25;
  const Eigen::Vector2d along(std::cos(course_rad), std::sin(course_rad));  // north, east
  const Eigen::Vector2d ship0(6580456.0, 650123.0);
  auto write = [&](const std::string& path, bool fish_apart_from_ship, float heading_deg = 60.0f) {
    sss::xtf::XtfWriter writer(path, options);
    ASSERT_TRUE(writer.isOpen());
    std::mt19937 random(8);
    for (int i = 0; i < 400; ++i) {  // 100 s at 4 Hz, 1.5 m/s
      const Eigen::Vector2d ship = ship0 + step_m * i * along;
      const Eigen::Vector2d sensor = fish_apart_from_ship ? Eigen::Vector2d(ship - layback_m * along) : ship;
      sss::xtf::XtfPingInput ping;
      ping.ping_number = static_cast<uint32_t>(i);
      ping.ping_time_us = 1780300800000000LL + i * 250000LL;
      ping.sound_velocity = 750.0f;
      ping.ship_y = ship.x();
      ping.ship_x = ship.y();
      ping.sensor_y = sensor.x();
      ping.sensor_x = sensor.y();
      ping.layback_m = static_cast<float>(layback_m);
      ping.depth_m = 20.0f;
      ping.altitude_m = 12.0f;
      ping.heading_deg = heading_deg;
      addSeabedChannels(ping, 2500, 0.03, 12.0, random);
      ASSERT_TRUE(writer.write(ping));
    }
  };

  const std::string ship_file = root_ + "/towed_ship_position.xtf";
  write(ship_file, false);
  sss::offline::OfflineRequest towed;
  towed.sonar_path = ship_file;
  towed.out_dir = root_ + "/run_towed_layback";
  towed.write_mosaics = false;
  towed.corrected_dir = towed.out_dir + "/corrected";
  const auto applied = sss::offline::runOffline(towed);
  ASSERT_TRUE(applied.ok) << applied.error;
  EXPECT_EQ(applied.summary.xtf_layback_pings, 400u);
  EXPECT_EQ(applied.summary.nav_laybacks_applied, 400u);
  EXPECT_DOUBLE_EQ(applied.summary.nav_max_layback_m, layback_m);
  EXPECT_TRUE(hasFinding(applied, "xtf_layback: ignore"));
  EXPECT_LT(worstFromTrack(towed.out_dir, along, step_m, layback_m), 0.01);

  // The corrected copy: the fish's position (the run's poses) and Layback 0.
  const auto slam = sss::eval::readTum(towed.out_dir + "/slam.tum");
  ASSERT_TRUE(slam.ok) << slam.error;
  std::map<int64_t, Eigen::Vector3d> slam_at;
  for (const auto& p : slam.poses) slam_at[p.utime_us] = p.T_world_body.translation;
  sss::xtf::XtfReader copy(towed.corrected_dir + "/towed_ship_position.xtf");
  ASSERT_TRUE(copy.isOpen()) << copy.error();
  sss::sonar::DriverPing ping;
  size_t compared = 0;
  double worst_m = 0.0;
  while (copy.next(ping)) {
    const auto found = slam_at.find(ping.utime_us);
    if (found == slam_at.end()) continue;
    const auto& side = *ping.ping.port;
    EXPECT_EQ(side.layback_m, 0.0);  // apart from the ship now: nothing left to apply
    worst_m = std::max(worst_m, (Eigen::Vector2d(side.northing_m, side.easting_m) - ship0 - found->second.head<2>()).norm());
    ++compared;
  }
  EXPECT_EQ(compared, applied.summary.pings_with_pose);
  EXPECT_EQ(copy.counters().pings_layback_to_apply, 0u);
  EXPECT_LT(worst_m, 1e-3);

  const std::string config = root_ + "/layback_ignore.yaml";
  std::ofstream(config) << "sonar_driver:\n  xtf_layback: ignore\n";
  towed.config_path = config;
  towed.out_dir = root_ + "/run_towed_ignore";
  towed.corrected_dir = towed.out_dir + "/corrected";
  const auto ignored = sss::offline::runOffline(towed);
  ASSERT_TRUE(ignored.ok) << ignored.error;
  EXPECT_EQ(ignored.summary.nav_laybacks_applied, 0u);
  EXPECT_FALSE(hasFinding(ignored, "layback"));
  EXPECT_LT(worstFromTrack(towed.out_dir, along, step_m, 0.0), 0.01);
  {
    // Not applied: the copy keeps its Layback over the (ship's) positions it writes.
    sss::xtf::XtfReader kept(towed.corrected_dir + "/towed_ship_position.xtf");
    ASSERT_TRUE(kept.isOpen()) << kept.error();
    while (kept.next(ping)) {
    }
    EXPECT_EQ(kept.counters().pings_layback_to_apply + kept.counters().pings_layback_in_position, 400u);
  }

  const std::string fish_file = root_ + "/towed_fish_position.xtf";
  write(fish_file, true);
  const auto as_recorded = runSonarFileOnly(fish_file, root_ + "/run_towed_fish");
  ASSERT_TRUE(as_recorded.ok) << as_recorded.error;
  EXPECT_EQ(as_recorded.summary.nav_laybacks_applied, 0u);
  EXPECT_EQ(as_recorded.summary.xtf_layback_in_position_pings, 400u);
  EXPECT_LT(worstFromTrack(root_ + "/run_towed_fish", along, step_m, 0.0), 0.01);  // origin: the fish's first position

  // A towfish without a compass (heading 0 in every ping): moved back along the track's direction.
  const std::string no_compass_file = root_ + "/towed_no_compass.xtf";
  write(no_compass_file, false, 0.0f);
  const auto along_track = runSonarFileOnly(no_compass_file, root_ + "/run_towed_no_compass");
  ASSERT_TRUE(along_track.ok) << along_track.error;
  EXPECT_EQ(along_track.summary.nav_headings_from_track, 400u);
  EXPECT_EQ(along_track.summary.nav_laybacks_applied, 400u);
  EXPECT_LT(worstFromTrack(root_ + "/run_towed_no_compass", along, step_m, layback_m), 0.01);
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

}  // namespace
