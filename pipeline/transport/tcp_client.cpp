// Non-blocking TCP client with reconnect, see tcp_client.hpp.
#include "pipeline/transport/tcp_client.hpp"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <vector>

namespace sss::transport {

TcpClient::TcpClient(TcpClientOptions options, DataHandler on_data, StateHandler on_state)
    : options_(std::move(options)), on_data_(std::move(on_data)), on_state_(std::move(on_state)) {
  backoff_s_ = options_.reconnect_min_s;
}

TcpClient::~TcpClient() {
  if (fd_ >= 0) ::close(fd_);
}

void TcpClient::setState(LinkState state, const std::string& reason) {
  state_ = state;
  if (on_state_) on_state_(state, reason);
}

void TcpClient::startConnect(int64_t now_us) {
  addrinfo hints{};
  hints.ai_family = AF_INET;
  hints.ai_socktype = SOCK_STREAM;
  addrinfo* result = nullptr;
  // getaddrinfo on a numeric address or /etc/hosts name does not block on the network.
  const int rc = ::getaddrinfo(options_.host.c_str(), std::to_string(options_.port).c_str(), &hints, &result);
  if (rc != 0 || result == nullptr) {
    next_attempt_us_ = now_us + static_cast<int64_t>(backoff_s_ * 1e6);
    backoff_s_ = std::min(options_.reconnect_max_s, backoff_s_ * 2.0);
    setState(LinkState::kDisconnected, "cannot resolve '" + options_.host + "': " + ::gai_strerror(rc));
    return;
  }
  fd_ = ::socket(AF_INET, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  const int one = 1;
  ::setsockopt(fd_, SOL_SOCKET, SO_KEEPALIVE, &one, sizeof(one));
  ::setsockopt(fd_, IPPROTO_TCP, TCP_KEEPIDLE, &options_.keepalive_idle_s, sizeof(options_.keepalive_idle_s));
  const int interval_s = 1, count = 3;
  ::setsockopt(fd_, IPPROTO_TCP, TCP_KEEPINTVL, &interval_s, sizeof(interval_s));
  ::setsockopt(fd_, IPPROTO_TCP, TCP_KEEPCNT, &count, sizeof(count));
  const int connected = ::connect(fd_, result->ai_addr, result->ai_addrlen);
  ::freeaddrinfo(result);
  connect_started_us_ = now_us;
  if (connected == 0 || errno == EINPROGRESS) {
    setState(LinkState::kConnecting, "connecting to " + options_.host + ":" + std::to_string(options_.port));
    service(now_us);  // a loopback connect often completes at once
    return;
  }
  disconnect(now_us, std::string("connect failed: ") + std::strerror(errno));
}

void TcpClient::disconnect(int64_t now_us, const std::string& reason) {
  const bool was_connected = state_ == LinkState::kConnected;
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
  if (was_connected) ++disconnects_;
  next_attempt_us_ = now_us + static_cast<int64_t>(backoff_s_ * 1e6);
  backoff_s_ = std::min(options_.reconnect_max_s, backoff_s_ * 2.0);
  setState(LinkState::kDisconnected, reason);
}

void TcpClient::service(int64_t now_us) {
  switch (state_) {
    case LinkState::kDisconnected:
      if (now_us >= next_attempt_us_) startConnect(now_us);
      break;
    case LinkState::kConnecting: {
      pollfd p{fd_, POLLOUT, 0};
      if (::poll(&p, 1, 0) > 0) {
        int error = 0;
        socklen_t length = sizeof(error);
        ::getsockopt(fd_, SOL_SOCKET, SO_ERROR, &error, &length);
        if (error != 0) {
          disconnect(now_us, std::string("connect to ") + options_.host + ":" + std::to_string(options_.port) +
                                 " failed: " + std::strerror(error));
          return;
        }
        ++connects_;
        backoff_s_ = options_.reconnect_min_s;
        last_data_us_ = now_us;
        setState(LinkState::kConnected, "connected to " + options_.host + ":" + std::to_string(options_.port));
      } else if (now_us - connect_started_us_ > static_cast<int64_t>(options_.connect_timeout_s * 1e6)) {
        disconnect(now_us, "connect timed out");
      }
      break;
    }
    case LinkState::kConnected:
      if (options_.silence_timeout_s > 0 &&
          now_us - last_data_us_ > static_cast<int64_t>(options_.silence_timeout_s * 1e6)) {
        disconnect(now_us, "no data for " + std::to_string(options_.silence_timeout_s) + " s; reconnecting");
      }
      break;
  }
}

void TcpClient::onReadable(int64_t now_us) {
  if (state_ != LinkState::kConnected) return;
  uint8_t buffer[65536];
  for (;;) {
    const ssize_t n = ::recv(fd_, buffer, sizeof(buffer), 0);
    if (n > 0) {
      bytes_received_ += static_cast<uint64_t>(n);
      last_data_us_ = now_us;
      on_data_(buffer, static_cast<size_t>(n));
      continue;
    }
    if (n == 0) {
      disconnect(now_us, "peer closed the connection");
    } else if (errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR) {
      disconnect(now_us, std::string("receive failed: ") + std::strerror(errno));
    }
    return;
  }
}

}  // namespace sss::transport
