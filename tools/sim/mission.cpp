// Mission assembly and outputs (options: sim_options.cpp): the seabed sized to the survey, parallel ping
// rendering in chunks (JSF streamed to disk), TUM trajectories, seabed rasters, PNG previews.
#include "tools/sim/mission.hpp"

#include "pipeline/core/mission_origin.hpp"

#include "drivers/edgetech/jsf_format.hpp"
#include "drivers/ins/ixblue_nmea.hpp"
#include "drivers/ins/position_fix.hpp"

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>

namespace sss::sim {

using sss::core::Status;
namespace {

constexpr double kPi = 3.14159265358979323846;

}  // namespace

// ---- Mission ------------------------------------------------------------------------------------

Mission::Mission(const SimOptions& options)
    : options_(options), plane_(options.origin_latitude_deg, options.origin_longitude_deg) {
  const auto seed = static_cast<uint64_t>(options_.seed);
  options_.seabed.seed = mixSeed(seed, 1);
  options_.trajectory.seed = mixSeed(seed, 2);
  options_.dead_reckoning.seed = mixSeed(seed, 3);
  options_.sonar.seed = mixSeed(seed, 4);
  // The vehicle surfaces where its GNSS fixes are to be taken.
  options_.trajectory.surface = options_.fixes.gnss;
  if (options_.auto_seabed_extent) {
    // The seabed covers the path plus the swath and a margin on every side.
    const Eigen::Vector4d extent = Trajectory::planExtent(options_.trajectory);
    const double pad = options_.sonar.range_m + options_.seabed_margin_m;
    options_.seabed.north_min_m = std::floor(extent[0] - pad);
    options_.seabed.east_min_m = std::floor(extent[1] - pad);
    options_.seabed.size_north_m = std::ceil(extent[2] + pad) - options_.seabed.north_min_m;
    options_.seabed.size_east_m = std::ceil(extent[3] + pad) - options_.seabed.east_min_m;
  }
  seabed_ = std::make_unique<Seabed>(options_.seabed);
  trajectory_ = std::make_unique<Trajectory>(options_.trajectory, seabed_.get());
  duration_s_ = trajectory_->durationS();
  if (options_.duration_s > 0.0) duration_s_ = std::min(duration_s_, options_.duration_s);
  dead_reckoning_ = std::make_unique<DeadReckoning>(options_.dead_reckoning, *trajectory_, duration_s_);
  sonar_ = std::make_unique<SonarModel>(options_.sonar, seabed_.get());
  ping_count_ = static_cast<size_t>(std::floor(duration_s_ * options_.sonar.ping_rate_hz + 1e-9)) + 1;
}

int64_t Mission::pingUtimeUs(size_t ping) const {
  return options_.start_utime_us + static_cast<int64_t>(std::llround(pingTimeS(ping) * 1e6));
}

std::vector<size_t> Mission::pingsOfLine(int line_index) const {
  std::vector<size_t> pings;
  for (size_t i = 0; i < ping_count_; ++i) {
    if (truthAtPing(i).line_index == line_index) pings.push_back(i);
  }
  return pings;
}

PingSamples Mission::renderPing(size_t ping) const {
  return sonar_->render(truthAtPing(ping).T_world_body, static_cast<uint32_t>(ping));
}

std::vector<uint8_t> Mission::encodePingJsf(size_t ping, const PingSamples& samples, uint8_t& sequence) const {
  namespace jsf = sss::edgetech;
  const NavSample nav = dead_reckoning_->sampleAt(pingTimeS(ping));
  const sss::core::GeodeticPosition geo = plane_.toGeodetic(nav.T_world_body.translation);
  jsf::SonarChannelRecord record;
  record.subsystem = options_.sonar.jsf_subsystem >= 0 ? static_cast<uint8_t>(options_.sonar.jsf_subsystem)
                     : options_.sonar.frequency_hz < 600e3 ? jsf::kSubsystemSideScanLow
                                                             : jsf::kSubsystemSideScanHigh;
  record.ping_time_us = pingUtimeUs(ping);
  record.ping_number = static_cast<uint32_t>(ping);
  record.start_depth_samples = 0;
  record.sample_interval_s = options_.sonar.sampleIntervalS();
  record.sound_speed_m_s = static_cast<float>(options_.sonar.sound_speed_m_s);
  record.start_frequency_hz = static_cast<float>(options_.sonar.frequency_hz - 0.5 * options_.sonar.bandwidth_hz);
  record.end_frequency_hz = static_cast<float>(options_.sonar.frequency_hz + 0.5 * options_.sonar.bandwidth_hz);
  record.data_format = 0;
  // The sonar processor stamps the vehicle's (DR) navigation into every ping header.
  record.validity = jsf::kValidLatLon | jsf::kValidHeading | jsf::kValidPitchRoll | jsf::kValidAltitude |
                    jsf::kValidDepth | jsf::kValidSoundSpeed;
  record.latitude_deg = geo.latitude_deg;
  record.longitude_deg = geo.longitude_deg;
  record.depth_m = geo.depth_m;
  record.altitude_m = nav.altitude_m;
  if (!options_.record_altitude) {
    record.validity &= ~jsf::kValidAltitude;
    record.altitude_m = 0.0;
  }
  record.heading_rad = nav.heading_rad < 0.0 ? nav.heading_rad + 2.0 * kPi : nav.heading_rad;
  record.pitch_rad = nav.pitch_rad;
  record.roll_rad = nav.roll_rad;
  std::vector<uint8_t> bytes;
  for (uint8_t channel : {jsf::kChannelPort, jsf::kChannelStarboard}) {
    record.channel = channel;
    const std::vector<float>& magnitudes = channel == jsf::kChannelPort ? samples.port : samples.starboard;
    int16_t weighting = 0;
    const std::vector<uint16_t> codes = jsf::quantiseEnvelope(magnitudes, weighting);
    record.weighting_factor = weighting;
    const std::vector<uint8_t> message = jsf::encodeSonarData(record, codes, sequence++);
    bytes.insert(bytes.end(), message.begin(), message.end());
  }
  return bytes;
}

std::string fixesNmea(const Mission& mission) {
  const SimFixOptions& f = mission.options().fixes;
  struct Timed {
    double time_s;
    std::string text;
  };
  std::vector<Timed> sentences;
  std::mt19937_64 rng(mixSeed(static_cast<uint64_t>(mission.options().seed), 5));
  std::normal_distribution<double> gauss(0.0, 1.0);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  const sss::core::LocalTangentPlane& plane = mission.tangentPlane();
  auto fixAt = [&](double time_s, const Eigen::Vector2d& position_ne_m, double sigma_m, int satellites) {
    sss::ins::PositionFix fix;
    fix.utime_us = mission.options().start_utime_us + static_cast<int64_t>(std::llround(time_s * 1e6));
    const sss::core::GeodeticPosition geo = plane.toGeodetic(Eigen::Vector3d(position_ne_m.x(), position_ne_m.y(), 0.0));
    fix.latitude_deg = geo.latitude_deg;
    fix.longitude_deg = geo.longitude_deg;
    fix.sigma_north_m = fix.sigma_east_m = sigma_m;
    fix.quality = 1;
    fix.satellites = satellites;
    fix.hdop = 0.9;
    return fix;
  };
  const double duration_s = mission.durationS();
  if (f.gnss != "none") {
    Eigen::Vector2d error_m = Eigen::Vector2d::Zero();
    double previous_s = -1.0;  // time of the previous fix (-1: none yet)
    for (double t = 0.0; t <= duration_s; t += f.gnss_period_s) {
      const TrajectorySample truth = mission.trajectory().sample(t);
      if (truth.T_world_body.translation.z() > f.gnss_max_depth_m) continue;
      const Eigen::Vector2d noise(gauss(rng), gauss(rng));
      // Gauss-Markov: what is left of the previous fix's error plus a fresh part, stationary sigma.
      const double rho =
          previous_s >= 0.0 && f.gnss_correlation_time_s > 0.0 ? std::exp(-(t - previous_s) / f.gnss_correlation_time_s) : 0.0;
      error_m = rho * error_m + std::sqrt(1.0 - rho * rho) * f.gnss_sigma_m * noise;
      previous_s = t;
      const Eigen::Vector2d measured = truth.T_world_body.translation.head<2>() + error_m;
      sentences.push_back({t, sss::ins::encodePositionFix(fixAt(t, measured, f.gnss_sigma_m, 10), "GP")});
    }
  }
  if (f.usbl_period_s > 0.0) {
    // The ship holds station at the surface over the middle of the survey.
    const Eigen::Vector4d extent = Trajectory::planExtent(mission.trajectory().options());
    const Eigen::Vector3d ship(0.5 * (extent[0] + extent[2]), 0.5 * (extent[1] + extent[3]), 0.0);
    for (double t = f.usbl_period_s; t <= duration_s; t += f.usbl_period_s) {
      const TrajectorySample truth = mission.trajectory().sample(t);
      const bool dropped = uniform(rng) < f.usbl_dropout_fraction;
      const bool outlier = uniform(rng) < f.usbl_outlier_fraction;
      const Eigen::Vector2d noise(gauss(rng), gauss(rng));
      const double outlier_m = f.usbl_outlier_min_m + (f.usbl_outlier_max_m - f.usbl_outlier_min_m) * uniform(rng);
      const double outlier_angle = 2.0 * M_PI * uniform(rng);
      if (dropped || truth.T_world_body.translation.z() < 2.0) continue;  // no reply; or at the surface
      const double slant_m = (truth.T_world_body.translation - ship).norm();
      const double sigma_m = f.usbl_sigma_floor_m + f.usbl_sigma_fraction * slant_m;
      Eigen::Vector2d measured = truth.T_world_body.translation.head<2>() + sigma_m * noise;
      if (outlier) measured += outlier_m * Eigen::Vector2d(std::cos(outlier_angle), std::sin(outlier_angle));
      sentences.push_back({t, sss::ins::encodePositionFix(fixAt(t, measured, sigma_m, 0), "II")});
    }
  }
  std::stable_sort(sentences.begin(), sentences.end(), [](const Timed& a, const Timed& b) { return a.time_s < b.time_s; });
  std::string out;
  for (const Timed& s : sentences) out += s.text;
  return out;
}

std::string insNmeaStream(const Mission& mission) {
  std::string stream;
  const sss::core::LocalTangentPlane& plane = mission.tangentPlane();
  for (const NavSample& nav : mission.deadReckoning().samples()) {
    sss::ins::InsState state;
    state.utime_us = mission.options().start_utime_us + static_cast<int64_t>(std::llround(nav.time_s * 1e6));
    const sss::core::GeodeticPosition geo = plane.toGeodetic(nav.T_world_body.translation);
    state.latitude_deg = geo.latitude_deg;
    state.longitude_deg = geo.longitude_deg;
    state.depth_m = geo.depth_m;
    state.altitude_m = nav.altitude_m;
    state.roll_rad = nav.roll_rad;
    state.pitch_rad = nav.pitch_rad;
    state.heading_rad = nav.heading_rad;
    state.velocity_north_m_s = nav.velocity_world_m_s.x();
    state.velocity_east_m_s = nav.velocity_world_m_s.y();
    state.velocity_down_m_s = nav.velocity_world_m_s.z();
    state.latitude_std_m = nav.position_std_m;
    state.longitude_std_m = nav.position_std_m;
    state.depth_std_m = 0.05;
    state.roll_std_rad = 0.0003;
    state.pitch_std_rad = 0.0003;
    const DeadReckoningOptions& dr = mission.options().dead_reckoning;
    state.heading_std_rad = dr.drift_scale * dr.reported_heading_std_rad;
    state.velocity_north_std_m_s = 0.01;
    state.velocity_east_std_m_s = 0.01;
    state.velocity_down_std_m_s = 0.01;
    state.validity = sss::ins::kValidAll;
    if (!mission.options().record_altitude) state.validity &= ~sss::ins::kValidAltitude;
    stream += sss::ins::encodeInsState(state);
  }
  return stream;
}

// ---- outputs ------------------------------------------------------------------------------------

namespace {

Status writeBinary(const std::string& path, const void* data, size_t bytes) {
  std::ofstream out(path, std::ios::binary);
  out.write(static_cast<const char*>(data), static_cast<std::streamsize>(bytes));
  if (!out) {
    return Status::error("cannot write " + path + "; check the output directory is writable and has space");
  }
  return Status::success();
}

Status writeText(const std::string& path, const std::string& text) {
  return writeBinary(path, text.data(), text.size());
}

std::string tumLine(int64_t utime_us, const sss::core::Pose& pose) {
  char line[256];
  const Eigen::Quaterniond& q = pose.rotation;
  std::snprintf(line, sizeof line, "%lld.%06lld %.4f %.4f %.4f %.9f %.9f %.9f %.9f\n",
                static_cast<long long>(utime_us / 1000000), static_cast<long long>(utime_us % 1000000),
                pose.translation.x(), pose.translation.y(), pose.translation.z(), q.x(), q.y(), q.z(), q.w());
  return line;
}

// The value below which `fraction` of the positive samples lie: a robust display white level.
float percentile(std::vector<float> values, double fraction) {
  values.erase(std::remove_if(values.begin(), values.end(), [](float v) { return !(v > 0.0f); }), values.end());
  if (values.empty()) return 1.0f;
  const size_t k = std::min(values.size() - 1, static_cast<size_t>(fraction * values.size()));
  std::nth_element(values.begin(), values.begin() + k, values.end());
  return std::max(values[k], 1e-6f);
}

cv::Mat toImage8(const std::vector<float>& values, int rows, int cols, float white) {
  cv::Mat image(rows, cols, CV_8UC1);
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      const float v = values[static_cast<size_t>(r) * cols + c] / white;
      image.at<uint8_t>(r, c) = static_cast<uint8_t>(std::clamp(v * 255.0f, 0.0f, 255.0f));
    }
  }
  return image;
}

