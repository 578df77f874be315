// Whole short missions on disk: same seed -> same bytes (any thread count), different seed ->
// different bytes, JSF type 80 fields at their exact byte offsets, TUM and seabed outputs.
#include "tools/sim/mission.hpp"
#include "pipeline/core/mission_origin.hpp"

#include "drivers/edgetech/jsf_format.hpp"
#include "tests/support/status_assertions.hpp"

#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>

#include <unistd.h>

namespace sss::sim {
namespace {

SimOptions shortMission(int64_t seed) {
  SimOptions options;
  options.seed = seed;
  options.trajectory.lines = 2;
  options.trajectory.line_length_m = 40.0;
  options.trajectory.line_spacing_m = 40.0;
  options.duration_s = 6.0;  // 25 pings
  options.seabed.resolution_m = 0.2;
  options.sonar.samples_per_side = 2000;
  return options;
}

std::string readFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

std::string tempDir(const std::string& name) {
  const std::string dir = (std::filesystem::temp_directory_path() / ("sss_sim_test_" + name + "_" +
                                                                      std::to_string(::getpid()))).string();
  std::filesystem::remove_all(dir);
  return dir;
}

template <typename T>
T readLe(const std::string& bytes, size_t offset) {
  T value;
  std::memcpy(&value, bytes.data() + offset, sizeof(T));  // the test host is little-endian
  return value;
}

TEST(Mission, SameSeedGivesSameBytesOnAnyThreadCountDifferentSeedDiffers) {
  const std::string a = tempDir("a"), b = tempDir("b"), c = tempDir("c");
  MissionReport report;
  omp_set_num_threads(1);
  ASSERT_OK(writeMission(Mission(shortMission(5)), a, report));
  omp_set_num_threads(2);
  ASSERT_OK(writeMission(Mission(shortMission(5)), b, report));
  ASSERT_OK(writeMission(Mission(shortMission(6)), c, report));
  for (const char* file : {"sonar.jsf", "ground_truth.tum", "dead_reckoning.tum", "ins.nmea", "seabed_depth.f32",
                           "seabed_reflectivity.f32", "waterfall_line_00.png", "mosaic.png"}) {
    const std::string bytes_a = readFile(a + "/" + file);
    EXPECT_FALSE(bytes_a.empty()) << file;
    EXPECT_EQ(bytes_a, readFile(b + "/" + file)) << file;
  }
  EXPECT_NE(readFile(a + "/sonar.jsf"), readFile(c + "/sonar.jsf"));
  EXPECT_NE(readFile(a + "/seabed_depth.f32"), readFile(c + "/seabed_depth.f32"));
  EXPECT_NE(readFile(a + "/dead_reckoning.tum"), readFile(c + "/dead_reckoning.tum"));
  for (const std::string& dir : {a, b, c}) std::filesystem::remove_all(dir);
}

TEST(Mission, JsfSonarDataFieldsAtExactOffsets) {
  const SimOptions options = shortMission(9);
  const Mission mission(options);
  const size_t ping = 7;
  const PingSamples samples = mission.renderPing(ping);
  uint8_t sequence = 0;
  const std::vector<uint8_t> bytes_vector = mission.encodePingJsf(ping, samples, sequence);
  const std::string bytes(bytes_vector.begin(), bytes_vector.end());
  const int n = options.sonar.samples_per_side;
  const size_t message_size = 16 + 240 + 2 * static_cast<size_t>(n);
  ASSERT_EQ(bytes.size(), 2 * message_size);
  EXPECT_EQ(sequence, 2);
  for (int channel = 0; channel < 2; ++channel) {
    const size_t base = channel * message_size;
    EXPECT_EQ(readLe<uint16_t>(bytes, base + 0), 0x1601);
    EXPECT_EQ(readLe<uint16_t>(bytes, base + 4), 80);
    EXPECT_EQ(static_cast<uint8_t>(bytes[base + 7]), 20);  // side-scan low frequency (410 kHz)
    EXPECT_EQ(static_cast<uint8_t>(bytes[base + 8]), channel);
    EXPECT_EQ(readLe<int32_t>(bytes, base + 12), static_cast<int32_t>(240 + 2 * n));
    const size_t h = base + 16;
    const int64_t utime = mission.pingUtimeUs(ping);
    EXPECT_EQ(readLe<int32_t>(bytes, h + 0), utime / 1000000);
    EXPECT_EQ(readLe<uint32_t>(bytes, h + 8), ping);
    EXPECT_EQ(readLe<uint16_t>(bytes, h + 114), n);
    // 2 * 75 m / 1500 m/s / 2000 samples = 50 us.
    EXPECT_EQ(readLe<uint32_t>(bytes, h + 116), 50000u);
    EXPECT_EQ(readLe<int16_t>(bytes, h + 34), 0);  // envelope

    const std::optional<edgetech::JsfMessageHeader> header =
        edgetech::decodeHeader(reinterpret_cast<const uint8_t*>(bytes.data() + base));
    ASSERT_TRUE(header.has_value());
    const sss::core::Result<sonar::SonarChannelRecord> decoded =
        edgetech::decodeSonarData(*header, reinterpret_cast<const uint8_t*>(bytes.data() + h), message_size - 16);
    ASSERT_OK(decoded);
    const sonar::SonarChannelRecord& record = *decoded;
    EXPECT_EQ(record.ping_number, ping);
    EXPECT_EQ(record.channel, channel);
    EXPECT_EQ(record.ping_time_us / 1000, utime / 1000);  // JSF carries milliseconds
    EXPECT_NEAR(record.sample_interval_s, 50e-6, 1e-12);
    EXPECT_NEAR(record.slantRangeM(1000), 37.5, 1e-9);
    // DR navigation in the header: lat/lon to the 1e-4 minute resolution (~0.2 m), altitude mm.
    const NavSample nav = mission.deadReckoning().sampleAt(mission.pingTimeS(ping));
    const core::GeodeticPosition geo = mission.tangentPlane().toGeodetic(nav.T_world_body.translation);
    EXPECT_NEAR(record.latitude_deg, geo.latitude_deg, 2e-6);
    EXPECT_NEAR(record.longitude_deg, geo.longitude_deg, 2e-6);
    EXPECT_NEAR(record.altitude_m, nav.altitude_m, 1e-3);
    EXPECT_NEAR(record.altitude_m, 18.0, 0.6);
    // Samples survive quantisation to within one code step of the rendered magnitude.
    const std::vector<float>& rendered = channel == 0 ? samples.port : samples.starboard;
    ASSERT_EQ(record.samples.size(), rendered.size());
    const double step = std::ldexp(1.0, -record.weighting_factor);
    for (size_t i = 0; i < rendered.size(); i += 97) EXPECT_NEAR(record.samples[i], rendered[i], step) << i;
  }
}

TEST(Mission, OutputsHaveOneTumLinePerPingAndAConsistentSeabedRaster) {
  const std::string dir = tempDir("outputs");
  const Mission mission(shortMission(3));
  MissionReport report;
  ASSERT_OK(writeMission(mission, dir, report));
  std::istringstream tum(readFile(dir + "/ground_truth.tum"));
  // The first line names the frame's origin (sss-eval re-expresses runs with another origin).
  std::string header;
  ASSERT_TRUE(static_cast<bool>(std::getline(tum, header)));
  const auto origin = core::parseOriginCommentLine(header);
  ASSERT_TRUE(origin) << header;
  EXPECT_DOUBLE_EQ(origin->latitude_deg, mission.options().origin_latitude_deg);
  EXPECT_DOUBLE_EQ(origin->longitude_deg, mission.options().origin_longitude_deg);
  size_t lines = 0;
  for (std::string line; std::getline(tum, line); ++lines) {
    std::istringstream fields(line);
    double t, x, y, z, qx, qy, qz, qw;
    ASSERT_TRUE(static_cast<bool>(fields >> t >> x >> y >> z >> qx >> qy >> qz >> qw)) << line;
    EXPECT_NEAR(t, mission.pingUtimeUs(lines) * 1e-6, 1e-6);
    EXPECT_NEAR(std::sqrt(qx * qx + qy * qy + qz * qz + qw * qw), 1.0, 1e-6);
  }
  EXPECT_EQ(lines, mission.pingCount());
  EXPECT_EQ(mission.pingCount(), 25u);
  const std::string depth = readFile(dir + "/seabed_depth.f32");
  EXPECT_EQ(depth.size(), static_cast<size_t>(mission.seabed().rows()) * mission.seabed().cols() * sizeof(float));
  // The yaml written is a valid --config: reading it back gives the same options.
  core::Config config = core::Config::fromFile(dir + "/mission.yaml");
  ASSERT_TRUE(config.ok()) << config.problemReport();
  SimOptions reread;
  readSimOptions(config.section("sim"), reread);
  ASSERT_TRUE(config.ok()) << config.problemReport();
  EXPECT_EQ(simOptionsYaml(reread), simOptionsYaml(mission.options()));
  std::filesystem::remove_all(dir);
}

TEST(Mission, ValidationNamesTheKeyAndTheReason) {
  SimOptions options;
  options.sonar.ping_rate_hz = 12.0;  // > 1500 / 150 = 10 Hz
  const std::vector<std::string> problems = validateSimOptions(options);
  ASSERT_EQ(problems.size(), 1u);
  EXPECT_NE(problems[0].find("sim.sonar.ping_rate_hz"), std::string::npos) << problems[0];
  EXPECT_TRUE(validateSimOptions(SimOptions()).empty());
}

}  // namespace
}  // namespace sss::sim

namespace sss::sim {
namespace {

TEST(Mission, ConfigWithSomeSectionsKeepsTheOtherDefaults) {
  core::Config config = core::Config::fromString("sim:\n  seed: 12\n  sonar:\n    range_m: 100\n");
  SimOptions options;
  readSimOptions(config.section("sim"), options);
  ASSERT_TRUE(config.ok()) << config.problemReport();
  EXPECT_EQ(options.seed, 12);
  EXPECT_EQ(options.sonar.range_m, 100.0);
  EXPECT_EQ(options.trajectory.lines, 5);  // vehicle section absent: defaults
  core::Config typo = core::Config::fromString("sim:\n  vehicle:\n    altitdue_m: 10\n");
  readSimOptions(typo.section("sim"), options);
  ASSERT_EQ(typo.problems().size(), 1u);
  EXPECT_EQ(typo.problems()[0].key, "sim.vehicle.altitdue_m");
}

}  // namespace
}  // namespace sss::sim
