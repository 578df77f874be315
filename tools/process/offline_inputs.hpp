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
#include <utility>
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
      if (r.nmea) {  // 2002: a GGA, RMC or GLL fix gives the position, at the message's (sonar clock) time
        if (const auto fix = sss::ins::parseNmeaPosition(*r.nmea)) {
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
  const sss::edgetech::PingAssemblerCounters& assemblerCounters() const { return driver_.assemblerCounters(); }
  uint64_t oldSideScanMessages() const { return driver_.oldSideScanMessages(); }
  uint64_t recordsWithLayback() const { return driver_.recordsWithLayback(); }
  double maxLaybackM() const { return driver_.maxLaybackM(); }

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
//
// Many recorders stamp every ping with the newest GPS or INS position they hold, so a 1 Hz GPS
// under a 10-30 Hz sonar repeats one position for 10-30 pings and then jumps: a staircase track
// whose steps are pixels of the image (the real Iver2 XTF repeats each position for 2-6 pings).
// A position that repeats the previous one exactly is no new fix: those samples are held back until
// the next new position and their horizontal position is interpolated in time between the two
// (attitude, depth and altitude stay each ping's own). A vehicle that really holds still repeats
// for longer than max_hold: those go out as recorded. The samples come out of takeReady() in time
// order; a held ping waits for its navigation in the ping-navigation fusion like any late nav.
class EmbeddedNavigation {
 public:
  static constexpr int64_t kMaxHoldUs = 10'000'000;  // a GPS at 0.1 Hz still interpolates
  static constexpr size_t kMaxHeldSamples = 128;      // within the fusion's 256 waiting pings

  explicit EmbeddedNavigation(const std::optional<sss::core::MissionOrigin>& origin) {
    if (origin) setOrigin(*origin);
  }
  const std::optional<sss::core::MissionOrigin>& origin() const { return origin_; }
  // Set once a ping with projected metres (XTF NavUnits 0) founded the frame: its easting, northing.
  const std::optional<Eigen::Vector2d>& projectedOrigin() const { return projected_origin_; }
  // True when the ping's header carries a position (its sample then comes out of takeReady, now or
  // once the next new position arrives).
  bool fromPing(const sss::sonar::DriverPing& driver_ping) {
    const auto& side = driver_ping.ping.port ? *driver_ping.ping.port : *driver_ping.ping.starboard;
    // The header fields a navigation packet borrows (not the samples: this runs for every ping).
    last_side_.validity = side.validity;
    last_side_.depth_m = side.depth_m;
    last_side_.altitude_m = side.altitude_m;
    last_side_.heading_rad = side.heading_rad;
    last_side_.pitch_rad = side.pitch_rad;
    last_side_.roll_rad = side.roll_rad;
    last_side_.layback_m = side.layback_m;  // a towfish's, for positions from navigation messages too
    return fromSide(driver_ping.utime_us, side);
  }
  // A navigation packet of an XTF whose pings carry no position (types 42 and 107 give one, 3
  // and 107 attitude): each position goes with the newest packet attitude (else the last ping's),
  // and the last ping's depth and altitude. Coordinates are in the file's NavUnits. True when the
  // packet gave a position.
  bool fromPacket(const FileNavigation& record, bool projected_units) {
    if (record.pitch_rad) packet_pitch_rad_ = record.pitch_rad;
    if (record.roll_rad) packet_roll_rad_ = record.roll_rad;
    if (record.heading_rad) packet_heading_rad_ = record.heading_rad;
    if (record.depth_m) packet_depth_m_ = record.depth_m;
    if (record.altitude_m) packet_altitude_m_ = record.altitude_m;
    if (!record.y || !record.x) return false;
    sss::sonar::SonarChannelRecord side = last_side_;
    side.pitch_rad = packet_pitch_rad_.value_or(side.pitch_rad);
    side.roll_rad = packet_roll_rad_.value_or(side.roll_rad);
    side.heading_rad = packet_heading_rad_.value_or(side.heading_rad);
    if (packet_heading_rad_) side.validity |= sss::sonar::kValidHeading;  // the packets' own heading
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
      if (std::abs(*record.y) > 90.0 || std::abs(*record.x) > 180.0) return false;
      side.latitude_deg = *record.y;
      side.longitude_deg = *record.x;
      side.validity |= sss::sonar::kValidLatLon;
    }
    return fromSide(record.utime_us, side);
  }
  // The samples complete so far, in time order.
  std::vector<NavInput> takeReady() { return std::exchange(ready_, {}); }
  // End of input: the samples still held keep the last position (nothing comes after it).
  std::vector<NavInput> finish() {
    flushHeld();
    releaseAwaitingCourse();
    return takeReady();
  }
  // Horizontal distance along the samples handed out (their own positions, in the frame's units).
  double distanceM() const { return distance_m_; }
  // Samples whose repeated position was interpolated between two new positions.
  uint64_t positionsInterpolated() const { return positions_interpolated_; }
  // Headers without a valid heading: given the recorded course over ground, the track's direction
  // over kCourseBaseM, or (the vehicle never moved that far) left as recorded.
  uint64_t headingsFromCourse() const { return headings_from_course_; }
  uint64_t headingsFromTrack() const { return headings_from_track_; }
  uint64_t headingsUnknown() const { return headings_unknown_; }
  // Samples without a heading of their own that took the next one to come (navigation messages
  // ahead of the first ping header, or headers without a heading before a valid one).
  uint64_t headingsFromNext() const { return headings_from_next_; }
  // Samples moved back by their towfish's layback (SonarChannelRecord::layback_m), the largest
  // layback, and samples left at the ship's position for want of a heading to move them along.
  uint64_t laybacksApplied() const { return laybacks_applied_; }
  double maxLaybackM() const { return max_layback_m_; }
  uint64_t laybacksWithoutHeading() const { return laybacks_without_heading_; }
  // Long enough that a JSF position's quantisation (1e-4 arc minute: 0.19 m) turns it by under a degree.
  static constexpr double kCourseBaseM = 10.0;

 private:
  bool fromSide(int64_t utime_us, const sss::sonar::SonarChannelRecord& side) {
    if (side.projected_position) return fromProjected(utime_us, side);
    if (!(side.validity & sss::sonar::kValidLatLon) && side.latitude_deg == 0.0 && side.longitude_deg == 0.0) {
      return false;  // no position in this ping
    }
    if (!plane_) {
      if (!sss::core::isFirstFixCandidate(side.latitude_deg, side.longitude_deg)) return false;
      setOrigin({side.latitude_deg, side.longitude_deg});
    }
    NavInput nav;
    nav.utime_us = utime_us;
    nav.origin = origin_;
    nav.position_ned_m = plane_->toNed({side.latitude_deg, side.longitude_deg, side.depth_m});
    const bool heading_from_track = fillAttitude(nav, side);
    hold({std::move(nav), heading_from_track, side.layback_m}, Eigen::Vector2d(side.latitude_deg, side.longitude_deg));
    return true;
  }

  // Projected metres: processed in the file's own grid, north = northing - N0, east = easting -
  // E0 of the first fix (the CRS is not in the file, so no latitude/longitude). The heading is
  // used as recorded: true north, which differs from the grid's north by the projection's
  // meridian convergence (within a degree or two in UTM).
  bool fromProjected(int64_t utime_us, const sss::sonar::SonarChannelRecord& side) {
    if (!projected_origin_) projected_origin_ = Eigen::Vector2d(side.easting_m, side.northing_m);
    NavInput nav;
    nav.utime_us = utime_us;
    nav.position_ned_m = Eigen::Vector3d(side.northing_m - projected_origin_->y(), side.easting_m - projected_origin_->x(),
                                         side.depth_m);
    const bool heading_from_track = fillAttitude(nav, side);
    hold({std::move(nav), heading_from_track, side.layback_m}, Eigen::Vector2d(side.northing_m, side.easting_m));
    return true;
  }
  // True when the header has no heading and the track's direction must stand in (emit).
  bool fillAttitude(NavInput& nav, const sss::sonar::SonarChannelRecord& side) {
    nav.roll_rad = side.roll_rad;
    nav.pitch_rad = side.pitch_rad;
    nav.heading_rad = side.heading_rad;
    nav.altitude_m = side.altitude_m;
    nav.altitude_valid = (side.validity & sss::sonar::kValidAltitude) != 0 && side.altitude_m > 0.0;
    // A header whose heading is flagged invalid (JSF validity bit 3 clear: a towfish without a
    // compass) holds a 0 that would turn every image to north. The recorded course over ground
    // stands in for it, else the track's own direction; neither sees a crab angle.
    if (side.validity & sss::sonar::kValidHeading) return false;
    if (!(side.validity & sss::sonar::kValidCourse)) return true;
    nav.heading_rad = side.course_rad;
    ++headings_from_course_;
    return false;
  }
  // A navigation sample on its way out; heading_from_track: its header had no heading of its own;
  // layback_m: the sensor trails the recorded (ship's) position by this much along its heading.
  struct Sample {
    NavInput nav;
    bool heading_from_track = false;
    double layback_m = 0.0;
  };
  // recorded: the position as the file holds it (compared exactly: a repeat is the same bytes).
  void hold(Sample sample, const Eigen::Vector2d& recorded) {
    const int64_t t_us = sample.nav.utime_us;
    const bool repeated = last_new_ && recorded == last_new_recorded_ && t_us >= last_new_->utime_us;
    if (repeated) {
      held_.push_back(std::move(sample));
      if (held_.size() >= kMaxHeldSamples || t_us - last_new_->utime_us > kMaxHoldUs) {
        flushHeld();  // holding still, or navigation that stopped: as recorded
      }
      return;
    }
    if (last_new_ && !held_.empty() && t_us > last_new_->utime_us) {
      const Eigen::Vector2d from = last_new_->position_ned_m.head<2>(), to = sample.nav.position_ned_m.head<2>();
      const double span_us = static_cast<double>(t_us - last_new_->utime_us);
      for (Sample& h : held_) {
        const double f = static_cast<double>(h.nav.utime_us - last_new_->utime_us) / span_us;
        h.nav.position_ned_m.head<2>() = from + f * (to - from);
        ++positions_interpolated_;
        emit(std::move(h));
      }
      held_.clear();
    }
    flushHeld();  // a new position out of time order: what was held keeps its position
    last_new_ = sample.nav;
    last_new_recorded_ = recorded;
    emit(std::move(sample));
  }
  void flushHeld() {
    if (held_.empty()) return;
    last_new_ = held_.back().nav;  // interpolation starts again from the last one held
    for (Sample& h : held_) emit(std::move(h));
    held_.clear();
  }
  // The distance travelled and the track's direction follow the recorded positions (the ship's,
  // when a layback is applied): the layback moves a sample once its heading is final.
  void emit(Sample sample) {
    NavInput& nav = sample.nav;
    if (last_) distance_m_ += (nav.position_ned_m - *last_).head<2>().norm();
    last_ = nav.position_ned_m;
    nav.distance_travelled_m = distance_m_;
    if (!sample.heading_from_track) {
      // In time order: samples still waiting for the track's direction (a navigation message before
      // the first ping header that gives the heading, or headers without one before this) take this
      // first heading that came after them rather than a 0 that turns their images to north.
      releaseAwaiting(nav.heading_rad, headings_from_next_);
      release(std::move(sample));
      return;
    }
    // The direction from the newest earlier position at least kCourseBaseM behind: over one ping
    // the step is position noise. Samples before the first such base wait for it.
    track_.push_back(nav.position_ned_m.head<2>());
    while (track_.size() > 2 && (track_.back() - track_[1]).norm() >= kCourseBaseM) track_.pop_front();
    const Eigen::Vector2d travelled = track_.back() - track_.front();
    awaiting_course_.push_back(std::move(sample));
    if (travelled.norm() >= kCourseBaseM) {
      const double course_rad = std::atan2(travelled.y(), travelled.x());
      releaseAwaiting(course_rad < 0.0 ? course_rad + 2.0 * M_PI : course_rad, headings_from_track_);
    } else if (awaiting_course_.size() >= kMaxHeldSamples) {
      releaseAwaitingCourse();  // holding still: no direction to take
    }
  }
  // The samples waiting for a heading, given heading_rad (counted in `given`), in time order.
  void releaseAwaiting(double heading_rad, uint64_t& given) {
    for (Sample& waiting : awaiting_course_) {
      waiting.nav.heading_rad = heading_rad;
      ++given;
      release(std::move(waiting));
    }
    awaiting_course_.clear();
  }
  // The same without a heading to give: left as recorded.
  void releaseAwaitingCourse() {
    for (Sample& waiting : awaiting_course_) {
      ++headings_unknown_;
      if (waiting.layback_m > 0.0) ++laybacks_without_heading_;  // no direction to move it in
      ready_.push_back(std::move(waiting.nav));
    }
    awaiting_course_.clear();
  }
  // Out with a final heading: a towfish whose position is the ship's is put layback_m behind it,
  // along its heading (as Isis does with XTF's Layback; a cross-current's offset is not seen).
  void release(Sample sample) {
    if (sample.layback_m > 0.0) {
      const double h = sample.nav.heading_rad;
      sample.nav.position_ned_m.x() -= sample.layback_m * std::cos(h);
      sample.nav.position_ned_m.y() -= sample.layback_m * std::sin(h);
      ++laybacks_applied_;
      max_layback_m_ = std::max(max_layback_m_, sample.layback_m);
    }
    ready_.push_back(std::move(sample.nav));
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
  std::optional<NavInput> last_new_;       // the newest sample with a new position (or the last held one)
  Eigen::Vector2d last_new_recorded_ = Eigen::Vector2d::Zero();
  std::vector<Sample> held_;               // samples repeating last_new_'s position, after it in time
  std::vector<NavInput> ready_;
  uint64_t positions_interpolated_ = 0;
  std::deque<Eigen::Vector2d> track_;      // emitted positions of those, back to kCourseBaseM
  std::vector<Sample> awaiting_course_;    // emitted before the track was kCourseBaseM long
  uint64_t headings_from_course_ = 0, headings_from_track_ = 0, headings_unknown_ = 0, headings_from_next_ = 0;
  uint64_t laybacks_applied_ = 0, laybacks_without_heading_ = 0;
  double max_layback_m_ = 0.0;
  std::optional<Eigen::Vector3d> last_;
  double distance_m_ = 0.0;
};

}  // namespace sss::offline
