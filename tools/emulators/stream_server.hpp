// Serves a recorded stream (time-stamped chunks: JSF messages, INS sentence bursts) to a live
// client the way the real sensor would: TCP server or UDP sender, paced by the chunk times at a
// speed factor, tolerating client disconnects, and injecting faults on demand for tests.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "pipeline/core/status.hpp"

namespace sss::emulators {

struct TimedChunk {
  int64_t time_us = 0;  // sensor time of the chunk (pacing only)
  std::vector<uint8_t> bytes;
};

struct FaultPlan {
  int corrupt_every = 0;        // every Kth chunk: garbage_bytes random bytes are sent before it
  int garbage_bytes = 64;
  int flip_every = 0;           // every Kth chunk: one byte inside it is flipped (bad checksum / data)
  int truncate_every = 0;       // every Kth chunk: only its first half is sent
  int drop_connection_every = 0;  // TCP: close the connection after every Kth chunk
  int pause_every = 0;          // every Kth chunk: stop sending for pause_s
  double pause_s = 0.0;
  // false: a stall, the chunks are sent late (the schedule shifts by pause_s); true: an outage,
  // the chunks that fell due during the pause are never sent and the schedule carries on.
  bool pause_skips = false;
  uint32_t seed = 1;
};

struct StreamServerOptions {
  std::string bind_address = "127.0.0.1";
  int port = 1701;              // 0: any free port (see port())
  double speed = 1.0;           // 1 = real time, 10 = ten times faster, 0 = as fast as the client reads
  // Set: chunk times are paced from this sensor time rather than from the first chunk's, so that two
  // streams of one mission (INS and fixes) started together stay in step.
  std::optional<int64_t> pacing_origin_us;
  FaultPlan faults;
};

struct StreamStats {
  uint64_t chunks_sent = 0;     // sent whole and untouched
  uint64_t chunks_faulted = 0;  // flipped or truncated
  uint64_t garbage_runs = 0;
  uint64_t connections = 0;
  uint64_t drops = 0;
  uint64_t pauses = 0;
  uint64_t chunks_skipped = 0;  // never sent: fell due during an outage (pause_skips)
};

class TcpStreamServer {
 public:
  TcpStreamServer(StreamServerOptions options, std::vector<TimedChunk> chunks);
  ~TcpStreamServer();

  // Binds and listens; fails when the port is taken or the address is wrong.
  sss::core::Status listen();
  int port() const { return port_; }
  // Called after the last byte of chunk `index` was handed to the kernel (benchmarks).
  void setChunkSentCallback(std::function<void(size_t index, int64_t monotonic_us)> callback) {
    on_chunk_sent_ = std::move(callback);
  }
  // Waits for a client, sends every chunk (continuing after a drop once a client reconnects),
  // returns when all are sent or stop becomes true. Closes the connection at the end.
  void run(const std::atomic<bool>& stop);
  const StreamStats& stats() const { return stats_; }

 private:
  int acceptClient(const std::atomic<bool>& stop);
  StreamServerOptions options_;
  std::vector<TimedChunk> chunks_;
  int listen_fd_ = -1;
  int port_ = 0;
  StreamStats stats_;
  std::function<void(size_t, int64_t)> on_chunk_sent_;
};

// Sends each chunk as one UDP datagram to host:port (an INS's usual output), paced and faulted
// like the TCP server (drops do not apply).
class UdpStreamSender {
 public:
  UdpStreamSender(StreamServerOptions options, std::vector<TimedChunk> chunks);
  // Fails only for a bad destination address; a datagram nobody receives is not an error (UDP).
  sss::core::Status run(const std::atomic<bool>& stop);
  const StreamStats& stats() const { return stats_; }

 private:
  StreamServerOptions options_;
  std::vector<TimedChunk> chunks_;
  StreamStats stats_;
};

}  // namespace sss::emulators
