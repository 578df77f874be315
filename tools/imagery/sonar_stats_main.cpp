// sss-sonar-stats: the image statistics of a side-scan file (JSF or XTF) that a person compares
// between simulated and real data: speckle, dynamic range, across-track fall-off, water column,
// nadir. Prints a few lines; --json FILE writes them as JSON.
#include "drivers/edgetech/sonar_driver.hpp"
#include "drivers/xtf/xtf_reader.hpp"
#include "pipeline/transport/command_line.hpp"
#include "tools/imagery/sonar_statistics.hpp"

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

namespace {

const char* kExplanation =
    "Image statistics of the raw envelope samples: speckle (median std/mean of homogeneous far-range\n"
    "blocks), dynamic range, across-track fall-off, water column and nadir re the seabed mean.\n"
    "--subsystem: JSF side-scan subsystem (20 low, 21 high; default 20); --pair: XTF channel pair\n"
    "(0 = lowest frequency). --waterfall: the raw slant-range waterfall (port mirrored left, first ping\n"
    "at the top, samples averaged to at most 1000 columns per side, white at the 99th percentile).\n"
    "Exit 2 on bad arguments or an unreadable file, 1 when it holds no ping.\n";

bool endsWith(const std::string& text, const std::string& suffix) {
  if (text.size() < suffix.size()) return false;
  std::string tail = text.substr(text.size() - suffix.size());
  for (char& c : tail) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return tail == suffix;
}

// Samples from slant range 0: a recording window that starts later is padded with zeros.
std::vector<float> fromRangeZero(const sss::sonar::SonarChannelRecord& side) {
  std::vector<float> samples(side.start_depth_samples, 0.0f);
  samples.insert(samples.end(), side.samples.begin(), side.samples.end());
  return samples;
}

sss::imagery::StatisticsPing toStatisticsPing(const sss::sonar::AssembledPing& ping) {
  sss::imagery::StatisticsPing out;
  const sss::sonar::SonarChannelRecord& any = ping.port ? *ping.port : *ping.starboard;
  if (ping.port) out.port = fromRangeZero(*ping.port);
  if (ping.starboard) out.starboard = fromRangeZero(*ping.starboard);
  out.sample_spacing_m = any.slantRangeM(1) - any.slantRangeM(0);
  if ((any.validity & sss::sonar::kValidAltitude) && any.altitude_m > 0.0) out.altitude_m = any.altitude_m;
  return out;
}

// The raw waterfall as a person first looks at a file: slant range, both sides, no correction.
bool writeWaterfall(const std::vector<sss::imagery::StatisticsPing>& pings, const std::string& path) {
  size_t samples = 0;
  for (const auto& ping : pings) samples = std::max({samples, ping.port.size(), ping.starboard.size()});
  const size_t bins = std::min<size_t>(1000, samples);
  if (bins == 0) return false;
  cv::Mat image(static_cast<int>(pings.size()), static_cast<int>(2 * bins), CV_32FC1, cv::Scalar(0.0f));
  for (size_t row = 0; row < pings.size(); ++row) {
    for (int side = 0; side < 2; ++side) {
      const std::vector<float>& values = side == 0 ? pings[row].port : pings[row].starboard;
      for (size_t j = 0; j < bins; ++j) {
        const size_t s0 = j * samples / bins, s1 = std::max(s0 + 1, (j + 1) * samples / bins);
        double sum = 0.0;
        size_t n = 0;
        for (size_t s = s0; s < s1 && s < values.size(); ++s) sum += values[s], ++n;
        const size_t column = side == 0 ? bins - 1 - j : bins + j;
        image.at<float>(static_cast<int>(row), static_cast<int>(column)) = n ? static_cast<float>(sum / n) : 0.0f;
      }
    }
  }
  std::vector<float> sorted(image.begin<float>(), image.end<float>());
  const size_t k = sorted.size() * 99 / 100;
  std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(k), sorted.end());
  const double white = std::max(1e-6f, sorted[k]);
  cv::Mat out;
  image.convertTo(out, CV_8UC1, 255.0 / white);
  try {
    return cv::imwrite(path, out);
  } catch (const cv::Exception&) {
    return false;
  }
}

}  // namespace

