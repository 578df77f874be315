// sss-process's engine: inputs in time order through the chain's libraries, then the outputs.
// See offline_runner.hpp.
#include "tools/process/offline_runner.hpp"

#include <strings.h>
#include <sys/resource.h>

#include <lcm/lcm-cpp.hpp>
#include <nlohmann/json.hpp>
#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cstring>
#include <chrono>
#include <cmath>
#include <deque>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <random>
#include <vector>

#include "drivers/edgetech/ping_message.hpp"
#include "drivers/edgetech/sonar_driver.hpp"
#include "drivers/ins/ins_bridge.hpp"
#include "drivers/ins/nav_message.hpp"
#include "drivers/ins/nmea_gga.hpp"
#include "drivers/ins/fix_aligner.hpp"
#include "drivers/ins/position_fix.hpp"
#include "drivers/xtf/xtf_reader.hpp"
#include "pipeline/core/config.hpp"
#include "pipeline/core/geodesy.hpp"
#include "pipeline/core/mission_origin.hpp"
#include "pipeline/core/time.hpp"
#include "pipeline/matcher/matcher_engine.hpp"
#include "pipeline/optimiser/optimiser_engine.hpp"
#include "pipeline/subframe/pictures.hpp"
#include "products/corrected_copy.hpp"
#include "products/geotiff.hpp"
#include "products/mosaic_products.hpp"
#include "products/navigation_products.hpp"
#include "products/survey_rasters.hpp"
#include "pipeline/subframe/subframe_buffer.hpp"
#include "pipeline/messages/sensor_messages.hpp"
#include "tools/eval/json_writer.hpp"
#include "products/coverage.hpp"
#include "products/footprints.hpp"
#include "tools/process/match_writer.hpp"

namespace sss::offline {

namespace {

namespace fs = std::filesystem;
using sss::core::Pose;
using sss::subframe::NavInput;
using sss::subframe::PingInput;

double wallSeconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

double peakRssMib() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_maxrss) / 1024.0;  // ru_maxrss is in KiB on Linux
}

bool hasExtension(const std::string& path, const char* extension) {
  const size_t n = std::strlen(extension);
  return path.size() > n && strcasecmp(path.c_str() + path.size() - n, extension) == 0;
}

struct Options {
  // mission.origin_*: an override; unset, the first valid position of the navigation.
  std::optional<sss::core::MissionOrigin> origin;
  sss::edgetech::SonarDriverOptions sonar;
  sss::xtf::XtfReaderOptions xtf;
  sss::ins::InsBridgeOptions ins;
  sss::subframe::SubframeBufferOptions buffer;
  sss::matcher::MatcherEngineOptions matcher;
  sss::optimiser::OptimiserEngineOptions optimiser;
  sss::subframe::PictureOptions pictures;
  // Section `fixes`: how fix files are read, and the depth above which a GNSS fix is real (the
  // antenna is out of the water only at the surface; below, a receiver reports stale or no fixes).
  sss::ins::FixReaderOptions fix_reader;
  sss::ins::FixAlignerOptions fix_aligner;
  // Section `products`: the CRS of a projected input's grid (XTF does not record it), and whether
  // to write the GeoTIFFs.
  std::string projected_crs;
  bool write_geotiff = true;
};

// The library keys of each process's section; keys only a live process uses (ports, channels)
// are left alone here: each process's --check-config validates the whole file.
bool readOptions(const std::string& path, Options& options, std::string& error) {
  if (!path.empty()) {
    using namespace sss::core;
    Config config = Config::fromFile(path);
    ConfigSection mission = config.section("mission");
    options.origin = readMissionOrigin(mission);
    ConfigSection sonar = config.section("sonar_driver");
    sss::edgetech::readSonarDriverOptions(sonar, options.sonar);
    sonar.optional("xtf_pair_index", options.xtf.pair_index, {inRange(0, 7)});
    ConfigSection ins = config.section("ins_bridge");
    sss::ins::readInsBridgeOptions(ins, options.ins);
    ConfigSection buffer = config.section("subframe_buffer");
    sss::subframe::readSubframeBufferOptions(buffer, options.buffer);
    ConfigSection matcher = config.section("matcher");
    sss::matcher::readMatcherEngineOptions(matcher, options.matcher);
    ConfigSection optimiser = config.section("optimiser");
    sss::optimiser::readOptimiserEngineOptions(optimiser, options.optimiser);
    {
      ConfigSection fixes = config.section("fixes");
      fixes.optional("gnss_max_depth_m", options.fix_aligner.gnss_max_depth_m, {atLeast(0.0)});
      fixes.optional("max_extrapolation_s", options.fix_aligner.max_extrapolation_s, {atLeast(0.0)});
      fixes.optional("gnss_sigma_per_hdop_m", options.fix_reader.gnss_sigma_per_hdop_m, {greaterThan(0.0)});
      fixes.optional("dgnss_sigma_per_hdop_m", options.fix_reader.dgnss_sigma_per_hdop_m, {greaterThan(0.0)});
      fixes.optional("rtk_fixed_sigma_per_hdop_m", options.fix_reader.rtk_fixed_sigma_per_hdop_m, {greaterThan(0.0)});
      fixes.optional("rtk_float_sigma_per_hdop_m", options.fix_reader.rtk_float_sigma_per_hdop_m, {greaterThan(0.0)});
      fixes.optional("missing_hdop", options.fix_reader.missing_hdop, {greaterThan(0.0)});
      fixes.optional("usbl_default_sigma_m", options.fix_reader.usbl_default_sigma_m, {greaterThan(0.0)});
      fixes.optional("min_sigma_m", options.fix_reader.min_sigma_m, {greaterThan(0.0)});
      fixes.rejectUnknownKeys();
    }
    {
      ConfigSection products = config.section("products");
      products.optional("projected_crs", options.projected_crs);
      products.optional("geotiff", options.write_geotiff);
      products.rejectUnknownKeys();
      std::string crs_problem;
      if (!options.projected_crs.empty() && !sss::products::isKnownCrs(options.projected_crs, crs_problem)) {
        products.addProblem("projected_crs", options.projected_crs, crs_problem);
      }
    }
    if (!config.ok()) {
      error = "invalid configuration " + path + ": " + config.problemReport();
      return false;
    }
  }
  options.ins.origin = options.origin;
  // Files carry the ping time of the sonar's clock; a recording has no live clock to compare with.
  options.sonar.time_source = sss::edgetech::TimeSource::kSonarClock;
  options.sonar.recorder.directory.clear();
  // Deterministic: no wall-clock limit anywhere.
  options.matcher.pair.pose.time_limit_s = 0.0;
  options.optimiser.graph.max_solver_time_s = 0.0;
  std::vector<std::string> problems = sss::matcher::validateMatcherEngineOptions(options.matcher);
  for (const std::string& problem : sss::optimiser::validateOptimiserEngineOptions(options.optimiser)) {
    problems.push_back(problem);
  }
  if (!problems.empty()) {
    error = "invalid configuration " + path + ": " + problems.front();
    return false;
  }
  return true;
}

// ---- inputs in time order ----------------------------------------------------------------------

// A navigation sample a sonar file carries apart from its pings (XTF packets 3, 42, 107; JSF
// messages 2020, 2080, 2090, 2091), in the file's units: latitude/longitude degrees, or projected
// northing/easting metres.
struct FileNavigation {
  int64_t utime_us = 0;
  std::optional<double> y, x;
  std::optional<double> depth_m;
  std::optional<double> altitude_m;  // above the seabed (a DVL's), when the message says so
  std::optional<double> pitch_rad, roll_rad, heading_rad;
};

// One source of pings and one of nav samples, each in file order; the runner merges them by time.
class PingSource {
 public:
  virtual ~PingSource() = default;
  // Appends what the next read gives (possibly nothing); false at the end of the input.
  virtual bool read(std::deque<sss::edgetech::DriverPing>& out) = 0;
  virtual double fractionRead() const = 0;
  virtual uint64_t faults() const = 0;
  // Navigation packets read so far (XTF types 3, 42, 107), and whether their coordinates are
  // projected metres (XTF NavUnits 0).
  virtual std::vector<FileNavigation> takeNavigation() { return {}; }
  virtual bool projectedUnits() const { return false; }
};

class JsfSource : public PingSource {
 public:
  JsfSource(const std::string& path, const sss::edgetech::SonarDriverOptions& options)
      : file_(path, std::ios::binary), driver_(options) {
    std::error_code ec;
    size_ = fs::file_size(path, ec);
    driver_.keepNavigation(true);
  }
  std::vector<FileNavigation> takeNavigation() override {
    std::vector<FileNavigation> out;
    for (const auto& r : driver_.takeNavigation()) {
      FileNavigation nav{r.time_us, r.latitude_deg, r.longitude_deg, r.depth_m, r.altitude_m, r.pitch_rad, r.roll_rad,
                         r.heading_rad};
      if (r.nmea) {  // 2002: a GGA fix gives the position, at the message's (sonar clock) time
        if (const auto fix = sss::ins::parseGga(*r.nmea)) {
          nav.y = fix->latitude_deg;
          nav.x = fix->longitude_deg;
        }
      }
      out.push_back(nav);
    }
    return out;
  }
  bool good() const { return file_.good(); }
  bool read(std::deque<sss::edgetech::DriverPing>& out) override {
    if (finished_) return false;
    std::vector<char> chunk(1 << 20);
    file_.read(chunk.data(), static_cast<std::streamsize>(chunk.size()));
    const std::streamsize n = file_.gcount();
    read_ += static_cast<uint64_t>(std::max<std::streamsize>(n, 0));
    std::vector<sss::edgetech::DriverPing> pings;
    if (n > 0) driver_.onBytes(reinterpret_cast<const uint8_t*>(chunk.data()), static_cast<size_t>(n), 0, 0, pings);
    if (n <= 0 || !file_) {
      driver_.finish(0, 0, pings);
      finished_ = true;
    }
    for (auto& ping : pings) out.push_back(std::move(ping));
    return !finished_ || !pings.empty();
  }
  double fractionRead() const override { return size_ > 0 ? static_cast<double>(read_) / static_cast<double>(size_) : 0.0; }
  uint64_t faults() const override {
    const auto& c = driver_.parserCounters();
    return c.bad_headers + c.truncated_messages + driver_.sonarDecodeErrors();
  }

