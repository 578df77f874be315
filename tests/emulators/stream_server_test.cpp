// The emulators deliver every message, in order, byte for byte, at the requested pace, over TCP
// and UDP; a client that disconnects and comes back gets the rest; a pause is a stall (sent late)
// or an outage (never sent).
#include "tools/emulators/stream_server.hpp"

#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <thread>
#include <vector>

#include "pipeline/core/time.hpp"
#include "tests/support/status_assertions.hpp"

namespace sss::emulators {
namespace {

std::vector<TimedChunk> makeChunks(int count, int64_t period_us) {
  std::vector<TimedChunk> chunks;
  for (int i = 0; i < count; ++i) {
    TimedChunk chunk;
    chunk.time_us = 1'780'000'000'000'000 + i * period_us;
    chunk.bytes.assign(100 + i, static_cast<uint8_t>(i));
    chunks.push_back(chunk);
  }
  return chunks;
}

int connectTo(int port) {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(static_cast<uint16_t>(port));
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (::connect(fd, reinterpret_cast<sockaddr*>(&address), sizeof(address)) != 0) {
    ::close(fd);
    return -1;
  }
  return fd;
}

// Reads until `expected` bytes arrived, recording when each chunk boundary was passed.
std::vector<uint8_t> readAll(int fd, size_t expected, const std::vector<TimedChunk>& chunks, std::vector<int64_t>& arrivals) {
  std::vector<uint8_t> received;
  size_t next_boundary = chunks[0].bytes.size();
  size_t chunk_index = 0;
  uint8_t buffer[4096];
  const int64_t deadline = sss::core::monotonicUtime() + 10'000'000;
  while (received.size() < expected && sss::core::monotonicUtime() < deadline) {
    pollfd p{fd, POLLIN, 0};
    if (::poll(&p, 1, 100) <= 0) continue;
    const ssize_t n = ::recv(fd, buffer, sizeof(buffer), 0);
    if (n <= 0) break;
    received.insert(received.end(), buffer, buffer + n);
    while (chunk_index < chunks.size() && received.size() >= next_boundary) {
      arrivals.push_back(sss::core::monotonicUtime());
      if (++chunk_index < chunks.size()) next_boundary += chunks[chunk_index].bytes.size();
    }
  }
  return received;
}

TEST(TcpStreamServer, DeliversEveryChunkInOrderAtTheRequestedPace) {
  const std::vector<TimedChunk> chunks = makeChunks(21, 100'000);  // 2 s of data at 10 Hz
  StreamServerOptions options;
  options.port = 0;
  options.speed = 2.0;  // 2 s in 1 s: one chunk every 50 ms
  TcpStreamServer server(options, chunks);
  ASSERT_OK(server.listen());
  std::atomic<bool> stop{false};
  std::thread thread([&] { server.run(stop); });
  const int fd = connectTo(server.port());
  ASSERT_GE(fd, 0);
  std::vector<uint8_t> expected;
  for (const auto& c : chunks) expected.insert(expected.end(), c.bytes.begin(), c.bytes.end());
  std::vector<int64_t> arrivals;
  const std::vector<uint8_t> received = readAll(fd, expected.size(), chunks, arrivals);
  thread.join();
  ::close(fd);
  EXPECT_EQ(received, expected);
  ASSERT_EQ(arrivals.size(), chunks.size());
  // Chunk i is due 50 ms x i after the first: arrival minus due time is the same for every
  // chunk up to scheduler jitter, which stays below one chunk spacing even on a loaded 2-core
  // host; unpaced, the spread would be the whole second.
  double lag_min_ms = 1e9, lag_max_ms = -1e9;
  for (size_t i = 0; i < arrivals.size(); ++i) {
    const double lag_ms = static_cast<double>(arrivals[i] - arrivals[0]) * 1e-3 - 50.0 * static_cast<double>(i);
    lag_min_ms = std::min(lag_min_ms, lag_ms);
    lag_max_ms = std::max(lag_max_ms, lag_ms);
  }
  EXPECT_LT(lag_max_ms - lag_min_ms, 40.0);
  EXPECT_NEAR(static_cast<double>(arrivals.back() - arrivals.front()) * 1e-3, 1000.0, 40.0);
  EXPECT_EQ(server.stats().chunks_sent, chunks.size());
}

TEST(TcpStreamServer, ClientThatReconnectsGetsTheRest) {
  const std::vector<TimedChunk> chunks = makeChunks(10, 100'000);
  StreamServerOptions options;
  options.port = 0;
  options.speed = 0.0;
  options.faults.drop_connection_every = 4;  // closes after chunks 3 and 7
  TcpStreamServer server(options, chunks);
  ASSERT_OK(server.listen());
  std::atomic<bool> stop{false};
  std::thread thread([&] { server.run(stop); });
  std::vector<uint8_t> all;
  for (int connection = 0; connection < 3; ++connection) {
    const int fd = connectTo(server.port());
    ASSERT_GE(fd, 0);
    uint8_t buffer[4096];
    ssize_t n;
    while ((n = ::recv(fd, buffer, sizeof(buffer), 0)) > 0) all.insert(all.end(), buffer, buffer + n);
    ::close(fd);
  }
  thread.join();
  std::vector<uint8_t> expected;
  for (const auto& c : chunks) expected.insert(expected.end(), c.bytes.begin(), c.bytes.end());
  EXPECT_EQ(all, expected);
  EXPECT_EQ(server.stats().drops, 2u);
  EXPECT_EQ(server.stats().connections, 3u);
}

TEST(UdpStreamSender, SendsOneDatagramPerChunkInOrder) {
  const int receiver = ::socket(AF_INET, SOCK_DGRAM, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ASSERT_EQ(::bind(receiver, reinterpret_cast<sockaddr*>(&address), sizeof(address)), 0);
  socklen_t length = sizeof(address);
  ::getsockname(receiver, reinterpret_cast<sockaddr*>(&address), &length);
  const std::vector<TimedChunk> chunks = makeChunks(30, 50'000);
  StreamServerOptions options;
  options.bind_address = "127.0.0.1";
  options.port = ntohs(address.sin_port);
  options.speed = 10.0;
  UdpStreamSender sender(options, chunks);
  std::atomic<bool> stop{false};
  const int64_t start = sss::core::monotonicUtime();
  ASSERT_OK(sender.run(stop));
  const double elapsed_ms = static_cast<double>(sss::core::monotonicUtime() - start) * 1e-3;
  EXPECT_NEAR(elapsed_ms, 29 * 5.0, 40.0);  // 29 periods of 50 ms at 10x; unpaced it is ~1 ms
  for (const auto& chunk : chunks) {
    uint8_t buffer[4096];
    const ssize_t n = ::recv(receiver, buffer, sizeof(buffer), MSG_DONTWAIT);
    ASSERT_EQ(n, static_cast<ssize_t>(chunk.bytes.size()));
    EXPECT_EQ(buffer[0], chunk.bytes[0]);
  }
  ::close(receiver);
}

// One pause of 0.1 s after the 40th of 70 chunks (50 ms apart, at 10x: 5 ms): as a stall every
// chunk comes, 0.1 s late; as an outage the ~20 chunks that fell due meanwhile never come and the
// rest keep their schedule.
TEST(UdpStreamSender, APauseIsAStallOrAnOutage) {
  for (const bool outage : {false, true}) {
    const int receiver = ::socket(AF_INET, SOCK_DGRAM, 0);
    sockaddr_in address{};
    address.sin_family = AF_INET;
    address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    ASSERT_EQ(::bind(receiver, reinterpret_cast<sockaddr*>(&address), sizeof(address)), 0);
    socklen_t length = sizeof(address);
    ::getsockname(receiver, reinterpret_cast<sockaddr*>(&address), &length);
    const std::vector<TimedChunk> chunks = makeChunks(70, 50'000);
    StreamServerOptions options;
    options.port = ntohs(address.sin_port);
    options.speed = 10.0;
    options.faults.pause_every = 40;  // after chunk 39 only
    options.faults.pause_s = 0.1;
    options.faults.pause_skips = outage;
    UdpStreamSender sender(options, chunks);
    std::atomic<bool> stop{false};
    const int64_t start = sss::core::monotonicUtime();
    ASSERT_OK(sender.run(stop));
    const double elapsed_ms = static_cast<double>(sss::core::monotonicUtime() - start) * 1e-3;
    std::vector<int> received;
    uint8_t buffer[4096];
    while (::recv(receiver, buffer, sizeof(buffer), MSG_DONTWAIT) > 0) received.push_back(buffer[0]);
    ::close(receiver);
    const StreamStats& stats = sender.stats();
    EXPECT_EQ(stats.pauses, 1u);
    ASSERT_EQ(received.size(), stats.chunks_sent);
    ASSERT_GE(received.size(), 41u);
    EXPECT_TRUE(std::is_sorted(received.begin(), received.end()));
    for (int i = 0; i < 40; ++i) EXPECT_EQ(received[static_cast<size_t>(i)], i);
    EXPECT_EQ(received.back(), 69);
    if (!outage) {
      EXPECT_EQ(stats.chunks_skipped, 0u);
      EXPECT_EQ(received.size(), chunks.size());
      EXPECT_NEAR(elapsed_ms, 69 * 5.0 + 100.0, 60.0) << "a stall shifts the rest";
    } else {
      // Chunks 40-58 (due 200-290 ms) fell due during the pause (195-295 ms); 59 is borderline.
      EXPECT_GE(stats.chunks_skipped, 17u);
      EXPECT_LE(stats.chunks_skipped, 21u);
      EXPECT_EQ(received.size() + stats.chunks_skipped, chunks.size());
      EXPECT_NEAR(elapsed_ms, 69 * 5.0, 60.0) << "an outage keeps the schedule";
    }
  }
}

}  // namespace
}  // namespace sss::emulators