Status writePng(const std::string& path, const cv::Mat& image) {
  try {
    if (cv::imwrite(path, image)) return Status::success();
  } catch (const cv::Exception& e) {
    return Status::error("cannot write " + path + ": " + e.what());
  }
  return Status::error("cannot write " + path);
}

Status writeSeabed(const Mission& mission, const std::string& dir, MissionReport& report) {
  const Seabed& seabed = mission.seabed();
  const SeabedOptions& o = seabed.options();
  const auto& depth = seabed.depthGrid();
  const auto& reflect = seabed.reflectivityGrid();
  // Raw float32 in the host byte order; every supported target (x86-64, aarch64) is little-endian.
  if (const Status written =
          writeBinary(dir + "/seabed_depth.f32", depth.data(), depth.size() * sizeof(float));
      !written) {
    return written;
  }
  if (const Status written =
          writeBinary(dir + "/seabed_reflectivity.f32", reflect.data(), reflect.size() * sizeof(float));
      !written) {
    return written;
  }
  std::ostringstream yaml;
  yaml.precision(12);
  yaml << "# True seabed of the simulated mission: two raw little-endian float32 rasters, row-major.\n"
       << "# Cell (row, col) lies at north = north_min_m + row * resolution_m, east = east_min_m + col *\n"
       << "# resolution_m in the local NED plane of the origin; rows grow northwards.\n"
       << "rows: " << seabed.rows() << "\ncols: " << seabed.cols() << "\nresolution_m: " << o.resolution_m
       << "\nnorth_min_m: " << o.north_min_m << "\neast_min_m: " << o.east_min_m
       << "\norigin_latitude_deg: " << mission.options().origin_latitude_deg
       << "\norigin_longitude_deg: " << mission.options().origin_longitude_deg
       << "\ndepth_file: seabed_depth.f32\ndepth_units: metres below the origin (NED z, positive down)"
       << "\nreflectivity_file: seabed_reflectivity.f32\nreflectivity_units: backscatter coefficient (dimensionless)\n";
  if (const Status written = writeText(dir + "/seabed.yaml", yaml.str()); !written) return written;

  // Previews at 4 cells per pixel, north up: hill-shaded depth and reflectivity.
  const int step = 4;
  const int rows = seabed.rows() / step;
  const int cols = seabed.cols() / step;
  cv::Mat shade(rows, cols, CV_8UC1);
  cv::Mat refl(rows, cols, CV_8UC1);
  double min_depth = 1e18, max_depth = -1e18;
  for (float d : depth) {
    min_depth = std::min(min_depth, static_cast<double>(d));
    max_depth = std::max(max_depth, static_cast<double>(d));
  }
  const Eigen::Vector3d light = Eigen::Vector3d(-1.0, -1.0, -1.0).normalized();  // from the north-west, above
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      const double north = o.north_min_m + r * step * o.resolution_m;
      const double east = o.east_min_m + c * step * o.resolution_m;
      const double relief = (seabed.depthM(north, east) - min_depth) / std::max(1e-6, max_depth - min_depth);
      const double lambert = std::max(0.0, seabed.normal(north, east).dot(-light) * -1.0 + 0.0);
      const double value = 0.55 * std::clamp(lambert, 0.0, 1.0) + 0.45 * (1.0 - relief);
      shade.at<uint8_t>(rows - 1 - r, c) = static_cast<uint8_t>(std::clamp(value * 255.0, 0.0, 255.0));
      refl.at<uint8_t>(rows - 1 - r, c) =
          static_cast<uint8_t>(std::clamp(seabed.reflectivity(north, east) / 1.2 * 255.0, 0.0, 255.0));
    }
  }
  if (const Status written = writePng(dir + "/seabed_depth.png", shade); !written) return written;
  if (const Status written = writePng(dir + "/seabed_reflectivity.png", refl); !written) return written;
  for (const char* name : {"seabed_depth.f32", "seabed_reflectivity.f32", "seabed.yaml", "seabed_depth.png",
                           "seabed_reflectivity.png"}) {
    report.files.push_back(name);
  }
  return Status::success();
}

}  // namespace