 private:
  std::ifstream file_;
  sss::edgetech::SonarDriver driver_;
  uint64_t size_ = 0;
  uint64_t read_ = 0;
  bool finished_ = false;
};

class XtfSource : public PingSource {
 public:
  XtfSource(const std::string& path, const sss::xtf::XtfReaderOptions& options) : reader_(path, options) {
    std::error_code ec;
    size_ = fs::file_size(path, ec);
  }
  const sss::xtf::XtfReader& reader() const { return reader_; }
  bool read(std::deque<sss::edgetech::DriverPing>& out) override {
    sss::edgetech::DriverPing ping;
    if (!reader_.next(ping)) return false;
    out.push_back(std::move(ping));
    return true;
  }
  double fractionRead() const override {
    return size_ > 0 ? static_cast<double>(reader_.bytesRead()) / static_cast<double>(size_) : 0.0;
  }
  uint64_t faults() const override { return reader_.counters().corruptRecords(); }
  std::vector<FileNavigation> takeNavigation() override {
    std::vector<FileNavigation> out;
    for (const auto& r : reader_.takeNavigation()) {
      // RawAltitude is the positioning system's height, not an altitude above the seabed.
      out.push_back({r.utime_us, r.y, r.x, std::nullopt, std::nullopt, r.pitch_rad, r.roll_rad, r.heading_rad});
    }
    return out;
  }
  bool projectedUnits() const override { return reader_.info().nav_units == sss::xtf::kNavUnitsMetres; }

 private:
  sss::xtf::XtfReader reader_;
  uint64_t size_ = 0;
};

class InsFileSource {
 public:
  InsFileSource(const std::string& path, const sss::ins::InsBridgeOptions& options)
      : file_(path, std::ios::binary), bridge_(options) {}
  bool good() const { return file_.good(); }
  bool read(std::deque<sss_msgs::nav_t>& out) {
    if (finished_) return false;
    std::vector<char> chunk(256 * 1024);
    file_.read(chunk.data(), static_cast<std::streamsize>(chunk.size()));
    const std::streamsize n = file_.gcount();
    std::vector<sss::ins::NavSample> samples;
    // Host time 0 throughout: staleness is a live-link notion, not one of a recorded file.
    // A chunk is not a datagram: a sentence may run on into the next chunk, so only the end of
    // the file (finish) ends one.
    if (n > 0) bridge_.onBytes(reinterpret_cast<const uint8_t*>(chunk.data()), static_cast<size_t>(n), 0, samples);
    if (n <= 0 || !file_) {
      bridge_.finish(0, samples);
      finished_ = true;
    }
    for (const auto& sample : samples) out.push_back(sss::ins::toNavMessage(sample));
    return !finished_ || !samples.empty();
  }
  const std::optional<sss::core::MissionOrigin>& origin() const { return bridge_.origin(); }
  uint64_t faults() const {
    const auto& c = bridge_.streamCounters();
    return static_cast<uint64_t>(c.bad_checksum + c.missing_checksum + c.overlong + c.bad_character + c.truncated);
  }

 private:
  std::ifstream file_;
  sss::ins::InsBridge bridge_;
  bool finished_ = false;
};

// Navigation from a sonar ping's header (JSF type 80 and XTF carry position, attitude, altitude).
// With no origin configured, the first ping with a position is the origin.
class EmbeddedNavigation {
 public:
  explicit EmbeddedNavigation(const std::optional<sss::core::MissionOrigin>& origin) {
    if (origin) setOrigin(*origin);
  }
  const std::optional<sss::core::MissionOrigin>& origin() const { return origin_; }
  // Set once a ping with projected metres (XTF NavUnits 0) founded the frame: its easting, northing.
  const std::optional<Eigen::Vector2d>& projectedOrigin() const { return projected_origin_; }
  std::optional<NavInput> fromPing(const sss::edgetech::DriverPing& driver_ping) {
    const auto& side = driver_ping.ping.port ? *driver_ping.ping.port : *driver_ping.ping.starboard;
    // The header fields a navigation packet borrows (not the samples: this runs for every ping).
    last_side_.validity = side.validity;
    last_side_.depth_m = side.depth_m;
    last_side_.altitude_m = side.altitude_m;
    last_side_.heading_rad = side.heading_rad;
    last_side_.pitch_rad = side.pitch_rad;
    last_side_.roll_rad = side.roll_rad;
    return fromSide(driver_ping.utime_us, side);
  }
  // A navigation packet of an XTF whose pings carry no position (types 42 and 107 give one, 3
  // and 107 attitude): each position goes with the newest packet attitude (else the last ping's),
  // and the last ping's depth and altitude. Coordinates are in the file's NavUnits.
  std::optional<NavInput> fromPacket(const FileNavigation& record, bool projected_units) {
    if (record.pitch_rad) packet_pitch_rad_ = record.pitch_rad;
    if (record.roll_rad) packet_roll_rad_ = record.roll_rad;
    if (record.heading_rad) packet_heading_rad_ = record.heading_rad;
    if (record.depth_m) packet_depth_m_ = record.depth_m;
    if (record.altitude_m) packet_altitude_m_ = record.altitude_m;
    if (!record.y || !record.x) return std::nullopt;
    sss::edgetech::SonarChannelRecord side = last_side_;
    side.pitch_rad = packet_pitch_rad_.value_or(side.pitch_rad);
    side.roll_rad = packet_roll_rad_.value_or(side.roll_rad);
    side.heading_rad = packet_heading_rad_.value_or(side.heading_rad);
    side.depth_m = packet_depth_m_.value_or(side.depth_m);
    if (packet_altitude_m_ && *packet_altitude_m_ > 0.0) {
      side.altitude_m = *packet_altitude_m_;
      side.validity |= sss::edgetech::kValidAltitude;
    }
    side.projected_position = projected_units;
    side.validity = static_cast<uint16_t>(side.validity & ~sss::edgetech::kValidLatLon);
    if (projected_units) {
      side.northing_m = *record.y;
      side.easting_m = *record.x;
    } else {
      if (std::abs(*record.y) > 90.0 || std::abs(*record.x) > 180.0) return std::nullopt;
      side.latitude_deg = *record.y;
      side.longitude_deg = *record.x;
      side.validity |= sss::edgetech::kValidLatLon;
    }
    return fromSide(record.utime_us, side);
  }

 private:
  std::optional<NavInput> fromSide(int64_t utime_us, const sss::edgetech::SonarChannelRecord& side) {
    if (side.projected_position) return fromProjected(utime_us, side);
    if (!(side.validity & sss::edgetech::kValidLatLon) && side.latitude_deg == 0.0 && side.longitude_deg == 0.0) {
      return std::nullopt;  // no position in this ping
    }
    if (!plane_) {
      if (!sss::core::isFirstFixCandidate(side.latitude_deg, side.longitude_deg)) return std::nullopt;
      setOrigin({side.latitude_deg, side.longitude_deg});
    }
    NavInput nav;
    nav.utime_us = utime_us;
    nav.origin = origin_;
    nav.position_ned_m = plane_->toNed({side.latitude_deg, side.longitude_deg, side.depth_m});
    fillAttitude(nav, side);
    return nav;
  }

  // Projected metres: processed in the file's own grid, north = northing - N0, east = easting -
  // E0 of the first fix (the CRS is not in the file, so no latitude/longitude). The heading is
  // used as recorded: true north, which differs from the grid's north by the projection's
  // meridian convergence (within a degree or two in UTM).
  std::optional<NavInput> fromProjected(int64_t utime_us, const sss::edgetech::SonarChannelRecord& side) {
    if (!projected_origin_) projected_origin_ = Eigen::Vector2d(side.easting_m, side.northing_m);
    NavInput nav;
    nav.utime_us = utime_us;
    nav.position_ned_m = Eigen::Vector3d(side.northing_m - projected_origin_->y(), side.easting_m - projected_origin_->x(),
                                         side.depth_m);
    fillAttitude(nav, side);
    return nav;
  }
  void fillAttitude(NavInput& nav, const sss::edgetech::SonarChannelRecord& side) {
    nav.roll_rad = side.roll_rad;
    nav.pitch_rad = side.pitch_rad;
    nav.heading_rad = side.heading_rad;
    nav.altitude_m = side.altitude_m;
    nav.altitude_valid = (side.validity & sss::edgetech::kValidAltitude) != 0 && side.altitude_m > 0.0;
    if (last_) distance_m_ += (nav.position_ned_m - *last_).head<2>().norm();
    last_ = nav.position_ned_m;
    nav.distance_travelled_m = distance_m_;
  }
  std::optional<Eigen::Vector2d> projected_origin_;
  sss::edgetech::SonarChannelRecord last_side_;  // the last ping's header (depth, altitude, attitude)
  std::optional<double> packet_pitch_rad_, packet_roll_rad_, packet_heading_rad_, packet_depth_m_, packet_altitude_m_;
  void setOrigin(const sss::core::MissionOrigin& origin) {
    origin_ = origin;
    plane_.emplace(origin.latitude_deg, origin.longitude_deg);
  }
  std::optional<sss::core::MissionOrigin> origin_;
  std::optional<sss::core::LocalTangentPlane> plane_;
  std::optional<Eigen::Vector3d> last_;
  double distance_m_ = 0.0;
};

