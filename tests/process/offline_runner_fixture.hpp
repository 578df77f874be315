// The fixture of sss-process's runner tests: a short simulated survey (3 lines of 200 m, 50 m
// apart, drifting DR) made once per test binary, requests on it, and the ATE of an output against
// its truth; helpers that build synthetic XTF pings.
#pragma once

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
inline void addSeabedChannels(sss::xtf::XtfPingInput& ping, int samples, double spacing_m, double altitude_m,
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

inline std::string readFile(const std::string& path) {
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
  static void TearDownTestSuite() { if (!std::getenv("SSS_KEEP_TEST_DIR")) fs::remove_all(root_); }

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

  static inline std::string root_;
};
}  // namespace
