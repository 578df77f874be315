// sss-ins-bridge's byte sources. See ins_input_source.hpp.
#include "drivers/ins/ins_input_source.hpp"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <utility>

#include "pipeline/core/time.hpp"

namespace sss::ins {
namespace {

speed_t baudConstant(int baud) {
  switch (baud) {
    case 9600: return B9600;
    case 19200: return B19200;
    case 38400: return B38400;
    case 57600: return B57600;
    case 230400: return B230400;
    case 460800: return B460800;
    default: return B115200;
  }
}

sss::core::Result<int> openUdp(const std::string& bind_address, int port) {
  const int fd = ::socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  const int one = 1;
  ::setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof(one));
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(static_cast<uint16_t>(port));
  ::inet_pton(AF_INET, bind_address.c_str(), &address.sin_addr);
  if (::bind(fd, reinterpret_cast<sockaddr*>(&address), sizeof(address)) != 0) {
    const std::string why = std::strerror(errno);
    ::close(fd);
    return sss::core::Status::error("cannot bind UDP " + bind_address + ":" + std::to_string(port) + ": " + why);
  }
  return fd;
}

sss::core::Result<int> openSerialPort(const std::string& device, int baud) {
  const int fd = ::open(device.c_str(), O_RDONLY | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) return sss::core::Status::error("cannot open serial port '" + device + "': " + std::strerror(errno));
  termios tty{};
  if (::tcgetattr(fd, &tty) == 0) {
    ::cfmakeraw(&tty);
    ::cfsetispeed(&tty, baudConstant(baud));
    tty.c_cflag |= CLOCAL | CREAD;
    ::tcsetattr(fd, TCSANOW, &tty);
  }
  return fd;
}

bool waitReadable(int fd, double timeout_s) {
  pollfd p{fd, POLLIN, 0};
  return ::poll(&p, 1, static_cast<int>(timeout_s * 1000.0)) > 0;
}

}  // namespace

InsInputSource::InsInputSource(InsInputOptions options, InsInputHooks hooks)
    : options_(std::move(options)), hooks_(std::move(hooks)) {
  if (options_.source == "udp") {
    kind_ = Kind::kUdp;
  } else if (options_.source == "tcp") {
    kind_ = Kind::kTcp;
  } else if (options_.source == "serial") {
    kind_ = Kind::kSerial;
  } else if (options_.source == "file") {
    kind_ = Kind::kFile;
  } else {
    throw std::invalid_argument("INS input source '" + options_.source + "': expected udp, tcp, serial or file");
  }
}

InsInputSource::~InsInputSource() {
  if (fd_ >= 0) ::close(fd_);
}

sss::core::Status InsInputSource::open() {
  switch (kind_) {
    case Kind::kUdp: {
      const sss::core::Result<int> socket = openUdp(options_.bind_address, options_.udp_port);
      if (!socket) return socket.status();
      fd_ = *socket;
      ++counters_.opens;
      return sss::core::Status::success();
    }
    case Kind::kSerial:
      openSerial();
      return sss::core::Status::success();
    case Kind::kTcp:
      tcp_ = std::make_unique<sss::transport::TcpClient>(
          options_.tcp,
          [this](const uint8_t* data, size_t size) {
            counters_.bytes += size;
            deliver(data, size, false, false);
          },
          [this](sss::transport::LinkState state, const std::string& reason) {
            if (state == sss::transport::LinkState::kDisconnected) {
              if (tcp_connected_) ++counters_.losses;
              tcp_connected_ = false;
              say(hooks_.warning, "INS link: " + reason);
              deliver(nullptr, 0, true, false);  // a sentence cut by the drop is not joined to the next link's
            } else if (state == sss::transport::LinkState::kConnected) {
              tcp_connected_ = true;
              ++counters_.opens;
              say(hooks_.info, "INS link: " + reason);
            }
          });
      return sss::core::Status::success();
    case Kind::kFile:
      file_.open(options_.file, std::ios::binary);
      if (!file_) return sss::core::Status::error("cannot open INS file '" + options_.file + "'");
      ++counters_.opens;
      return sss::core::Status::success();
  }
  return sss::core::Status::success();
}