// ---- what a run yields, and why not -------------------------------------------------------------

std::string count(uint64_t n) { return std::to_string(static_cast<unsigned long long>(n)); }

// One line per stage that yielded nothing, naming the cause and the fix, in chain order; the
// first explains the rest. Empty when every stage produced something.
std::vector<std::string> explainRun(const OfflineSummary& s, const Options& options) {
  std::vector<std::string> findings;
  const auto& fusion = s.buffer.fusion;
  const uint64_t pings = s.pings;
  if (s.pings_with_pose == 0) {
    // The largest cause of loss first.
    const std::pair<uint64_t, std::string> causes[] = {
        {s.nav_from_packets > 0 ? 0 : s.pings_without_position,
         count(s.pings_without_position) + " of " + count(pings) + " ping headers carry no position: the file has no "
         "navigation of its own; give the INS file with --ins"},
        {fusion.dropped_no_altitude,
         count(fusion.dropped_no_altitude) + " of " + count(pings) + " pings have no altitude: the navigation and "
         "the ping headers carry none" +
             (options.buffer.fusion.altitude_source == sss::subframe::AltitudePolicy::kNav
                  ? "; set subframe_buffer.fusion.altitude_source: auto (tracks the bottom in the returns)"
                  : " and no seabed return was found in the sonar returns (bottom tracking found one in " +
                        count(s.bottom_track.detected) + " pings); check that the file holds the sonar's raw "
                        "returns from the water column down, or give an INS file with altitude (--ins)")},
        {fusion.dropped_nav_gap,
         count(fusion.dropped_nav_gap) + " of " + count(pings) + " pings fall between navigation samples more than " +
             std::to_string(options.buffer.fusion.max_nav_gap_s) + " s apart; raise subframe_buffer.fusion."
             "max_nav_gap_s to the navigation's sample interval"},
        {fusion.dropped_no_nav + fusion.dropped_too_old + fusion.dropped_before_first_fix,
         count(fusion.dropped_no_nav + fusion.dropped_too_old + fusion.dropped_before_first_fix) + " of " +
             count(pings) + " pings have no navigation at their time (" + count(fusion.dropped_before_first_fix) +
             " before the first fix): the INS file does not cover the sonar file's times (another day? a clock "
             "offset?); give the INS file recorded with it"},
        {fusion.pings_duplicate + fusion.pings_out_of_order,
         count(fusion.pings_duplicate + fusion.pings_out_of_order) + " of " + count(pings) +
             " pings repeat a ping number or go back in time; check the file's ping times"},
    };
    const auto* worst = &causes[0];
    for (const auto& cause : causes) {
      if (cause.first > worst->first) worst = &cause;
    }
    findings.push_back(worst->first > 0 ? "no ping got a pose: " + worst->second
                                        : "no ping got a pose (" + count(pings) + " pings, " + count(s.nav_samples) +
                                              " navigation samples)");
    return findings;
  }
  if (s.subframes == 0) {
    const auto& builder = s.buffer.builder;
    std::string why;
    if (builder.lines == 0) {
      why = "no straight survey line was found: the " + count(s.pings_with_pose) + " pings with a pose are all in "
            "turns (" + count(builder.turn_pings) + ") or the heading wanders more than subframe_buffer.lines."
            "max_heading_deviation_rad; a curved line needs that raised";
    } else {
      why = "the " + count(builder.lines) + " survey line(s) are shorter than subframe_buffer.subframes.min_pings (" +
            std::to_string(options.buffer.subframes.min_pings) + " pings; " + count(builder.dropped_tail_pings) +
            " pings dropped as short tails); lower min_pings for short lines";
    }
    findings.push_back("no subframe: " + why);
    return findings;
  }
  const double swath_m = s.canonical_swath_m;
  if (s.pairs_attempted == 0) {
    if (s.survey_lines < 2) {
      findings.push_back("no pair to match: every subframe is on one survey line; loop closures need a second line "
                         "over the same seabed (the result is dead reckoning)");
    } else if (s.nearest_other_line_m < 0.0) {
      findings.push_back("no pair to match: the " + count(s.survey_lines) + " survey lines follow one another along "
                         "one track (split where the heading changed), none runs beside another; loop closures need "
                         "a second pass over the same seabed (the result is dead reckoning)");
    } else {
      char text[512];
      if (options.buffer.canonical.swath_from_range && s.nearest_other_line_m > 2.0 * swath_m) {
        std::snprintf(text, sizeof text,
                      "no pair to match: the nearest lines run %.0f m apart, more than twice the %.0f m of seabed "
                      "the sonar records per side: no seabed is seen from two lines (closer lines or a longer "
                      "range would overlap)",
                      s.nearest_other_line_m, swath_m);
      } else {
        std::snprintf(text, sizeof text,
                      "no pair to match: no two subframes of different lines overlap within the canonical swath of "
                      "%.0f m per side (the nearest lines run %.0f m apart); subframe_buffer.canonical."
                      "swath_from_range: true widens it to the sonar's recorded range (or set bins_per_side x "
                      "bin_size_m)",
                      swath_m, s.nearest_other_line_m);
      }
      findings.push_back(text);
    }
    return findings;
  }
  if (s.matcher_closures == 0) {
    findings.push_back("no loop closure: " + count(s.pairs_attempted) + " pair attempts, " +
                       count(s.pairs_few_matches) + " with too few dense matches (little overlap or texture), " +
                       count(s.pairs_pose_rejected) + " with a rejected relative pose; first: " + s.first_pair_rejection +
                       " (the result is dead reckoning)");
    return findings;
  }
  if (s.closures_accepted == 0) {
    findings.push_back("no closure accepted: the optimiser rejected all " + count(s.matcher_closures) +
                       " (inconsistent with dead reckoning and with each other; see loop_closures.csv); the result is "
                       "dead reckoning");
  }
  // DR strained beyond its own error model: on the randomised missions this marked exactly the
  // runs SLAM made worse than DR (closures with an error common to a pair, relief at far range).
  const double strain = s.variance_factors.odometry_strain;
  if (s.closures_accepted > 0 && std::isfinite(strain) && strain > 1.0) {
    char text[512];
    std::snprintf(text, sizeof(text),
                  "the accepted closures bend dead reckoning %.1fx beyond its error model (variance; "
                  "optimiser.graph.odometry_*): closures sharing an error (a biased pair, relief at far range) are "
                  "likely, and SLAM may be worse than dead reckoning here: compare loop_closures.csv with the DR "
                  "and SLAM mosaics before using slam.tum over dead_reckoning.tum",
                  strain);
    findings.push_back(text);
  }
  // Opposite-side closures and DR disagree on how far apart the lines run, all pairs alike.
  const sss::optimiser::SeparationBias& bias = s.separation_bias;
  if (bias.significant && !bias.applied) {
    char text[640];
    std::snprintf(text, sizeof(text),
                  "the closures between lines that look at their overlap from opposite sides put the lines %.2f m "
                  "%s together than dead reckoning does (+- %.2f m, over %d closures, every pair alike): either raised "
                  "features (rocks, boulders) show each line their near face and bias the matches, or dead reckoning's "
                  "turns between lines are off (a DVL scale factor); cross lines or fixes tell the two apart. "
                  "optimiser.graph.separation_bias_apply: true corrects the closures by it",
                  std::abs(bias.tested_m), bias.tested_m > 0.0 ? "closer" : "further", bias.sigma_m, bias.closures);
    findings.push_back(text);
  }
  return findings;
}

// One line each for fixes that were given but not used, naming the cause and the fix.
std::vector<std::string> explainFixes(const FixSummary& f, const Options& options) {
  std::vector<std::string> findings;
  if (f.files == 0) return findings;
  char text[640];
  if (f.read == 0) {
    std::snprintf(text, sizeof text,
                  "the %llu fix file(s) hold no usable fix (GGA sentences with a fix; %llu sentences skipped%s%s)",
                  static_cast<unsigned long long>(f.files), static_cast<unsigned long long>(f.sentences_skipped),
                  f.first_problem.empty() ? "" : ", first: ", f.first_problem.c_str());
    findings.push_back(text);
    return findings;
  }
  if (f.no_frame > 0) {
    std::snprintf(text, sizeof text,
                  "%llu fixes not used: the mission frame is the sonar file's projected grid without a CRS, so "
                  "latitude/longitude fixes cannot be placed in it; give the INS file (--ins) or configure "
                  "mission.origin_latitude_deg/origin_longitude_deg",
                  static_cast<unsigned long long>(f.no_frame));
    findings.push_back(text);
  }
  if (f.outside_navigation > 0) {
    std::snprintf(text, sizeof text,
                  "%llu of %llu fixes fall outside the navigation's time span (more than %.1f s before it starts or "
                  "after it ends): check that the fix file belongs to this mission and its dates (files without "
                  "ZDA/RMC are dated from the navigation's first day)",
                  static_cast<unsigned long long>(f.outside_navigation), static_cast<unsigned long long>(f.read),
                  options.fix_aligner.max_extrapolation_s);
    findings.push_back(text);
  }
  if (f.below_surface > 0 && f.below_surface == f.gnss) {
    std::snprintf(text, sizeof text,
                  "all %llu GNSS fixes came while the vehicle was deeper than fixes.gnss_max_depth_m (%.1f m) and were "
                  "ignored (a receiver under water reports stale positions); if they are the ship's USBL, name the file "
                  "usbl:PATH",
                  static_cast<unsigned long long>(f.below_surface), options.fix_aligner.gnss_max_depth_m);
    findings.push_back(text);
  }
  if (f.fed > 0 && f.accepted == 0) {
    std::snprintf(text, sizeof text,
                  "none of the %llu fixes given to the optimiser was accepted (%llu rejected by the gate against "
                  "dead reckoning; see fixes.csv): fixes and navigation disagree, check the fixes' datum and time",
                  static_cast<unsigned long long>(f.fed), static_cast<unsigned long long>(f.rejected_gate));
    findings.push_back(text);
  }
  return findings;
}

