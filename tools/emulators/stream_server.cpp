// Paced stream serving with fault injection, see stream_server.hpp.
#include "tools/emulators/stream_server.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <random>
#include <thread>

#include "pipeline/core/time.hpp"

namespace sss::emulators {

namespace {

bool sendAll(int fd, const uint8_t* data, size_t size) {
  while (size > 0) {
    const ssize_t n = ::send(fd, data, size, MSG_NOSIGNAL);
    if (n < 0) {
      if (errno == EINTR) continue;
      return false;
    }
    data += n;
    size -= static_cast<size_t>(n);
  }
  return true;
}

bool every(int k, size_t index) { return k > 0 && (index + 1) % static_cast<size_t>(k) == 0; }

// Sleeps until the chunk's paced due time; returns false if stop was requested meanwhile.
class Pacer {
 public:
  Pacer(double speed, int64_t first_time_us) : speed_(speed), first_time_us_(first_time_us) {}
  bool waitFor(int64_t chunk_time_us, const std::atomic<bool>& stop) {
    if (speed_ <= 0.0) return !stop;
    if (start_us_ < 0) start_us_ = sss::core::monotonicUtime();
    const int64_t due = dueUs(chunk_time_us);
    for (;;) {
      if (stop) return false;
      const int64_t wait = due - sss::core::monotonicUtime();
      if (wait <= 0) return true;
      std::this_thread::sleep_for(std::chrono::microseconds(std::min<int64_t>(wait, 50'000)));
    }
  }
  // A stall shifts the whole schedule, like a sensor that stops and then carries on where it
  // was; an outage keeps it, like a sensor that goes silent and comes back with live data.
  void pause(double seconds, bool shift, const std::atomic<bool>& stop) {
    const int64_t end = sss::core::monotonicUtime() + static_cast<int64_t>(seconds * 1e6);
    while (!stop && sss::core::monotonicUtime() < end) std::this_thread::sleep_for(std::chrono::milliseconds(10));
    if (shift && start_us_ >= 0) start_us_ += static_cast<int64_t>(seconds * 1e6);
  }
  // The chunk fell due before now (after an outage).
  bool overdue(int64_t chunk_time_us) const {
    return speed_ > 0.0 && start_us_ >= 0 && dueUs(chunk_time_us) < sss::core::monotonicUtime();
  }

 private:
  int64_t dueUs(int64_t chunk_time_us) const {
    return start_us_ + static_cast<int64_t>(static_cast<double>(chunk_time_us - first_time_us_) / speed_);
  }

  double speed_;
  int64_t first_time_us_;
  int64_t start_us_ = -1;
};

// The bytes to send for chunk index i under the fault plan: garbage first, then the chunk
// (flipped or truncated). Returns whether the chunk itself was damaged.
bool faultedBytes(const FaultPlan& plan, size_t index, const std::vector<uint8_t>& chunk, std::mt19937& rng,
                  std::vector<uint8_t>& out, StreamStats& stats) {
  out.clear();
  if (every(plan.corrupt_every, index)) {
    for (int i = 0; i < plan.garbage_bytes; ++i) out.push_back(static_cast<uint8_t>(rng()));
    ++stats.garbage_runs;
  }
  const size_t begin = out.size();
  out.insert(out.end(), chunk.begin(), chunk.end());
  bool damaged = false;
  if (every(plan.flip_every, index) && !chunk.empty()) {
    // Not the first bytes: those would make it garbage (start marker), not a damaged message.
    const size_t at = begin + chunk.size() / 2 + rng() % std::max<size_t>(1, chunk.size() / 2);
    out[std::min(at, out.size() - 1)] ^= 0x5A;
    damaged = true;
  }
  if (every(plan.truncate_every, index)) {
    out.resize(begin + chunk.size() / 2);
    damaged = true;
  }
  return damaged;
}

}  // namespace

TcpStreamServer::TcpStreamServer(StreamServerOptions options, std::vector<TimedChunk> chunks)
    : options_(std::move(options)), chunks_(std::move(chunks)) {}

TcpStreamServer::~TcpStreamServer() {
  if (listen_fd_ >= 0) ::close(listen_fd_);
}

sss::core::Status TcpStreamServer::listen() {
  listen_fd_ = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  const int one = 1;
  ::setsockopt(listen_fd_, SOL_SOCKET, SO_REUSEADDR, &one, sizeof(one));
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(static_cast<uint16_t>(options_.port));
  if (::inet_pton(AF_INET, options_.bind_address.c_str(), &address.sin_addr) != 1) {
    return sss::core::Status::error("bad bind address '" + options_.bind_address + "'");
  }
  if (::bind(listen_fd_, reinterpret_cast<sockaddr*>(&address), sizeof(address)) != 0 || ::listen(listen_fd_, 4) != 0) {
    return sss::core::Status::error("cannot listen on " + options_.bind_address + ":" + std::to_string(options_.port) +
                                    ": " + std::strerror(errno));
  }
  socklen_t length = sizeof(address);
  ::getsockname(listen_fd_, reinterpret_cast<sockaddr*>(&address), &length);
  port_ = ntohs(address.sin_port);
  return sss::core::Status::success();
}

int TcpStreamServer::acceptClient(const std::atomic<bool>& stop) {
  while (!stop) {
    pollfd p{listen_fd_, POLLIN, 0};
    if (::poll(&p, 1, 100) > 0) {
      const int fd = ::accept4(listen_fd_, nullptr, nullptr, SOCK_CLOEXEC);
      if (fd >= 0) {
        ++stats_.connections;
        return fd;
      }
    }
  }
  return -1;
}

void TcpStreamServer::run(const std::atomic<bool>& stop) {
  if (chunks_.empty()) return;
  std::mt19937 rng(options_.faults.seed);
  Pacer pacer(options_.speed, options_.pacing_origin_us.value_or(chunks_.front().time_us));
  std::vector<uint8_t> bytes;
  int client = acceptClient(stop);
  for (size_t i = 0; i < chunks_.size() && client >= 0; ++i) {
    if (!pacer.waitFor(chunks_[i].time_us, stop)) break;
    const bool damaged = faultedBytes(options_.faults, i, chunks_[i].bytes, rng, bytes, stats_);
    if (!sendAll(client, bytes.data(), bytes.size())) {
      // The client went away: this chunk is lost with the connection, as on a real link.
      ::close(client);
      client = acceptClient(stop);
      continue;
    }
    damaged ? ++stats_.chunks_faulted : ++stats_.chunks_sent;
    if (on_chunk_sent_) on_chunk_sent_(i, sss::core::monotonicUtime());
    if (every(options_.faults.pause_every, i)) {
      ++stats_.pauses;
      pacer.pause(options_.faults.pause_s, !options_.faults.pause_skips, stop);
      while (options_.faults.pause_skips && i + 1 < chunks_.size() && pacer.overdue(chunks_[i + 1].time_us)) {
        ++i;
        ++stats_.chunks_skipped;
      }
    }
    if (every(options_.faults.drop_connection_every, i) && i + 1 < chunks_.size()) {
      ++stats_.drops;
      ::close(client);
      client = acceptClient(stop);
    }
  }
  if (client >= 0) ::close(client);
}

UdpStreamSender::UdpStreamSender(StreamServerOptions options, std::vector<TimedChunk> chunks)
    : options_(std::move(options)), chunks_(std::move(chunks)) {}

sss::core::Status UdpStreamSender::run(const std::atomic<bool>& stop) {
  const int fd = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(static_cast<uint16_t>(options_.port));
  if (::inet_pton(AF_INET, options_.bind_address.c_str(), &address.sin_addr) != 1) {
    ::close(fd);
    return sss::core::Status::error("bad destination address '" + options_.bind_address + "'");
  }
  if (chunks_.empty()) {
    ::close(fd);
    return sss::core::Status::success();
  }
  std::mt19937 rng(options_.faults.seed);
  Pacer pacer(options_.speed, options_.pacing_origin_us.value_or(chunks_.front().time_us));
  std::vector<uint8_t> bytes;
  for (size_t i = 0; i < chunks_.size(); ++i) {
    if (!pacer.waitFor(chunks_[i].time_us, stop)) break;
    const bool damaged = faultedBytes(options_.faults, i, chunks_[i].bytes, rng, bytes, stats_);
    ::sendto(fd, bytes.data(), bytes.size(), 0, reinterpret_cast<sockaddr*>(&address), sizeof(address));
    damaged ? ++stats_.chunks_faulted : ++stats_.chunks_sent;
    if (every(options_.faults.pause_every, i)) {
      ++stats_.pauses;
      pacer.pause(options_.faults.pause_s, !options_.faults.pause_skips, stop);
      while (options_.faults.pause_skips && i + 1 < chunks_.size() && pacer.overdue(chunks_[i + 1].time_us)) {
        ++i;
        ++stats_.chunks_skipped;
      }
    }
    // As fast as possible over UDP would overrun any receiver: yield a little every datagram.
    if (options_.speed <= 0.0) std::this_thread::sleep_for(std::chrono::microseconds(50));
  }
  ::close(fd);
  return sss::core::Status::success();
}

}  // namespace sss::emulators