int InsInputSource::fd() const {
  if (kind_ == Kind::kTcp) return tcp_ ? tcp_->fd() : -1;
  return fd_;
}

double InsInputSource::servicePeriodS() const {
  if (kind_ == Kind::kSerial) return options_.serial_reopen_period_s;
  if (kind_ == Kind::kTcp) return options_.tcp_service_period_s;
  return 0.0;
}

void InsInputSource::service(int64_t now_us) {
  if (kind_ == Kind::kSerial) openSerial();
  if (kind_ == Kind::kTcp && tcp_) tcp_->service(now_us);
}

size_t InsInputSource::read(double timeout_s) {
  if (kind_ == Kind::kFile) return readFile();
  const int readable_fd = fd();
  if (readable_fd < 0) return 0;
  if (timeout_s > 0.0 && !waitReadable(readable_fd, timeout_s)) return 0;
  switch (kind_) {
    case Kind::kUdp: return readUdp();
    case Kind::kSerial: return readSerial();
    case Kind::kTcp: {
      const uint64_t before = counters_.bytes;
      tcp_->onReadable(sss::core::monotonicUtime());
      return static_cast<size_t>(counters_.bytes - before);
    }
    case Kind::kFile: break;
  }
  return 0;
}

int InsInputSource::boundUdpPort() const {
  if (kind_ != Kind::kUdp || fd_ < 0) return 0;
  sockaddr_in address{};
  socklen_t length = sizeof(address);
  if (::getsockname(fd_, reinterpret_cast<sockaddr*>(&address), &length) != 0) return 0;
  return ntohs(address.sin_port);
}

void InsInputSource::openSerial() {
  if (fd_ >= 0) return;
  const sss::core::Result<int> port = openSerialPort(options_.serial_device, options_.serial_baud);
  if (!port) {
    if (hooks_.open_failed) hooks_.open_failed(port.message());
    return;
  }
  fd_ = *port;
  ++counters_.opens;
  say(hooks_.info, "reading INS from " + options_.serial_device);
}

size_t InsInputSource::readUdp() {
  uint8_t datagram[65536];
  size_t total = 0;
  ssize_t n;
  // Each datagram is its own piece: a sentence never continues into the next one.
  while ((n = ::recv(fd_, datagram, sizeof(datagram), 0)) > 0) {
    counters_.bytes += static_cast<uint64_t>(n);
    total += static_cast<size_t>(n);
    deliver(datagram, static_cast<size_t>(n), true, false);
  }
  return total;
}

size_t InsInputSource::readSerial() {
  uint8_t buffer[4096];
  const ssize_t n = ::read(fd_, buffer, sizeof(buffer));
  if (n > 0) {
    counters_.bytes += static_cast<uint64_t>(n);
    deliver(buffer, static_cast<size_t>(n), false, false);
    return static_cast<size_t>(n);
  }
  if (n == 0 || (errno != EAGAIN && errno != EINTR)) {
    say(hooks_.warning, "serial port '" + options_.serial_device + "' closed; reopening");
    ::close(fd_);
    fd_ = -1;
    ++counters_.losses;
  }
  return 0;
}

size_t InsInputSource::readFile() {
  if (at_end_ || !file_.is_open()) return 0;
  char chunk[16384];
  file_.read(chunk, sizeof(chunk));
  const size_t n = static_cast<size_t>(file_.gcount());
  counters_.bytes += n;
  at_end_ = n < sizeof(chunk);
  deliver(reinterpret_cast<const uint8_t*>(chunk), n, false, at_end_);
  return n;
}

void InsInputSource::deliver(const uint8_t* data, size_t size, bool stream_break, bool end_of_file) {
  if (!hooks_.chunk) return;
  InsInputChunk chunk;
  chunk.data = data;
  chunk.size = size;
  chunk.arrival_us = sss::core::monotonicUtime();
  chunk.stream_break = stream_break;
  chunk.end_of_file = end_of_file;
  hooks_.chunk(chunk);
}

void InsInputSource::say(const std::function<void(const std::string&)>& hook, const std::string& line) const {
  if (hook) hook(line);
}

}  // namespace sss::ins