// ---- outputs -----------------------------------------------------------------------------------

bool writeSummaryJson(const std::string& path, const OfflineRequest& request, const OfflineSummary& s,
                      std::string& error) {
  sss::eval::JsonWriter json;
  json.beginObject();
  json.key("schema").value("sss-process/1");
  json.key("inputs").beginObject();
  json.key("sonar").value(request.sonar_path);
  json.key("ins").value(request.ins_path);
  json.key("lcm_log").value(request.lcm_log_path);
  json.key("config").value(request.config_path);
  json.endObject();
  // The frame of every trajectory, heightmap and point cloud of the run (local NED of this point).
  json.key("origin").beginObject();
  if (s.origin) {
    json.key("latitude_deg").value(s.origin->latitude_deg, 13);
    json.key("longitude_deg").value(s.origin->longitude_deg, 13);
  }
  if (s.origin_source == "projected_first_fix") {
    json.key("projected_easting_m").value(s.projected_origin_easting_m, 12);
    json.key("projected_northing_m").value(s.projected_origin_northing_m, 12);
  }
  json.key("source").value(s.origin_source);
  json.key("detail").value(s.origin_detail);
  json.endObject();
  const std::pair<const char*, uint64_t> counts[] = {
      {"nav_samples", s.nav_samples},         {"pings", s.pings},
      {"pings_with_pose", s.pings_with_pose}, {"subframes", s.subframes},
      {"pairs_attempted", s.pairs_attempted}, {"matcher_closures", s.matcher_closures},
      {"false_closures_injected", s.false_closures_injected},
      {"closures_accepted", s.closures_accepted}, {"closures_rejected", s.closures_rejected},
      {"closures_superseded", s.closures_superseded}, {"seabed_points", s.seabed_points},
      {"input_faults", s.input_faults}};
  for (const auto& [name, value] : counts) json.key(name).value(value);
  const auto& fusion = s.buffer.fusion;
  json.key("navigation").beginObject();
  json.key("ping_headers_without_position").value(s.pings_without_position);
  json.key("samples_from_nav_packets").value(s.nav_from_packets);  // XTF attitude/navigation packets
  json.key("samples_without_position").value(fusion.nav_without_position);
  json.endObject();
  json.key("pings_dropped").beginObject();
  const std::pair<const char*, uint64_t> drops[] = {
      {"before_first_fix", fusion.dropped_before_first_fix},
      {"no_nav", fusion.dropped_no_nav},
      {"older_than_nav_history", fusion.dropped_too_old},
      {"nav_gap", fusion.dropped_nav_gap},
      {"no_altitude", fusion.dropped_no_altitude},
      {"duplicate", fusion.pings_duplicate},
      {"out_of_order", fusion.pings_out_of_order}};
  for (const auto& [name, value] : drops) json.key(name).value(value);
  json.endObject();
  json.key("altitude_sources").beginObject();
  json.key("nav").value(fusion.altitude_from_nav);
  json.key("ping_header").value(fusion.altitude_from_ping);
  json.key("bottom_track").value(fusion.altitude_from_bottom_track);
  json.key("implausible_rejected").value(fusion.altitude_implausible);
  json.endObject();
  json.key("bottom_track").beginObject();
  json.key("pings").value(s.bottom_track.pings);
  json.key("detected").value(s.bottom_track.detected);
  json.key("one_side_only").value(s.bottom_track.one_side_only);
  json.key("outliers").value(s.bottom_track.outliers);
  json.key("scale_applied").value(fusion.bottom_track_scale, 6);
  json.endObject();
  json.key("variance_factors").beginObject();  // what the graph learnt of its own weights
  json.key("closure").value(s.variance_factors.closure, 6);
  json.key("odometry").value(s.variance_factors.odometry, 6);
  json.key("closure_redundancy").value(s.variance_factors.closure_redundancy, 4);
  json.key("odometry_redundancy").value(s.variance_factors.odometry_redundancy, 4);
  json.key("odometry_strain").value(s.variance_factors.odometry_strain, 4);
  json.key("closures").value(static_cast<uint64_t>(s.variance_factors.closures));
  json.key("iterations").value(static_cast<uint64_t>(s.variance_factors.iterations));
  json.endObject();
  json.key("separation_bias").beginObject();  // how much closer opposite-side closures put the lines
  json.key("estimate_m").value(s.separation_bias.tested_m, 4);
  json.key("sigma_m").value(s.separation_bias.sigma_m, 4);
  json.key("significant").value(s.separation_bias.significant);
  json.key("applied").value(s.separation_bias.applied);
  json.key("closures").value(static_cast<uint64_t>(s.separation_bias.closures));
  json.endObject();
  json.key("fixes").beginObject();  // absolute fixes (--fixes): what was read and what became of it
  json.key("files").value(s.fixes.files);
  json.key("read").value(s.fixes.read);
  json.key("gnss").value(s.fixes.gnss);
  json.key("usbl").value(s.fixes.usbl);
  json.key("sentences_skipped").value(s.fixes.sentences_skipped);
  json.key("first_problem").value(s.fixes.first_problem);
  json.key("below_surface").value(s.fixes.below_surface);
  json.key("outside_navigation").value(s.fixes.outside_navigation);
  json.key("no_geographic_frame").value(s.fixes.no_frame);
  json.key("fed").value(s.fixes.fed);
  json.key("accepted").value(s.fixes.accepted);
  json.key("rejected_gate").value(s.fixes.rejected_gate);
  json.key("refused").value(s.fixes.refused);
  json.key("rms_residual_m").value(s.fixes.rms_residual_m, 4);
  json.endObject();
  json.key("coverage").beginObject();  // coverage.yaml: how many lines saw each 5 m cell (SLAM poses)
  json.key("covered_m2").value(s.coverage_covered_m2, 8);
  json.key("seen_twice_m2").value(s.coverage_seen_twice_m2, 8);
  json.key("fraction_seen_twice").value(s.coverage_covered_m2 > 0.0 ? s.coverage_seen_twice_m2 / s.coverage_covered_m2 : 0.0, 4);
  json.endObject();
  // INS heading error (closures and fixes observe it) and DVL scale (with fixes only; else 0, sigma null)
  json.key("calibration").beginObject();
  json.key("estimated").value(s.calibration.estimated);
  json.key("dvl_scale_estimated").value(s.calibration.scale_estimated);
  json.key("dvl_scale").value(s.calibration.dvl_scale, 6);
  json.key("dvl_scale_sigma").value(s.calibration.sigma(0), 6);
  json.key("heading_bias_rad").value(s.calibration.heading_bias_rad, 6);
  json.key("heading_bias_sigma_rad").value(s.calibration.sigma(1), 6);
  json.key("heading_cos_rad").value(s.calibration.heading_cos_rad, 6);
  json.key("heading_cos_sigma_rad").value(s.calibration.sigma(2), 6);
  json.key("heading_sin_rad").value(s.calibration.heading_sin_rad, 6);
  json.key("heading_sin_sigma_rad").value(s.calibration.sigma(3), 6);
  json.endObject();
  json.key("lines").beginObject();
  json.key("survey_lines").value(s.survey_lines);
  json.key("turn_pings").value(s.buffer.builder.turn_pings);
  json.key("short_tail_pings").value(s.buffer.builder.dropped_tail_pings);
  json.key("nearest_other_line_m").value(s.nearest_other_line_m, 6);
  json.key("canonical_swath_m").value(s.canonical_swath_m, 6);
  json.endObject();
  json.key("pairs_rejected").beginObject();
  json.key("few_dense_matches").value(s.pairs_few_matches);
  json.key("relative_pose").value(s.pairs_pose_rejected);
  json.key("first_reason").value(s.first_pair_rejection);
  json.endObject();
  // The GeoTIFFs written and their CRS (QGIS and gdalinfo read it from the files too).
  json.key("corrected_copy").beginObject();
  json.key("path").value(s.corrected_copy);
  json.key("pings_corrected").value(s.corrected_records);
  json.key("pings_without_pose").value(s.corrected_records_without_pose);
  json.endObject();
  json.key("geotiff").beginObject();
  json.key("crs").value(s.geotiff_crs);
  json.key("epsg").value(static_cast<uint64_t>(s.geotiff_epsg));
  json.key("files").beginArray();
  for (const std::string& file : s.geotiffs) json.value(file);
  json.endArray();
  json.endObject();
  json.key("findings").beginArray();
  for (const std::string& finding : s.findings) json.value(finding);
  json.endArray();
  const std::pair<const char*, double> figures[] = {
      {"mission_s", s.mission_s},     {"wall_s", s.wall_s},
      {"matcher_s", s.matcher_s},     {"optimiser_s", s.optimiser_s},
      {"real_time_factor", s.real_time_factor}, {"peak_rss_mib", s.peak_rss_mib}};
  for (const auto& [name, value] : figures) json.key(name).value(value, 6);
  json.endObject();
  std::ofstream out(path);
  out << json.str() << "\n";
  if (!out) {
    error = "cannot write " + path;
    return false;
  }
  return true;
}


// ---- the run -----------------------------------------------------------------------------------

