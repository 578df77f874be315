// Where sss-sonar-driver gets its pings: the sonar processor's TCP data port (reconnected with
// backoff) through SonarDriver, or a .jsf or .xtf file replayed at its recorded pace. No middleware
// and no logging: pings and log lines go out through hooks; the link and the counters to the health.
#pragma once

#include <cstddef>
#include <cstdint>
#include <deque>
#include <fstream>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "drivers/edgetech/sonar_driver.hpp"
#include "drivers/xtf/xtf_reader.hpp"
#include "pipeline/core/health.hpp"
#include "pipeline/core/status.hpp"
#include "pipeline/transport/replay_pacer.hpp"
#include "pipeline/transport/tcp_client.hpp"

namespace sss::edgetech {

struct SonarInputOptions {
  SonarDriverOptions driver;  // a replay always uses the sonar's clock (nothing to compare it with)
  sss::transport::TcpClientOptions tcp;
  std::string replay_file;    // non-empty: read this .jsf or .xtf file instead of TCP
  double replay_speed = 1.0;  // 0: as fast as possible
  int xtf_pair_index = 0;     // XTF with several side-scan pairs: 0 = lowest frequency
  int xtf_nav_units = -1;     // XTF NavUnits forced (0 metres, 3 lat/lon); -1: as the file says
  // A replay decodes this many pings ahead of its pace and hands over at most replay_pings_per_step
  // per step(), so that the process stays responsive to signals and its status.
  size_t replay_read_ahead_pings = 64;
  int replay_pings_per_step = 200;
  double replay_step_period_s = 0.002;
  // How often the TCP link is driven: connect attempts, the silence timeout, lone sides expired.
  double link_step_period_s = 0.05;
};

struct SonarInputHooks {
  std::function<void(const DriverPing& ping)> ping;
  // Lines for the process's log.
  std::function<void(const std::string& line)> info;
  std::function<void(const std::string& line)> warning;
  // Faults of the input, each kind once (the process counts them and logs them).
  std::function<void(const std::vector<std::string>& faults)> faults;
};

// True when path ends in .xtf (any case): replayed by XtfReader, else as JSF.
bool isXtfPath(const std::string& path);

class SonarInputSource {
 public:
  // health receives the link's state and the counters; it must outlive this object.
  SonarInputSource(SonarInputOptions options, sss::core::HealthMonitor& health, SonarInputHooks hooks);
  SonarInputSource(const SonarInputSource&) = delete;
  SonarInputSource& operator=(const SonarInputSource&) = delete;

  // Replay: fails with what failed when the file cannot be opened (the process cannot run without
  // it); an XTF file's summary goes to hooks.info. TCP: always succeeds (the link connects in step()).
  sss::core::Status open();
  // The socket to watch for readability (then call onReadable()): the TCP link while it is up,
  // else -1. It changes as the link reconnects.
  int fd() const;
  // How often step() wants to run.
  double stepPeriodS() const;
  // Replay: decodes ahead and hands over the pings that are due; at the end of the file, the last
  // lines to hooks.info. TCP: drives the link and hands over pings whose other side never came.
  void step();
  // TCP: reads what the link has and hands over the pings it completes.
  void onReadable();
  // The driver's counters to the health and its new faults to hooks.faults: every second, and by
  // step() at the end of a JSF replay.
  void updateStatus();

  bool done() const;  // a replay handed over its last ping
  const SonarDriver& driver() const { return driver_; }

 private:
  enum class Kind { kTcp, kJsfFile, kXtfFile };

  void stepJsf();
  void stepXtf();
  void stepLink();
  void onLinkState(sss::transport::LinkState state, const std::string& reason);
  // Hands over the queued pings that are due, at most replay_pings_per_step; returns how many.
  size_t publishDue();
  void deliverAll(const std::vector<DriverPing>& pings);
  void say(const std::function<void(const std::string&)>& hook, const std::string& line) const;
  void reportFaults(const std::vector<std::string>& faults) const;

  Kind kind_ = Kind::kTcp;
  SonarInputOptions options_;
  sss::core::HealthMonitor& health_;
  SonarInputHooks hooks_;
  SonarDriver driver_;
  std::vector<DriverPing> pings_;  // reused between calls
  std::unique_ptr<sss::transport::TcpClient> tcp_;
  std::ifstream jsf_file_;
  std::vector<char> jsf_chunk_;  // the replay's read buffer (64 KiB once the file is open)
  std::unique_ptr<sss::xtf::XtfReader> xtf_reader_;
  sss::transport::ReplayPacer pacer_;
  std::deque<DriverPing> queue_;  // decoded, waiting for their time
  bool end_of_file_ = false;
  bool end_reported_ = false;
  uint64_t xtf_pings_published_ = 0;
};

}  // namespace sss::edgetech
