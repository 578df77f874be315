// A non-blocking TCP client for sensor links (sonar data port, INS): connects, reconnects with
// exponential backoff, enables keep-alive, declares a link dead after a silence timeout, and
// hands every received chunk to a callback. Driven by ProcessLoop (fd + a timer): never blocks.
#pragma once

#include <cstdint>
#include <functional>
#include <string>

namespace sss::transport {

struct TcpClientOptions {
  std::string host = "127.0.0.1";
  int port = 1701;
  double reconnect_min_s = 0.2;   // first retry delay, doubled per failure up to the max
  double reconnect_max_s = 5.0;
  double connect_timeout_s = 3.0;
  double silence_timeout_s = 10.0;  // no byte for this long: reconnect (0 = never)
  int keepalive_idle_s = 5;
};

enum class LinkState { kDisconnected, kConnecting, kConnected };

class TcpClient {
 public:
  using DataHandler = std::function<void(const uint8_t* data, size_t size)>;
  // Called on every state change with a reason ("connected", "connection refused", ...).
  using StateHandler = std::function<void(LinkState state, const std::string& reason)>;

  TcpClient(TcpClientOptions options, DataHandler on_data, StateHandler on_state);
  ~TcpClient();
  TcpClient(const TcpClient&) = delete;
  TcpClient& operator=(const TcpClient&) = delete;

  // Call often (e.g. every 50 ms): starts connection attempts when due, completes pending
  // connects, enforces the silence timeout. now_us: monotonic.
  void service(int64_t now_us);
  // Call when fd() is readable: reads everything available.
  void onReadable(int64_t now_us);

  // The socket while connected (for poll), else -1.
  int fd() const { return state_ == LinkState::kConnected ? fd_ : -1; }
  LinkState state() const { return state_; }
  uint64_t connects() const { return connects_; }
  uint64_t disconnects() const { return disconnects_; }
  uint64_t bytesReceived() const { return bytes_received_; }

 private:
  void startConnect(int64_t now_us);
  void disconnect(int64_t now_us, const std::string& reason);
  void setState(LinkState state, const std::string& reason);

  TcpClientOptions options_;
  DataHandler on_data_;
  StateHandler on_state_;
  int fd_ = -1;
  LinkState state_ = LinkState::kDisconnected;
  int64_t next_attempt_us_ = 0;
  int64_t connect_started_us_ = 0;
  int64_t last_data_us_ = 0;
  double backoff_s_ = 0.0;
  uint64_t connects_ = 0;
  uint64_t disconnects_ = 0;
  uint64_t bytes_received_ = 0;
};

}  // namespace sss::transport