class Runner {
 public:
  Runner(const OfflineRequest& request, const Options& options)
      : request_(request),
        options_(options),
        buffer_(options.buffer),
        matcher_(options.matcher),
        optimiser_(options.optimiser),
        mosaic_store_(options.pictures, std::numeric_limits<size_t>::max()),
        fix_aligner_(options.fix_aligner) {
    buffer_.setFusedPingObserver([this](const sss::subframe::FusedPing& fused) {
      dr_per_ping_.push_back({fused.ping.utime_us, fused.T_world_body});
      altitude_per_ping_.push_back({fused.ping.utime_us, fused.altitude_m, fused.altitude_source, fused.bottom_track_quality});
    });
  }

  void addNav(const NavInput& nav) {
    ++summary_.nav_samples;
    if (nav.origin && !origin_) origin_ = nav.origin;  // the frame every output is written in
    buffer_.addNav(nav, subframes_);
    handleSubframes();
    if (nav.position_valid) fix_aligner_.addNav(nav.utime_us, nav.position_ned_m, nav.distance_travelled_m, nav.origin);
    feedFixes(false);
  }

  // The fixes of the request's files, in file order (dated against the navigation later).
  void setFixes(const std::vector<sss::ins::PositionFix>& fixes) {
    for (const auto& fix : fixes) fix_aligner_.addFix(fix);
  }
  void addPing(PingInput ping) {
    ++summary_.pings;
    if (first_ping_us_ < 0) first_ping_us_ = ping.utime_us;
    last_ping_us_ = std::max(last_ping_us_, ping.utime_us);
    buffer_.addPing(std::move(ping), subframes_);
    handleSubframes();
  }

  void finish() {
    buffer_.finish(subframes_);
    handleSubframes();
    feedFixes(true);
    const double start = wallSeconds();
    optimiser_.finish();
    summary_.optimiser_s += wallSeconds() - start;
    // One more association round with the smoothed poses (the paper's last iteration), then the
    // final smoothing with whatever it found.
    if (addOutcomes(timedMatch([&] { return matcher_.updateTrajectory(optimiser_.trajectory()); }))) {
      const double again = wallSeconds();
      optimiser_.finish();
      summary_.optimiser_s += wallSeconds() - again;
    }
  }

  void progress(double fraction, bool force) {
    if (!request_.progress) return;
    const double now = wallSeconds();
    if (!force && now - last_progress_s_ < request_.progress_period_s) return;
    last_progress_s_ = now;
    const double elapsed = now - start_s_;
    const double mission_s = first_ping_us_ >= 0 ? 1e-6 * static_cast<double>(last_ping_us_ - first_ping_us_) : 0.0;
    const double eta = fraction > 0.01 ? elapsed * (1.0 - fraction) / fraction : 0.0;
    std::fprintf(request_.progress,
                 "sss-process: %5.1f %% | pings %llu | subframes %llu | closures %llu | mission %.0f s | %.1fx real time"
                 " | ETA %.0f s\n",
                 100.0 * fraction, static_cast<unsigned long long>(summary_.pings),
                 static_cast<unsigned long long>(summary_.subframes),
                 static_cast<unsigned long long>(summary_.matcher_closures), mission_s,
                 elapsed > 0 ? mission_s / elapsed : 0.0, eta);
    std::fflush(request_.progress);
  }

  bool writeOutputs(std::string& error);
  bool writeFixOutputs(const std::string& dir, std::string& error);
  bool writeNavigation(const std::string& dir, const std::vector<sss::optimiser::StampedPose>& slam, std::string& error) const;
  bool writeGeoJson(const std::string& dir, const std::vector<sss::optimiser::StampedPose>& slam, std::string& error) const;
  // --write-corrected: the sonar file with the SLAM navigation in every ping.
  bool writeCorrectedCopy(const std::vector<sss::optimiser::StampedPose>& slam, std::string& error);
  // The GeoTIFFs' frame: the origin's tangent plane, or the file's projected grid; nullopt: neither.
  std::optional<sss::products::RasterFrame> rasterFrame() const;
  // Writes dir/name as a GeoTIFF when the run has a frame on Earth and GeoTIFFs are on.
  bool writeRaster(const std::string& dir, const std::string& name, const sss::products::FrameRaster& raster,
                   std::string& error);
  bool writeAltitudeCsv(const std::string& path, std::string& error) const;
  OfflineSummary& summary() { return summary_; }
  const std::optional<sss::core::MissionOrigin>& origin() const { return origin_; }
  // The frame is a projected grid's (XTF NavUnits 0): said in every trajectory file.
  void setProjectedOrigin(const Eigen::Vector2d& easting_northing_m) {
    char text[256];
    std::snprintf(text, sizeof text,
                  "\nframe: the file's projected grid (XTF NavUnits 0, CRS not recorded): north = northing - %.3f, "
                  "east = easting - %.3f",
                  easting_northing_m.y(), easting_northing_m.x());
    frame_comment_ = text;
    projected_origin_ = easting_northing_m;
  }
  const sss::subframe::SubframeBuffer& buffer() const { return buffer_; }
  // The stage counters and the survey's layout into the summary (after finish()).
  void countStages() {
    summary_.buffer = buffer_.counters();
    summary_.bottom_track = buffer_.bottomTrackCounters();
    summary_.canonical_swath_m = buffer_.geometry().bins_per_side * buffer_.geometry().bin_size_m;
    std::vector<int> lines;
    for (const auto& [line, centre] : centres_) {
      if (std::find(lines.begin(), lines.end(), line) == lines.end()) lines.push_back(line);
    }
    summary_.survey_lines = lines.size();
    // Of two subframes of different lines, the one's centre in the other's frame: side by side
    // (more across than along) is a pair the swath could cover; ahead or behind is the same track
    // going on (a line split where the heading changed).
    double nearest = -1.0;
    for (size_t i = 0; i < centres_.size(); ++i) {
      for (size_t j = 0; j < centres_.size(); ++j) {
        if (centres_[i].first == centres_[j].first) continue;
        const Eigen::Vector3d in_i = centres_[i].second.inverse() * centres_[j].second.translation;
        if (std::abs(in_i.x()) > std::abs(in_i.y())) continue;
        if (nearest < 0.0 || std::abs(in_i.y()) < nearest) nearest = std::abs(in_i.y());
      }
    }
    summary_.nearest_other_line_m = nearest;
  }

  // matches.csv: the matcher engine shows every matched pair to the writer.
  bool openMatchWriter(std::string& error) {
    if (!match_writer_.open(request_.out_dir + "/matches.csv", options_.matcher.pair.dense.stride, 4, error)) return false;
    matcher_.setPairMatchObserver([this](const sss::core::Subframe& a, const sss::core::Subframe& b, int round,
                                         const sss::matcher::PairMatch& match) {
      match_writer_.addPair(a, b, round, match);
    });
    return true;
  }
  double startSeconds() const { return start_s_; }
  double missionSeconds() const {
    return first_ping_us_ >= 0 ? 1e-6 * static_cast<double>(last_ping_us_ - first_ping_us_) : 0.0;
  }

 private:
  template <typename F>
  std::vector<sss::matcher::PairOutcome> timedMatch(F&& call) {
    const double start = wallSeconds();
    auto outcomes = call();
    summary_.matcher_s += wallSeconds() - start;
    return outcomes;
  }

  // Closures into the optimiser; true when any was added.
  bool addOutcomes(const std::vector<sss::matcher::PairOutcome>& outcomes) {
    bool added = false;
    for (const auto& outcome : outcomes) {
      ++summary_.pairs_attempted;
      if (!outcome.accepted) {
        const bool few_matches = outcome.reason.find("dense matches, below") != std::string::npos;
        ++(few_matches ? summary_.pairs_few_matches : summary_.pairs_pose_rejected);
        if (summary_.first_pair_rejection.empty()) summary_.first_pair_rejection = outcome.reason;
        continue;
      }
      ++summary_.matcher_closures;
      sss::matcher::LoopClosure closure = outcome.closure;
      if (injectFalseClosure(closure)) ++summary_.false_closures_injected;
      added = optimiser_.addLoopClosure(closure).ok || added;
    }
    return added;
  }

  // --inject-false-closures (OfflineRequest::false_closure_fraction): the draw depends only on the
  // pair and the seed, so every association round of a chosen pair gets the same wrong pose.
  bool injectFalseClosure(sss::matcher::LoopClosure& closure) const {
    if (!(request_.false_closure_fraction > 0.0)) return false;
    std::mt19937_64 random(request_.false_closure_seed * 0x9E3779B97F4A7C15ULL ^
                           static_cast<uint64_t>(closure.subframe_id_a) * 0x100000001B3ULL ^
                           static_cast<uint64_t>(closure.subframe_id_b));
    std::uniform_real_distribution<double> uniform(0.0, 1.0);
    if (uniform(random) >= request_.false_closure_fraction) return false;
    const double distance_m = 3.0 + 7.0 * uniform(random);
    const double direction_rad = 2.0 * M_PI * uniform(random);
    const double heading_rad = (2.0 + 8.0 * uniform(random)) * M_PI / 180.0 * (uniform(random) < 0.5 ? -1.0 : 1.0);
    closure.T_a_b.translation += Eigen::Vector3d(distance_m * std::cos(direction_rad), distance_m * std::sin(direction_rad), 0.0);
    closure.T_a_b.rotation = Eigen::Quaterniond(Eigen::AngleAxisd(heading_rad, Eigen::Vector3d::UnitZ())) * closure.T_a_b.rotation;
    return true;
  }