Status writeMission(const Mission& mission, const std::string& out_dir, MissionReport& report) {
  const auto start = std::chrono::steady_clock::now();
  std::error_code ec;
  std::filesystem::create_directories(out_dir, ec);
  if (ec) {
    return Status::error("cannot create " + out_dir + ": " + ec.message());
  }
  const std::string dir = out_dir;
  const SimOptions& options = mission.options();
  const SonarOptions& sonar = mission.sonar().options();
  const size_t pings = mission.pingCount();
  report = MissionReport();
  report.pings = pings;
  report.duration_s = mission.durationS();
  report.distance_m = mission.deadReckoning().distanceTravelledM();

  if (const Status written = writeSeabed(mission, dir, report); !written) return written;

  // Trajectories, one line per ping.
  // The frame's origin heads both files, so that a run with another origin is compared right.
  const std::string origin_line =
      sss::core::originCommentLine({mission.options().origin_latitude_deg, mission.options().origin_longitude_deg}) + "\n";
  std::string truth_text = origin_line, dr_text = origin_line;
  for (size_t i = 0; i < pings; ++i) {
    const int64_t utime = mission.pingUtimeUs(i);
    const sss::core::Pose truth = mission.truthAtPing(i).T_world_body;
    const sss::core::Pose dr = mission.deadReckoning().poseAt(mission.pingTimeS(i));
    truth_text += tumLine(utime, truth);
    dr_text += tumLine(utime, dr);
    const double err = (truth.translation - dr.translation).head<2>().norm();
    report.max_dr_error_m = std::max(report.max_dr_error_m, err);
    if (i + 1 == pings) report.final_dr_error_m = err;
  }
  if (const Status written = writeText(dir + "/ground_truth.tum", truth_text); !written) return written;
  if (const Status written = writeText(dir + "/dead_reckoning.tum", dr_text); !written) return written;
  report.files.push_back("ground_truth.tum");
  report.files.push_back("dead_reckoning.tum");

  // INS stream: iXblue NMEA ($PIXSE family) at the DR rate.
  if (const Status written = writeText(dir + "/ins.nmea", insNmeaStream(mission)); !written) return written;
  report.files.push_back("ins.nmea");
  if (options.fixes.gnss != "none" || options.fixes.usbl_period_s > 0.0) {
    if (const Status written = writeText(dir + "/fixes.nmea", fixesNmea(mission)); !written) return written;
    report.files.push_back("fixes.nmea");
  }

  // Pings: rendered in parallel chunks, written in order.
  const int bins = options.waterfall_bins_per_side;
  const int samples = sonar.samples_per_side;
  const double spacing = sonar.sampleSpacingM();
  std::vector<std::vector<float>> line_rows;  // per ping: 2 * bins, port mirrored on the left
  std::vector<int> ping_line(pings, -1);
  line_rows.resize(pings);
  const SeabedOptions& bed = mission.seabed().options();
  const double along_track_step = options.trajectory.speed_m_s / sonar.ping_rate_hz;
  const double mres = options.mosaic_resolution_m;
  const int mosaic_rows = static_cast<int>(std::ceil(bed.size_north_m / mres));
  const int mosaic_cols = static_cast<int>(std::ceil(bed.size_east_m / mres));
  std::vector<float> mosaic_sum(static_cast<size_t>(mosaic_rows) * mosaic_cols, 0.0f);
  std::vector<uint16_t> mosaic_count(mosaic_sum.size(), 0);

  std::ofstream jsf_out(dir + "/sonar.jsf", std::ios::binary);
  if (!jsf_out) {
    return Status::error("cannot write " + dir + "/sonar.jsf");
  }
  const auto render_start = std::chrono::steady_clock::now();
  uint8_t sequence = 0;
  const size_t chunk = 64;
  std::vector<PingSamples> rendered(chunk);
  for (size_t first = 0; first < pings; first += chunk) {
    const size_t count = std::min(chunk, pings - first);
#pragma omp parallel for schedule(dynamic, 1)
    for (long k = 0; k < static_cast<long>(count); ++k) rendered[k] = mission.renderPing(first + k);
    for (size_t k = 0; k < count; ++k) {
      const size_t ping = first + k;
      const std::vector<uint8_t> bytes = mission.encodePingJsf(ping, rendered[k], sequence);
      jsf_out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
      const TrajectorySample truth = mission.truthAtPing(ping);
      ping_line[ping] = truth.line_index;
      if (truth.line_index < 0) continue;
      std::vector<float>& row = line_rows[ping];
      row.assign(2 * bins, 0.0f);
      for (Side side : {Side::kPort, Side::kStarboard}) {
        const std::vector<float>& values = side == Side::kPort ? rendered[k].port : rendered[k].starboard;
        const FanPlane plane = fanPlane(truth.T_world_body, side);
        for (int j = 0; j < bins; ++j) {
          const int s0 = static_cast<int>(static_cast<int64_t>(j) * samples / bins);
          const int s1 = std::max(s0 + 1, static_cast<int>(static_cast<int64_t>(j + 1) * samples / bins));
          double sum = 0.0;
          for (int s = s0; s < s1; ++s) sum += values[s];
          const float mean = static_cast<float>(sum / (s1 - s0));
          row[side == Side::kPort ? bins - 1 - j : bins + j] = mean;
          // Mosaic: flat-seabed ground range at the true altitude, from the true position.
          const double range = 0.5 * (s0 + s1) * spacing;
          if (range <= truth.altitude_m) continue;
          const double ground = std::sqrt(range * range - truth.altitude_m * truth.altitude_m);
          // Each sample stands for one ping spacing of track: splatting it at two along-track taps
          // keeps every line's contribution in every cell it covers (else cells alias between
          // lines and the overlap average stripes).
          for (const double tap : {-0.25, 0.25}) {
            const Eigen::Vector3d p = plane.origin + ground * plane.outward + tap * along_track_step * plane.normal;
            const int mr = static_cast<int>(std::floor((p.x() - bed.north_min_m) / mres));
            const int mc = static_cast<int>(std::floor((p.y() - bed.east_min_m) / mres));
            if (mr < 0 || mc < 0 || mr >= mosaic_rows || mc >= mosaic_cols) continue;
            const size_t index = static_cast<size_t>(mosaic_rows - 1 - mr) * mosaic_cols + mc;
            mosaic_sum[index] += mean;
            if (mosaic_count[index] < 65535) ++mosaic_count[index];
          }
        }
      }
    }
  }
  jsf_out.close();
  if (!jsf_out) {
    return Status::error("cannot write " + dir + "/sonar.jsf (disk full?)");
  }
  report.render_wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - render_start).count();
  report.files.push_back("sonar.jsf");

  // Waterfalls: one PNG per survey line, first ping at the top.
  for (int line = 0; line < options.trajectory.lines; ++line) {
    std::vector<float> image;
    int rows = 0;
    for (size_t i = 0; i < pings; ++i) {
      if (ping_line[i] != line) continue;
      image.insert(image.end(), line_rows[i].begin(), line_rows[i].end());
      ++rows;
    }
    if (rows == 0) continue;
    char name[64];
    std::snprintf(name, sizeof name, "waterfall_line_%02d.png", line);
    if (const Status written =
            writePng(dir + "/" + name, toImage8(image, rows, 2 * bins, percentile(image, 0.99)));
        !written) {
      return written;
    }
    report.files.push_back(name);
  }
  // Mosaic, north up, on the seabed raster's extent.
  std::vector<float> mosaic(mosaic_sum.size(), 0.0f);
  for (size_t i = 0; i < mosaic.size(); ++i) {
    if (mosaic_count[i] > 0) mosaic[i] = mosaic_sum[i] / mosaic_count[i];
  }
  if (const Status written =
          writePng(dir + "/mosaic.png", toImage8(mosaic, mosaic_rows, mosaic_cols, percentile(mosaic, 0.99)));
      !written) {
    return written;
  }
  std::ostringstream mosaic_yaml;
  mosaic_yaml.precision(12);
  mosaic_yaml << "# mosaic.png: mean envelope per cell from the true poses (flat seabed at the true altitude).\n"
              << "# Pixel (row, col): north = north_max_m - (row + 0.5) * resolution_m, east = east_min_m + (col + 0.5)"
              << " * resolution_m.\nresolution_m: " << mres << "\nnorth_max_m: " << bed.north_min_m + mosaic_rows * mres
              << "\neast_min_m: " << bed.east_min_m << "\nrows: " << mosaic_rows << "\ncols: " << mosaic_cols << "\n";
  if (const Status written = writeText(dir + "/mosaic.yaml", mosaic_yaml.str()); !written) return written;
  report.files.push_back("mosaic.png");
  report.files.push_back("mosaic.yaml");

  report.total_wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::ostringstream yaml;
  yaml.precision(12);
  yaml << "# sss-sim mission: the `sim` section is the full configuration used (reusable with --config);\n"
       << "# `mission` describes what came out.\nsim:\n";
  std::istringstream sim_yaml(simOptionsYaml(options));
  for (std::string line; std::getline(sim_yaml, line);) yaml << "  " << line << "\n";
  const DeadReckoning& dr = mission.deadReckoning();
  yaml << "mission:\n  pings: " << pings << "\n  duration_s: " << mission.durationS()
       << "\n  start_utime_us: " << options.start_utime_us << "\n  distance_m: " << report.distance_m
       << "\n  sample_interval_s: " << sonar.sampleIntervalS() << "\n  sample_spacing_m: " << spacing
       << "\n  dr_velocity_scale_factor: " << dr.velocityScaleFactor() << "\n  dr_heading_bias_rad: " << dr.headingBiasRad()
       << "\n  dr_heading_deviation_rad: " << dr.headingDeviationRad()
       << "\n  dr_heading_deviation_phase_rad: " << dr.headingDeviationPhaseRad()
       << "\n  dr_final_error_m: " << report.final_dr_error_m << "\n  dr_max_error_m: " << report.max_dr_error_m
       << "\n  frames: local NED at the origin (x north, y east, z down), body FRD, TUM t x y z qx qy qz qw"
       << "\n  ins_protocol: iXblue NMEA 0183 ($HEHDT, $PIXSE ATITUD/POSITI/SPEED_/TIME__/STD*, $SDDPT, $INZDA)"
       << "\n  jsf: type 80 envelope, port (channel 0) then starboard (1) per ping, DR navigation in the headers\n";
  if (const Status written = writeText(dir + "/mission.yaml", yaml.str()); !written) return written;
  report.files.push_back("mission.yaml");
  return Status::success();
}

}  // namespace sss::sim
