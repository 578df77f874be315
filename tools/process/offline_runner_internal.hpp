// sss-process's runner: the chain's libraries in one deterministic thread (subframe buffer,
// matcher, optimiser, fixes), fed in time order by runOffline, and the outputs it writes.
// Internal to sss-process.
#pragma once

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

#include "tools/process/offline_runner.hpp"

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
#include "tools/eval/json_values.hpp"
#include "products/coverage.hpp"
#include "products/footprints.hpp"
#include "tools/process/match_writer.hpp"
#include "tools/process/offline_options.hpp"

namespace sss::offline {

using sss::core::Status;
using sss::subframe::NavInput;
using sss::subframe::PingInput;


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
    if (nav.position_valid) optimiser_.addNavAccuracy(sss::optimiser::navAccuracyOf(nav));
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

  Status writeOutputs();
  Status writeFixOutputs(const std::string& dir);
  Status writeNavigation(const std::string& dir, const std::vector<sss::optimiser::StampedPose>& slam) const;
  Status writeGeoJson(const std::string& dir, const std::vector<sss::optimiser::StampedPose>& slam) const;
  // --write-corrected: the sonar file with the SLAM navigation in every ping.
  Status writeCorrectedCopy(const std::vector<sss::optimiser::StampedPose>& slam);
  // The GeoTIFFs' frame: the origin's tangent plane, or the file's projected grid; nullopt: neither.
  std::optional<sss::products::RasterFrame> rasterFrame() const;
  // Writes dir/name as a GeoTIFF when the run has a frame on Earth and GeoTIFFs are on.
  Status writeRaster(const std::string& dir, const std::string& name, const sss::products::FrameRaster& raster);
  Status writeAltitudeCsv(const std::string& path) const;
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
    summary_.survey_lines = pings_per_line_.size();
    summary_.short_lines = 0;
    for (const auto& [line, pings] : pings_per_line_)
      if (pings < static_cast<size_t>(options_.buffer.subframes.pings_per_subframe)) ++summary_.short_lines;
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
  Status openMatchWriter() {
    const Status opened = match_writer_.open(request_.out_dir + "/matches.csv", options_.matcher.pair.dense.stride, 4);
    if (!opened) return opened;
    matcher_.setPairMatchObserver([this](const sss::core::Subframe& a, const sss::core::Subframe& b, int round,
                                         const sss::matcher::PairMatch& match) {
      match_writer_.addPair(a, b, round, match);
    });
    return Status::success();
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
      if (const sss::core::Status added = optimiser_.addSubframe(subframe); !added) {
        // Without a node its closures would be refused too: the subframe is left out of SLAM.
        if (summary_.subframes_refused++ == 0) summary_.first_subframe_refusal = added.message;
        continue;
      }
      centres_.push_back({subframe.line_id, subframe.centre().T_world_body});
      pings_per_line_[subframe.line_id] += subframe.pings.size();
      footprints_.push_back(sss::products::footprintOf(subframe));
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
  std::map<int, size_t> pings_per_line_;                   // in the subframes of each line
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

}  // namespace sss::offline