  // The fixes the navigation has passed (all when final) into the optimiser.
  void feedFixes(bool final) {
    for (const sss::ins::AlignedFix& aligned : fix_aligner_.take(final)) {
      sss::optimiser::AbsoluteFix input;
      input.utime_us = aligned.fix.utime_us;
      input.position_ne_m = aligned.position_ne_m;
      input.covariance_m2 = aligned.covariance_m2;
      input.dr_position_m = aligned.dr_position_m;
      input.dr_distance_m = aligned.dr_distance_m;
      input.source = sss::ins::fixSourceName(aligned.fix.source);
      ++(optimiser_.addFix(input).ok ? summary_.fixes.fed : summary_.fixes.refused);
    }
    const sss::ins::FixAlignerCounters& c = fix_aligner_.counters();
    summary_.fixes.below_surface = c.below_surface;
    summary_.fixes.outside_navigation = c.outside_navigation;
    summary_.fixes.no_frame = c.no_frame;
  }

  void update() {
    const double start = wallSeconds();
    optimiser_.update();
    summary_.optimiser_s += wallSeconds() - start;
  }

  // Each new subframe: node, matches, update; then the optimised poses go back to the matcher
  // (re-association, new overlaps) and what that finds is optimised at once, as the live chain
  // does asynchronously.
  void handleSubframes() {
    for (sss::core::Subframe& subframe : subframes_) {
      ++summary_.subframes;
      centres_.push_back({subframe.line_id, subframe.centre().T_world_body});
      footprints_.push_back(sss::products::footprintOf(subframe));
      optimiser_.addSubframe(subframe);
      if (request_.write_mosaics) mosaic_store_.add(subframe);
      addOutcomes(timedMatch([&] { return matcher_.addSubframe(std::move(subframe)); }));
      update();
      if (addOutcomes(timedMatch([&] { return matcher_.updateTrajectory(optimiser_.trajectory()); }))) update();
    }
    subframes_.clear();
  }

  const OfflineRequest& request_;
  Options options_;
  sss::subframe::SubframeBuffer buffer_;
  sss::matcher::MatcherEngine matcher_;
  sss::optimiser::OptimiserEngine optimiser_;
  std::vector<sss::core::Subframe> subframes_;  // reused
  sss::products::MosaicStore mosaic_store_;  // every subframe at mosaic resolution (no bound offline)
  std::vector<std::pair<int, sss::core::Pose>> centres_;  // line id and DR centre pose of every subframe
  std::vector<sss::products::SubframeFootprint> footprints_;  // of every subframe, for GeoJSON and coverage
  std::vector<sss::optimiser::StampedPose> dr_per_ping_;
  sss::ins::FixAligner fix_aligner_;  // the request's fixes, tied to the navigation as it comes
  struct PingAltitude {
    int64_t utime_us;
    double altitude_m;
    sss::subframe::AltitudeSource source;
    double quality;
  };
  std::vector<PingAltitude> altitude_per_ping_;
  OfflineSummary summary_;
  MatchCsvWriter match_writer_;  // open only with request_.write_matches
  int64_t first_ping_us_ = -1;
  int64_t last_ping_us_ = 0;
  std::optional<sss::core::MissionOrigin> origin_;
  std::string frame_comment_;  // appended to the trajectories' comment (a projected frame)
  std::optional<Eigen::Vector2d> projected_origin_;  // the file's grid (easting, northing) at the frame's origin
  double start_s_ = wallSeconds();
  double last_progress_s_ = 0.0;
};

// With fixes: fixes.csv (every fix the optimiser saw, its decision and residual) and
// dead_reckoning_fixed.tum, the best answer without side-scan: the same nodes, odometry and fixes in
// a graph without closures (what an aided-INS smoother with the same fixes gives).
bool Runner::writeFixOutputs(const std::string& dir, std::string& error) {
  const sss::optimiser::SlidingWindowPoseGraph& graph = optimiser_.graph();
  const std::vector<sss::optimiser::FixRecord> records = graph.fixes();
  sss::offline::FixSummary& s = summary_.fixes;
  s.accepted = graph.fixCounters().accepted;
  s.rejected_gate = graph.fixCounters().rejected_gate;
  if (records.empty()) return true;
  double sum_squared = 0.0;
  for (const auto& r : records)
    if (r.status == sss::optimiser::FixStatus::kAccepted) sum_squared += r.residual_ne_m.squaredNorm();
  s.rms_residual_m = s.accepted > 0 ? std::sqrt(sum_squared / static_cast<double>(s.accepted)) : 0.0;

  const std::string csv_path = dir + "/fixes.csv";
  std::FILE* f = std::fopen(csv_path.c_str(), "w");
  if (!f) {
    error = "cannot write " + csv_path;
    return false;
  }
  std::fprintf(f, "# absolute fixes given to the optimiser (local NED of the mission origin); residual = fix - SLAM "
                  "estimate at the fix time; chi2 = innovation at the gate (2 dof)\n"
                  "utime_us,source,north_m,east_m,sigma_north_m,sigma_east_m,status,innovation_chi2,subframe_id,"
                  "residual_north_m,residual_east_m\n");
  for (const auto& r : records) {
    const char* status = r.status == sss::optimiser::FixStatus::kAccepted   ? "accepted"
                         : r.status == sss::optimiser::FixStatus::kRejected ? "rejected_gate"
                                                                              : "pending";
    std::fprintf(f, "%lld,%s,%.3f,%.3f,%.3f,%.3f,%s,%.3f,%lld,%.3f,%.3f\n", static_cast<long long>(r.fix.utime_us),
                 r.fix.source.c_str(), r.fix.position_ne_m.x(), r.fix.position_ne_m.y(),
                 std::sqrt(r.fix.covariance_m2(0, 0)), std::sqrt(r.fix.covariance_m2(1, 1)), status, r.innovation_chi2,
                 static_cast<long long>(r.subframe_id), r.residual_ne_m.x(), r.residual_ne_m.y());
  }
  if (std::fclose(f) != 0) {
    error = "cannot write " + csv_path;
    return false;
  }

  sss::optimiser::SlidingWindowPoseGraph fixed(options_.optimiser.graph);
  for (const sss::optimiser::NodeState& n : graph.nodes()) {
    fixed.addNode(n.subframe_id, n.utime_us, n.T_world_body_dr, n.distance_travelled_m);
  }
  for (const auto& r : records) fixed.addFix(r.fix);
  fixed.fullSmoothing();
  std::vector<sss::optimiser::StampedPose> poses;
  poses.reserve(dr_per_ping_.size());
  for (const auto& p : dr_per_ping_) poses.push_back({p.utime_us, fixed.correctionAt(p.utime_us).T_corrected_dr * p.T_world_body});
  return sss::optimiser::writeTum(dir + "/dead_reckoning_fixed.tum", poses,
                                  "sss-process: dead reckoning with the same fixes, no side-scan (graph without "
                                  "closures) at every ping" + frame_comment_,
                                  error, origin_);
}

// The corrected navigation for the survey's own tools: navigation.csv (every ping: UTC time,
// latitude, longitude, local north/east, depth below the ellipsoid, attitude, altitude, horizontal 1-sigma,
// DR or SLAM) and, when
// the frame is geographic, navigation.nmea (ZDA + GGA + HDT per ping, GGA quality 6: estimated).
bool Runner::writeNavigation(const std::string& dir, const std::vector<sss::optimiser::StampedPose>& slam,
                             std::string& error) const {
  std::vector<double> altitude_m;
  for (const PingAltitude& p : altitude_per_ping_) altitude_m.push_back(p.altitude_m);
  return sss::products::writeNavigationFiles(dir, slam, optimiser_, origin_, altitude_m, error);
}