int main(int argc, char** argv) {
  std::string sonar_path, json_path, waterfall_path;
  int subsystem = sss::sonar::kSubsystemSideScanLow, pair = 0;
  long max_pings = 0;
  sss::imagery::SonarStatisticsOptions stats_options;
  std::vector<int> block;
  sss::cli::CommandLine command_line("sss-sonar-stats",
                                     "the image statistics of a side-scan file (JSF or XTF) that a person compares "
                                     "between simulated and real data",
                                     kExplanation);
  command_line.add_option("--sonar", sonar_path, "FILE.jsf or FILE.xtf")->required();
  command_line.add_option("--json", json_path, "write the statistics as JSON");
  command_line.add_option("--waterfall", waterfall_path, "write the raw slant-range waterfall (PNG)");
  CLI::Option* subsystem_option = command_line.add_option("--subsystem", subsystem, "JSF side-scan subsystem")
                                      ->check(CLI::Range(0, 255))
                                      ->capture_default_str();
  command_line.add_option("--pair", pair, "XTF channel pair")->check(sss::cli::nonNegative())->capture_default_str();
  command_line.add_option("--max-pings", max_pings, "read at most this many pings (0: all)")
      ->check(sss::cli::nonNegative());
  command_line.add_option("--block", block, "PINGS,SAMPLES of a speckle block (each >= 2)")
      ->delimiter(',')
      ->expected(2)
      ->check(CLI::Range(2, 1 << 20));
  sss::cli::addIncreasingPair(command_line, "--far-range", stats_options.far_range_min_fraction,
                              stats_options.far_range_max_fraction,
                              "MIN,MAX fractions of the range for the far-range statistics", CLI::Range(0.0, 1.0));
  command_line.add_option("--max-quarter-deviation", stats_options.max_quarter_deviation,
                          "largest deviation between a block's quarters for it to count as homogeneous")
      ->check(sss::cli::positive())
      ->capture_default_str();
  if (const int code = sss::cli::parseCommandLine(command_line, argc, argv); code >= 0) return code;
  if (!block.empty()) stats_options.block_pings = block[0], stats_options.block_samples = block[1];

  std::vector<sss::imagery::StatisticsPing> pings;
  std::string file_facts;  // what the reader found in the file (formats, laybacks, older messages)
  const auto full = [&] { return max_pings > 0 && pings.size() >= static_cast<size_t>(max_pings); };
  if (endsWith(sonar_path, ".xtf")) {
    sss::xtf::XtfReaderOptions options;
    options.pair_index = static_cast<int>(pair);
    sss::xtf::XtfReader reader(sonar_path, options);
    if (!reader.isOpen()) {
      std::cerr << "sss-sonar-stats: " << reader.error() << "\n";
      return 2;
    }
    sss::sonar::DriverPing ping;
    while (!full() && reader.next(ping)) pings.push_back(toStatisticsPing(ping.ping));
    for (const std::string& fault : reader.takeNewFaultMessages()) std::cerr << "sss-sonar-stats: " << fault << "\n";
    file_facts = reader.summary();
  } else {
    std::ifstream file(sonar_path, std::ios::binary);
    if (!file) {
      std::cerr << "sss-sonar-stats: cannot open " << sonar_path << "\n";
      return 2;
    }
    sss::edgetech::SonarDriverOptions options;
    options.assembler.subsystem = static_cast<uint8_t>(subsystem);
    // Asked for by name: that subsystem or nothing. Left at the default: a file of another
    // side-scan frequency only is read as it is (PingAssemblerOptions::adopt_other_side_scan_after).
    if (subsystem_option->count() > 0) options.assembler.adopt_other_side_scan_after = 0;
    options.time_source = sss::edgetech::TimeSource::kSonarClock;
    sss::edgetech::SonarDriver driver(options);
    std::vector<char> chunk(1 << 20);
    std::vector<sss::sonar::DriverPing> out;
    while (!full() && file) {
      file.read(chunk.data(), static_cast<std::streamsize>(chunk.size()));
      const std::streamsize n = file.gcount();
      out.clear();
      if (n > 0) driver.onBytes(reinterpret_cast<const uint8_t*>(chunk.data()), static_cast<size_t>(n), 0, 0, out);
      if (!file) driver.finish(0, 0, out);
      for (const auto& ping : out) {
        if (!full()) pings.push_back(toStatisticsPing(ping.ping));
      }
    }
    for (const std::string& fault : driver.takeNewFaultMessages()) std::cerr << "sss-sonar-stats: " << fault << "\n";
    char layback[64];
    std::snprintf(layback, sizeof layback, "%.1f m", driver.maxLaybackM());
    file_facts = "JSF: side-scan records of the older message 82: " + std::to_string(driver.oldSideScanMessages()) +
                 "; records with a towfish layback: " + std::to_string(driver.recordsWithLayback()) +
                 (driver.recordsWithLayback() > 0 ? " (up to " + std::string(layback) + ")" : std::string()) +
                 "; other messages: " + std::to_string(driver.otherMessages());
  }
  if (pings.empty()) {
    std::cerr << "sss-sonar-stats: " << sonar_path << " holds no side-scan ping"
              << (endsWith(sonar_path, ".xtf") ? " (try another --pair)\n" : " of subsystem " + std::to_string(subsystem) +
                                                                                   " (try --subsystem 21)\n");
    return 1;
  }
  const sss::imagery::SonarStatistics stats = sss::imagery::computeSonarStatistics(pings, stats_options);
  std::cout << sonar_path << ":\n" << file_facts << "\n" << sss::imagery::statisticsText(stats);
  if (!waterfall_path.empty() && !writeWaterfall(pings, waterfall_path)) {
    std::cerr << "sss-sonar-stats: cannot write " << waterfall_path << "\n";
    return 2;
  }
  if (!json_path.empty()) {
    std::ofstream json(json_path);
    json << sss::imagery::statisticsJson(stats) << "\n";
    if (!json) {
      std::cerr << "sss-sonar-stats: cannot write " << json_path << "\n";
      return 2;
    }
  }
  return 0;
}
