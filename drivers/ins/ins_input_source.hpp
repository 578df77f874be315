// Where sss-ins-bridge reads its bytes: a UDP port, a TCP link (reconnected with backoff), a serial
// line (reopened when it vanishes) or a recorded file. No middleware and no logging: the bytes and
// what happened to the link come back through hooks, for the process to parse and to log.
#pragma once

#include <cstddef>
#include <cstdint>
#include <fstream>
#include <functional>
#include <memory>
#include <string>

#include "pipeline/core/status.hpp"
#include "pipeline/transport/tcp_client.hpp"

namespace sss::ins {

struct InsInputOptions {
  std::string source = "udp";  // udp | tcp | serial | file
  std::string bind_address = "0.0.0.0";
  int udp_port = 8110;  // 0: a free port the system chooses (boundUdpPort())
  sss::transport::TcpClientOptions tcp;
  std::string serial_device = "/dev/ttyS0";
  int serial_baud = 115200;  // 9600, 19200, 38400, 57600, 115200, 230400 or 460800; others read at 115200
  std::string file;
  // A serial port can vanish (USB adapter): tried again this often until it is back.
  double serial_reopen_period_s = 2.0;
  // How often the TCP link is driven: connect attempts, pending connects, the silence timeout.
  double tcp_service_period_s = 0.05;
};

// A piece of the byte stream, as it arrived.
struct InsInputChunk {
  const uint8_t* data = nullptr;
  size_t size = 0;
  int64_t arrival_us = 0;  // monotonic clock
  // No sentence continues past these bytes: a UDP datagram ends here, or the TCP link dropped
  // (then without bytes).
  bool stream_break = false;
  // The file has nothing after these bytes.
  bool end_of_file = false;
};

struct InsInputHooks {
  std::function<void(const InsInputChunk& chunk)> chunk;
  // Lines for the process's log.
  std::function<void(const std::string& line)> info;
  std::function<void(const std::string& line)> warning;
  // The serial port could not be opened (tried again every serial_reopen_period_s): the process
  // counts it in its health and says it once.
  std::function<void(const std::string& error)> open_failed;
};

struct InsInputCounters {
  uint64_t bytes = 0;
  uint64_t opens = 0;   // the UDP port bound, the file or the serial port opened, the TCP link connected
  uint64_t losses = 0;  // the serial port closed, the TCP link dropped
};

class InsInputSource {
 public:
  // Throws std::invalid_argument for a source other than udp, tcp, serial or file (the
  // configuration is validated before).
  InsInputSource(InsInputOptions options, InsInputHooks hooks);
  ~InsInputSource();
  InsInputSource(const InsInputSource&) = delete;
  InsInputSource& operator=(const InsInputSource&) = delete;

  // UDP and file: fails with what and where when they cannot be opened (the process cannot run
  // without them). Serial: always succeeds (a missing port goes to hooks.open_failed and is tried
  // again by service()). TCP: always succeeds (the link connects in service()).
  sss::core::Status open();
  // The descriptor to watch for readability; -1 when there is none now (no serial port, TCP link
  // down, file). It changes as a serial port comes back or the TCP link reconnects.
  int fd() const;
  // How often service() wants to run; 0: never (UDP, file).
  double servicePeriodS() const;
  // Serial: reopens a port that closed. TCP: connects, times out, reconnects. now_us: monotonic.
  void service(int64_t now_us);
  // Waits up to timeout_s for bytes (0: not at all), then reads what is there and hands it to
  // hooks.chunk: UDP every waiting datagram, serial one read of up to 4 KiB, TCP all there is, file
  // the next 16 KiB. Serial: a port that reads end-of-file or fails is closed. Returns the bytes read.
  size_t read(double timeout_s);

  bool atEnd() const { return at_end_; }  // the file's last chunk was handed over
  int boundUdpPort() const;               // 0 when no UDP port is bound
  const InsInputCounters& counters() const { return counters_; }

 private:
  enum class Kind { kUdp, kTcp, kSerial, kFile };

  void openSerial();
  size_t readUdp();
  size_t readSerial();
  size_t readFile();
  void deliver(const uint8_t* data, size_t size, bool stream_break, bool end_of_file);
  void say(const std::function<void(const std::string&)>& hook, const std::string& line) const;

  Kind kind_ = Kind::kUdp;
  InsInputOptions options_;
  InsInputHooks hooks_;
  int fd_ = -1;  // the UDP socket or the serial port
  std::unique_ptr<sss::transport::TcpClient> tcp_;
  bool tcp_connected_ = false;
  std::ifstream file_;
  bool at_end_ = false;
  InsInputCounters counters_;
};

}  // namespace sss::ins