// For GIS (QGIS opens them as they are; RFC 7946, WGS 84 longitude/latitude): track.geojson, the SLAM
// and DR tracks (a vertex every 4 pings), and subframes.geojson, each subframe's footprint on the
// seabed under the SLAM poses (its swath of canonical ground range either side, a vertex every 25
// pings) with its id and line. Only in a geographic frame.
bool Runner::writeCorrectedCopy(const std::vector<sss::optimiser::StampedPose>& slam, std::string& error) {
  std::optional<sss::core::LocalTangentPlane> plane;
  if (origin_) plane.emplace(origin_->latitude_deg, origin_->longitude_deg);
  if (!plane && !projected_origin_) return true;  // no frame on Earth: said in the findings
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
  const bool ok = hasExtension(request_.sonar_path, ".xtf")
                      ? sss::products::writeCorrectedXtf(request_.sonar_path, out_path, navigation, counters, error,
                                                         options_.xtf.pair_index)
                      : sss::products::writeCorrectedJsf(request_.sonar_path, out_path, navigation, counters, error);
  if (!ok) return false;
  summary_.corrected_copy = out_path;
  summary_.corrected_records = counters.records_corrected;
  summary_.corrected_records_without_pose = counters.records_without_pose;
  return true;
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

bool Runner::writeRaster(const std::string& dir, const std::string& name, const sss::products::FrameRaster& raster,
                         std::string& error) {
  if (!options_.write_geotiff) return true;
  const std::optional<sss::products::RasterFrame> frame = rasterFrame();
  if (!frame) return true;  // no frame on Earth (said once in the findings)
  sss::products::GeoTiffInfo info;
  if (!sss::products::writeGeoTiff(dir + "/" + name, raster, *frame, error, &info)) return false;
  summary_.geotiffs.push_back(name);
  summary_.geotiff_crs = info.crs_name;
  summary_.geotiff_epsg = info.epsg;
  return true;
}

bool Runner::writeGeoJson(const std::string& dir, const std::vector<sss::optimiser::StampedPose>& slam,
                          std::string& error) const {
  return sss::products::writeGeoJsonFiles(dir, slam, dr_per_ping_, footprints_, optimiser_, origin_, error);
}

// altitude.csv: the altitude every ping was processed with and where it came from.
bool Runner::writeAltitudeCsv(const std::string& path, std::string& error) const {
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (!f) {
    error = "cannot write " + path;
    return false;
  }
  std::fprintf(f, "# the sonar's altitude above the seabed each ping was processed with; source: nav (DVL), "
                  "ping_header (the sonar's own field) or bottom_track (its returns; quality 0..1)\n"
                  "utime_us,altitude_m,source,bottom_track_quality\n");
  for (const PingAltitude& p : altitude_per_ping_) {
    std::fprintf(f, "%lld,%.3f,%s,%.2f\n", static_cast<long long>(p.utime_us), p.altitude_m,
                 sss::subframe::altitudeSourceName(p.source), p.quality);
  }
  const bool ok = std::fclose(f) == 0;
  if (!ok) error = "cannot write " + path;
  return ok;
}

bool Runner::writeOutputs(std::string& error) {
  const std::string dir = request_.out_dir;
  // Per-ping trajectories: DR as fused, SLAM = the correction at the ping time applied to it.
  std::vector<sss::optimiser::StampedPose> slam;
  slam.reserve(dr_per_ping_.size());
  for (const auto& p : dr_per_ping_) {
    slam.push_back({p.utime_us, optimiser_.correctionAt(p.utime_us).T_corrected_dr * p.T_world_body});
  }
  summary_.pings_with_pose = dr_per_ping_.size();
  if (!sss::optimiser::writeTum(dir + "/dead_reckoning.tum", dr_per_ping_,
                                "sss-process: dead reckoning at every ping" + frame_comment_, error, origin_)) {
    return false;
  }
  if (!sss::optimiser::writeTum(dir + "/slam.tum", slam, "sss-process: SLAM-corrected pose at every ping" + frame_comment_,
                                error, origin_)) {
    return false;
  }
  if (!writeFixOutputs(dir, error)) return false;
  if (!writeNavigation(dir, slam, error)) return false;
  if (!writeGeoJson(dir, slam, error)) return false;
  if (!request_.corrected_dir.empty() && !writeCorrectedCopy(slam, error)) return false;
  if (!footprints_.empty()) {
    const sss::products::CoverageGrid coverage =
        sss::products::computeCoverage(sss::products::slamStrips(footprints_, optimiser_), 5.0);
    summary_.coverage_covered_m2 = coverage.covered_m2;
    summary_.coverage_seen_twice_m2 = coverage.seen_twice_m2;
    if (!sss::products::writeCoverageFiles(dir + "/coverage.yaml", coverage, error, origin_)) return false;
    if (!writeRaster(dir, "coverage.tif", sss::products::coverageRaster(coverage), error)) return false;
  }
  if (!sss::products::writeTieReportCsv(dir + "/loop_closures.csv", optimiser_, error)) return false;
  if (!writeAltitudeCsv(dir + "/altitude.csv", error)) return false;
  if (!match_writer_.close(error)) return false;

  const auto& counters = optimiser_.graph().counters();
  summary_.closures_accepted = counters.closures_accepted;
  summary_.closures_rejected = counters.closures_rejected_gate + counters.closures_rejected_inconsistent +
                               counters.closures_rejected_no_support;
  summary_.closures_superseded = counters.closures_superseded;
  summary_.variance_factors = optimiser_.graph().varianceFactors();
  summary_.separation_bias = optimiser_.graph().separationBias();
  summary_.calibration = optimiser_.graph().calibration();

  // Bathymetry: SLAM poses (the product) and DR poses (the baseline the map error is compared to).
  const auto& bathymetry = options_.optimiser.bathymetry;
  const std::vector<sss::optimiser::SeabedPoint> points = optimiser_.seabedPoints(false);
  const std::vector<sss::optimiser::SeabedPoint> points_dr = optimiser_.seabedPoints(true);
  summary_.seabed_points = points.size();
  if (!sss::optimiser::writeSeabedPly(dir + "/bathymetry.ply", points, error, origin_)) return false;
  if (!sss::optimiser::writeSeabedPly(dir + "/bathymetry_dr.ply", points_dr, error, origin_)) return false;
  const struct {
    const std::vector<sss::optimiser::SeabedPoint>& points;
    const char* name;
    const char* description;
  } heightmaps[] = {{points, "heightmap", "sss-process: seabed re-triangulated with the SLAM poses"},
                    {points_dr, "heightmap_dr", "sss-process: seabed triangulated with the DR poses"}};
  for (const auto& heightmap : heightmaps) {
    if (heightmap.points.empty()) continue;
    const sss::optimiser::HeightmapGrid grid = sss::optimiser::gridSeabedPoints(heightmap.points, bathymetry);
    if (!sss::optimiser::writeHeightmapFiles(dir + "/" + heightmap.name + ".yaml", grid, heightmap.description, error,
                                             origin_) ||
        !writeRaster(dir, std::string(heightmap.name) + ".tif",
                     sss::products::heightmapRaster(grid, std::string(heightmap.description) + " (depth m, down)"),
                     error)) {
      return false;
    }
  }

  if (request_.write_mosaics) {
    const std::optional<sss::products::RasterFrame> frame =
        options_.write_geotiff ? rasterFrame() : std::optional<sss::products::RasterFrame>();
    sss::products::GeoTiffInfo info;
    const size_t before = summary_.geotiffs.size();
    if (!sss::products::writeMosaicProducts(dir, mosaic_store_.subframes(), optimiser_, options_.pictures, origin_, frame,
                                            "sss-process", summary_.geotiffs, info, error)) {
      return false;
    }
    if (summary_.geotiffs.size() > before) {
      summary_.geotiff_crs = info.crs_name;
      summary_.geotiff_epsg = info.epsg;
    }
  }
  return true;
}

}  // namespace

