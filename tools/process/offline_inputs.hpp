// sss-process's inputs in time order: pings from a sonar file (JSF, XTF), nav samples from an INS
// file or rebuilt from the navigation the sonar file carries. Internal to sss-process.
#pragma once

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <deque>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "drivers/edgetech/ping_message.hpp"
#include "drivers/ins/nav_message.hpp"
#include "drivers/ins/nmea_gga.hpp"
#include "pipeline/core/geodesy.hpp"
#include "tools/process/offline_options.hpp"

namespace sss::offline {

namespace fs = std::filesystem;
using sss::subframe::NavInput;
using sss::subframe::PingInput;


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
  virtual bool read(std::deque<sss::sonar::DriverPing>& out) = 0;
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
  bool read(std::deque<sss::sonar::DriverPing>& out) override {
    if (finished_) return false;
    std::vector<char> chunk(1 << 20);
    file_.read(chunk.data(), static_cast<std::streamsize>(chunk.size()));
    const std::streamsize n = file_.gcount();
    read_ += static_cast<uint64_t>(std::max<std::streamsize>(n, 0));
    std::vector<sss::sonar::DriverPing> pings;
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
  bool read(std::deque<sss::sonar::DriverPing>& out) override {
    sss::sonar::DriverPing ping;
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
  std::optional<NavInput> fromPing(const sss::sonar::DriverPing& driver_ping) {
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
    sss::sonar::SonarChannelRecord side = last_side_;
    side.pitch_rad = packet_pitch_rad_.value_or(side.pitch_rad);
    side.roll_rad = packet_roll_rad_.value_or(side.roll_rad);
    side.heading_rad = packet_heading_rad_.value_or(side.heading_rad);
    side.depth_m = packet_depth_m_.value_or(side.depth_m);
    if (packet_altitude_m_ && *packet_altitude_m_ > 0.0) {
      side.altitude_m = *packet_altitude_m_;
      side.validity |= sss::sonar::kValidAltitude;
    }
    side.projected_position = projected_units;
    side.validity = static_cast<uint16_t>(side.validity & ~sss::sonar::kValidLatLon);
    if (projected_units) {
      side.northing_m = *record.y;
      side.easting_m = *record.x;
    } else {
      if (std::abs(*record.y) > 90.0 || std::abs(*record.x) > 180.0) return std::nullopt;
      side.latitude_deg = *record.y;
      side.longitude_deg = *record.x;
      side.validity |= sss::sonar::kValidLatLon;
    }
    return fromSide(record.utime_us, side);
  }

 private:
  std::optional<NavInput> fromSide(int64_t utime_us, const sss::sonar::SonarChannelRecord& side) {
    if (side.projected_position) return fromProjected(utime_us, side);
    if (!(side.validity & sss::sonar::kValidLatLon) && side.latitude_deg == 0.0 && side.longitude_deg == 0.0) {
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
  std::optional<NavInput> fromProjected(int64_t utime_us, const sss::sonar::SonarChannelRecord& side) {
    if (!projected_origin_) projected_origin_ = Eigen::Vector2d(side.easting_m, side.northing_m);
    NavInput nav;
    nav.utime_us = utime_us;
    nav.position_ned_m = Eigen::Vector3d(side.northing_m - projected_origin_->y(), side.easting_m - projected_origin_->x(),
                                         side.depth_m);
    fillAttitude(nav, side);
    return nav;
  }
  void fillAttitude(NavInput& nav, const sss::sonar::SonarChannelRecord& side) {
    nav.roll_rad = side.roll_rad;
    nav.pitch_rad = side.pitch_rad;
    nav.heading_rad = side.heading_rad;
    nav.altitude_m = side.altitude_m;
    nav.altitude_valid = (side.validity & sss::sonar::kValidAltitude) != 0 && side.altitude_m > 0.0;
    if (last_) distance_m_ += (nav.position_ned_m - *last_).head<2>().norm();
    last_ = nav.position_ned_m;
    nav.distance_travelled_m = distance_m_;
  }
  std::optional<Eigen::Vector2d> projected_origin_;
  sss::sonar::SonarChannelRecord last_side_;  // the last ping's header (depth, altitude, attitude)
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

}  // namespace sss::offline