OfflineResult runOffline(const OfflineRequest& request) {
  OfflineResult result;
  result.exit_code = 2;
  const bool from_log = !request.lcm_log_path.empty();
  if (from_log == !request.sonar_path.empty()) {
    result.error = "give either a sonar file (--sonar) or an LCM log (--lcm-log)";
    return result;
  }
  if (from_log && !request.corrected_dir.empty()) {
    result.error = "--write-corrected copies a sonar file: give --sonar, not --lcm-log";
    return result;
  }
  if (request.out_dir.empty()) {
    result.error = "no output folder (--out)";
    return result;
  }
  Options options;
  if (!readOptions(request.config_path, options, result.error)) return result;
  for (const std::string& path : {request.sonar_path, request.ins_path, request.lcm_log_path}) {
    if (path.empty()) continue;
    std::error_code ec;
    if (!fs::is_regular_file(path, ec)) {
      result.error = "cannot read " + path + ": no such file";
      return result;
    }
  }
  std::error_code ec;
  fs::create_directories(request.out_dir, ec);
  if (ec || !fs::is_directory(request.out_dir)) {
    result.error = "cannot create the output folder " + request.out_dir + (ec ? ": " + ec.message() : "");
    result.exit_code = 1;
    return result;
  }

  std::vector<sss::ins::PositionFix> fixes;
  FixSummary fix_summary;
  for (const std::string& spec : request.fix_paths) {
    std::vector<sss::ins::PositionFix> read;
    sss::ins::FixReaderCounters counters;
    std::string problem;
    if (!sss::ins::readPositionFixFile(spec, options.fix_reader, read, counters, problem, result.error)) return result;
    ++fix_summary.files;
    fix_summary.read += read.size();
    fix_summary.sentences_skipped += counters.rejected_sentences + counters.malformed + counters.no_fix;
    if (fix_summary.first_problem.empty() && !problem.empty()) fix_summary.first_problem = spec + ": " + problem;
    for (const auto& fix : read) ++(fix.source == sss::ins::FixSource::kGnss ? fix_summary.gnss : fix_summary.usbl);
    if (request.progress) {
      std::fprintf(request.progress, "sss-process: %zu fixes from %s (%llu GNSS, %llu USBL so far)%s%s\n", read.size(),
                   spec.c_str(), static_cast<unsigned long long>(fix_summary.gnss),
                   static_cast<unsigned long long>(fix_summary.usbl), problem.empty() ? "" : "; skipped: ",
                   problem.c_str());
    }
    fixes.insert(fixes.end(), read.begin(), read.end());
  }

  Runner runner(request, options);
  runner.summary().fixes = fix_summary;
  runner.setFixes(std::move(fixes));
  if (request.write_matches && !runner.openMatchWriter(result.error)) {
    result.exit_code = 1;
    return result;
  }
  uint64_t faults = 0;
  std::optional<Eigen::Vector2d> projected_origin;  // a projected frame (XTF NavUnits 0): E0, N0
  if (from_log) {
    lcm::LogFile log(request.lcm_log_path, "r");
    if (!log.good()) {
      result.error = "cannot read the LCM log " + request.lcm_log_path;
      return result;
    }
    const uint64_t size = fs::file_size(request.lcm_log_path, ec);
    uint64_t events = 0;
    for (const lcm::LogEvent* event = log.readNextEvent(); event; event = log.readNextEvent()) {
      if (event->channel == request.nav_channel) {
        sss_msgs::nav_t message;
        if (message.decode(event->data, 0, event->datalen) < 0) {
          ++faults;
          continue;
        }
        runner.addNav(sss::messages::fromNavMessage(message));
      } else if (event->channel == request.ping_channel) {
        sss_msgs::ping_t message;
        if (message.decode(event->data, 0, event->datalen) < 0) {
          ++faults;
          continue;
        }
        runner.addPing(sss::messages::fromPingMessage(message));
      }
      if (++events % 256 == 0 && size > 0) {
        runner.progress(static_cast<double>(std::ftell(log.getFilePtr())) / static_cast<double>(size), false);
      }
    }
    if (runner.summary().pings == 0) {
      result.error = "the LCM log " + request.lcm_log_path + " has no " + request.ping_channel + " messages";
      return result;
    }
  } else {
    std::unique_ptr<PingSource> pings;
    if (hasExtension(request.sonar_path, ".xtf")) {
      auto xtf = std::make_unique<XtfSource>(request.sonar_path, options.xtf);
      if (!xtf->reader().isOpen()) {
        result.error = "cannot read " + request.sonar_path + ": " + xtf->reader().error();
        return result;
      }
      pings = std::move(xtf);
    } else if (hasExtension(request.sonar_path, ".jsf")) {
      auto jsf = std::make_unique<JsfSource>(request.sonar_path, options.sonar);
      if (!jsf->good()) {
        result.error = "cannot read " + request.sonar_path;
        return result;
      }
      pings = std::move(jsf);
    } else {
      result.error = "unknown sonar file type " + request.sonar_path + " (expected .jsf or .xtf)";
      return result;
    }
    std::unique_ptr<InsFileSource> ins;
    std::optional<EmbeddedNavigation> embedded;
    if (!request.ins_path.empty()) {
      ins = std::make_unique<InsFileSource>(request.ins_path, options.ins);
      if (!ins->good()) {
        result.error = "cannot read " + request.ins_path;
        return result;
      }
    } else {
      embedded.emplace(options.origin);
    }
    // Merge by time: nav before a ping of the same time, so the ping finds its bracketing nav.
    // Everything goes through the SSS_PING and SSS_NAV messages, exactly as in the live chain.
    std::unique_ptr<lcm::LogFile> recording;
    if (!request.record_lcm_log_path.empty()) {
      recording = std::make_unique<lcm::LogFile>(request.record_lcm_log_path, "w");
      if (!recording->good()) {
        result.error = "cannot write the LCM log " + request.record_lcm_log_path;
        result.exit_code = 1;
        return result;
      }
    }
    int64_t event_number = 0;
    auto record = [&](const std::string& channel, const auto& message, int64_t utime_us) {
      if (!recording) return;
      std::vector<uint8_t> bytes(static_cast<size_t>(message.getEncodedSize()));
      message.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
      lcm::LogEvent event;
      event.eventnum = event_number++;
      event.timestamp = utime_us;
      event.channel = channel;
      event.datalen = static_cast<int32_t>(bytes.size());
      event.data = bytes.data();
      recording->writeEvent(&event);
    };
    std::deque<sss::edgetech::DriverPing> ping_queue;
    std::deque<sss_msgs::nav_t> nav_queue;
    // Navigation packets of the sonar file (XTF 3/42/107), used while its pings carry no
    // position of their own: fed in time order before the pings they precede.
    std::deque<FileNavigation> packet_queue;
    bool ping_positions_seen = false;
    auto feedPackets = [&](int64_t up_to_us) {
      while (!packet_queue.empty() && packet_queue.front().utime_us <= up_to_us) {
        if (embedded && !ping_positions_seen) {
          if (auto nav = embedded->fromPacket(packet_queue.front(), pings->projectedUnits())) {
            runner.addNav(*nav);
            ++runner.summary().nav_from_packets;
          }
        }
        packet_queue.pop_front();
      }
    };
    bool pings_left = true, nav_left = ins != nullptr;
    uint64_t without_nav = 0;
    for (;;) {
      while (pings_left && ping_queue.empty()) pings_left = pings->read(ping_queue);
      for (auto& record : pings->takeNavigation()) packet_queue.push_back(record);
      while (nav_left && nav_queue.empty()) nav_left = ins->read(nav_queue);
      if (ping_queue.empty() && nav_queue.empty()) break;
      const bool nav_first =
          !nav_queue.empty() && (ping_queue.empty() || nav_queue.front().utime <= ping_queue.front().utime_us);
      if (nav_first) {
        record(request.nav_channel, nav_queue.front(), nav_queue.front().utime);
        runner.addNav(sss::messages::fromNavMessage(nav_queue.front()));
        nav_queue.pop_front();
        continue;
      }
      sss::edgetech::DriverPing ping = std::move(ping_queue.front());
      ping_queue.pop_front();
      feedPackets(ping.utime_us);
      if (embedded) {
        if (auto nav = embedded->fromPing(ping)) {
          ping_positions_seen = true;
          runner.addNav(*nav);
        } else {
          ++without_nav;
          ++runner.summary().pings_without_position;
        }
      }
      const sss_msgs::ping_t message = sss::edgetech::toPingMessage(ping);
      record(request.ping_channel, message, message.utime);
      runner.addPing(sss::messages::fromPingMessage(message));
      runner.progress(pings->fractionRead(), false);
    }
    feedPackets(INT64_MAX);  // the file's last navigation, after its last ping
    faults += pings->faults() + (ins ? ins->faults() : 0);
    if (runner.summary().pings == 0) {
      result.error = "no usable pings in " + request.sonar_path;
      return result;
    }
    if (embedded) projected_origin = embedded->projectedOrigin();
    if (embedded && without_nav == runner.summary().pings && runner.summary().nav_from_packets == 0) {
      result.error = request.sonar_path + " carries no navigation in its ping headers; give an INS file with --ins";
      return result;
    }
  }
  if (projected_origin) runner.setProjectedOrigin(*projected_origin);
  runner.progress(1.0, true);
  runner.finish();
  runner.countStages();
  OfflineSummary& summary = runner.summary();
  summary.origin = runner.origin();
  if (projected_origin) {
    summary.origin_source = "projected_first_fix";
    summary.projected_origin_easting_m = projected_origin->x();
    summary.projected_origin_northing_m = projected_origin->y();
    char text[320];
    std::snprintf(text, sizeof text,
                  "projected metres (XTF NavUnits 0): north = northing - %.3f, east = easting - %.3f of the first "
                  "fix, in the file's grid; the file records no CRS, so no latitude/longitude; headings are used as "
                  "recorded (true north, not grid north)",
                  summary.projected_origin_northing_m, summary.projected_origin_easting_m);
    summary.origin_detail = text;
  } else if (options.origin) {
    summary.origin_source = sss::core::originSourceName(sss::core::OriginSource::kConfigured);
    summary.origin_detail = "mission.origin_latitude_deg / origin_longitude_deg in " + request.config_path;
  } else if (from_log) {
    summary.origin_source = sss::core::originSourceName(sss::core::OriginSource::kFromNavigation);
    summary.origin_detail = "carried by the log's " + request.nav_channel + " messages (the INS bridge's origin)";
  } else {
    summary.origin_source = sss::core::originSourceName(sss::core::OriginSource::kFirstFix);
    summary.origin_detail = request.ins_path.empty() ? "the first position in the sonar file's ping headers"
                                                     : "the first position fix in " + request.ins_path;
  }
  if (request.progress && summary.origin) {
    std::fprintf(request.progress, "sss-process: mission origin %.7f %.7f (%s: %s)\n", summary.origin->latitude_deg,
                 summary.origin->longitude_deg, summary.origin_source.c_str(), summary.origin_detail.c_str());
  } else if (request.progress && !summary.origin_detail.empty()) {
    std::fprintf(request.progress, "sss-process: frame: %s\n", summary.origin_detail.c_str());
  }
  summary.input_faults = faults;
  result.exit_code = 1;
  if (!runner.writeOutputs(result.error)) return result;
  summary.wall_s = wallSeconds() - runner.startSeconds();
  summary.mission_s = runner.missionSeconds();
  summary.real_time_factor = summary.wall_s > 0.0 ? summary.mission_s / summary.wall_s : 0.0;
  summary.peak_rss_mib = peakRssMib();
  summary.findings = explainRun(summary, options);
  for (const std::string& finding : explainFixes(summary.fixes, options)) summary.findings.push_back(finding);
  if (!request.corrected_dir.empty() && summary.pings_with_pose > 0) {
    if (summary.corrected_copy.empty()) {
      summary.findings.push_back("no corrected copy of " + request.sonar_path +
                                 ": the mission frame has no position on Earth; set mission.origin_latitude_deg and "
                                 "origin_longitude_deg");
    } else if (summary.corrected_records_without_pose > 0) {
      summary.findings.push_back(std::to_string(summary.corrected_records_without_pose) + " sonar records of " +
                                 summary.corrected_copy +
                                 " keep their recorded navigation: no pose at their time (before the navigation "
                                 "started, in a gap, or dropped by the chain)");
    }
  }
  if (options.write_geotiff && summary.pings_with_pose > 0) {
    if (summary.origin_source == "projected_first_fix" && options.projected_crs.empty()) {
      summary.findings.push_back(
          "GeoTIFFs without a CRS: the sonar file gives positions in projected metres (XTF NavUnits 0) and does not "
          "name its grid; set products.projected_crs (e.g. EPSG:32633) so that GIS software places them");
    } else if (summary.geotiffs.empty() && !summary.origin && summary.origin_source != "projected_first_fix") {
      summary.findings.push_back("no GeoTIFF: the mission frame has no position on Earth; set mission.origin_latitude_deg "
                                 "and origin_longitude_deg");
    }
  }
  result.summary = summary;
  if (!writeSummaryJson(request.out_dir + "/summary.json", request, summary, result.error)) return result;
  if (summary.pings_with_pose == 0 || summary.subframes == 0) {
    // Nothing could be processed: the outputs say so (summary.json), and so does the exit code.
    result.exit_code = 3;
    result.error = summary.findings.empty() ? "nothing could be processed" : summary.findings.front();
    return result;
  }
  result.ok = true;
  result.exit_code = 0;
  return result;
}

}  // namespace sss::offline
