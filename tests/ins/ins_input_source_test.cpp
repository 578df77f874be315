// sss-ins-bridge's byte sources on real descriptors: UDP datagrams on loopback, a TCP link that
// reconnects after the peer closes, a serial line played by a pseudo-terminal that vanishes and
// comes back, and a file replay; each failure says what and where.
#include "drivers/ins/ins_input_source.hpp"

#include <gtest/gtest.h>

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <stdlib.h>
#include <sys/socket.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "pipeline/core/time.hpp"
#include "tests/support/loopback_socket.hpp"
#include "tools/fixtures/poll_until.hpp"
#include "tests/support/status_assertions.hpp"

namespace sss::ins {
namespace {

namespace fs = std::filesystem;

// What a source handed over, in order.
struct Recorder {
  struct Piece {
    std::string bytes;
    bool stream_break;
    bool end_of_file;
  };
  std::vector<Piece> pieces;
  std::vector<std::string> info;
  std::vector<std::string> warnings;
  std::vector<std::string> open_failures;

  InsInputHooks hooks() {
    InsInputHooks hooks;
    hooks.chunk = [this](const InsInputChunk& chunk) {
      pieces.push_back({std::string(reinterpret_cast<const char*>(chunk.data), chunk.size), chunk.stream_break,
                        chunk.end_of_file});
    };
    hooks.info = [this](const std::string& line) { info.push_back(line); };
    hooks.warning = [this](const std::string& line) { warnings.push_back(line); };
    hooks.open_failed = [this](const std::string& error) { open_failures.push_back(error); };
    return hooks;
  }
  std::string bytes() const {
    std::string all;
    for (const Piece& piece : pieces) all += piece.bytes;
    return all;
  }
};

using sss::test::within1s;

using sss::test::boundPort;
using sss::test::boundSocket;
using sss::test::loopback;

TEST(InsInputSource, UdpHandsOverEachDatagramWithAStreamBreakAfterIt) {
  InsInputOptions options;
  options.source = "udp";
  options.bind_address = "127.0.0.1";
  options.udp_port = 0;
  Recorder recorder;
  InsInputSource source(options, recorder.hooks());
  ASSERT_OK(source.open());
  ASSERT_GT(source.boundUdpPort(), 0);
  EXPECT_GE(source.fd(), 0);
  EXPECT_EQ(source.servicePeriodS(), 0.0);

  const int sender = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  const sockaddr_in to = loopback(source.boundUdpPort());
  for (const std::string datagram : {"$HEHDT,1", "0.0,T*2C\r\n"}) {
    ::sendto(sender, datagram.data(), datagram.size(), 0, reinterpret_cast<const sockaddr*>(&to), sizeof(to));
  }
  ::close(sender);
  ASSERT_TRUE(within1s([&] { source.read(0.1); }, [&] { return recorder.pieces.size() >= 2; }));

  ASSERT_EQ(recorder.pieces.size(), 2u);
  EXPECT_EQ(recorder.pieces[0].bytes, "$HEHDT,1");  // the break tells the bridge not to join it to the next
  EXPECT_TRUE(recorder.pieces[0].stream_break);
  EXPECT_EQ(recorder.pieces[1].bytes, "0.0,T*2C\r\n");
  EXPECT_TRUE(recorder.pieces[1].stream_break);
  EXPECT_FALSE(recorder.pieces[1].end_of_file);
  EXPECT_EQ(source.counters().bytes, 18u);
  EXPECT_EQ(source.counters().opens, 1u);
  EXPECT_EQ(source.read(0.0), 0u);  // nothing waiting: returns at once
}

TEST(InsInputSource, UdpPortAlreadyTakenSaysWhichPortAndWhy) {
  const int taken = boundSocket(SOCK_DGRAM);
  const int port = boundPort(taken);
  InsInputOptions options;
  options.source = "udp";
  options.bind_address = "127.0.0.1";
  options.udp_port = port;
  InsInputSource source(options, {});
  const sss::core::Status opened = source.open();
  ::close(taken);
  EXPECT_FALSE(opened.ok);
  EXPECT_EQ(opened.message, "cannot bind UDP 127.0.0.1:" + std::to_string(port) + ": Address already in use");
  EXPECT_EQ(source.fd(), -1);
  EXPECT_EQ(source.boundUdpPort(), 0);
}

class InsInputFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    path_ = (fs::temp_directory_path() / ("sss_ins_input_" + std::to_string(::getpid()) + ".nmea")).string();
  }
  void TearDown() override { fs::remove(path_); }
  std::string path_;
};

TEST_F(InsInputFileTest, DeliversTheFileInChunksAndSignalsItsEnd) {
  std::string contents;
  for (int i = 0; contents.size() < 16384 + 100; ++i) contents += "$PIXSE,TIME__," + std::to_string(i) + "*00\r\n";
  contents.resize(16384 + 100);
  std::ofstream(path_, std::ios::binary) << contents;
  InsInputOptions options;
  options.source = "file";
  options.file = path_;
  Recorder recorder;
  InsInputSource source(options, recorder.hooks());
  ASSERT_OK(source.open());
  EXPECT_EQ(source.fd(), -1);  // read when the replay wants more, not when a descriptor says so

  EXPECT_EQ(source.read(0.0), 16384u);
  EXPECT_FALSE(source.atEnd());
  EXPECT_EQ(source.read(0.0), 100u);
  EXPECT_TRUE(source.atEnd());
  EXPECT_EQ(source.read(0.0), 0u);  // after the end: nothing more is handed over

  ASSERT_EQ(recorder.pieces.size(), 2u);
  EXPECT_FALSE(recorder.pieces[0].end_of_file);
  EXPECT_TRUE(recorder.pieces[1].end_of_file);
  EXPECT_FALSE(recorder.pieces[0].stream_break || recorder.pieces[1].stream_break);
  EXPECT_EQ(recorder.bytes(), contents);
  EXPECT_EQ(source.counters().bytes, contents.size());
}

TEST_F(InsInputFileTest, MissingFileSaysWhich) {
  InsInputOptions options;
  options.source = "file";
  options.file = path_ + ".missing";
  InsInputSource source(options, {});
  EXPECT_EQ(source.open().message, "cannot open INS file '" + path_ + ".missing'");
}

TEST(InsInputSource, TcpReconnectsAfterThePeerClosesAndBreaksTheStreamAtTheDrop) {
  const int listener = boundSocket(SOCK_STREAM);
  ASSERT_EQ(::listen(listener, 4), 0);
  const int port = boundPort(listener);
  InsInputOptions options;
  options.source = "tcp";
  options.tcp.host = "127.0.0.1";
  options.tcp.port = port;
  options.tcp.reconnect_min_s = 0.01;  // the default 0.2 s would only slow the test
  Recorder recorder;
  InsInputSource source(options, recorder.hooks());
  ASSERT_OK(source.open());
  EXPECT_EQ(source.fd(), -1);  // connects in service(), not before
  EXPECT_EQ(source.servicePeriodS(), 0.05);

  const auto connectAndSend = [&](const std::string& bytes) {
    EXPECT_TRUE(within1s([&] { source.service(sss::core::monotonicUtime()); }, [&] { return source.fd() >= 0; }));
    const int peer = ::accept4(listener, nullptr, nullptr, SOCK_CLOEXEC);
    EXPECT_GE(peer, 0);
    EXPECT_EQ(::send(peer, bytes.data(), bytes.size(), 0), static_cast<ssize_t>(bytes.size()));
    return peer;
  };
  const int first_peer = connectAndSend("$HEHDT,10.0,T*2C\r\n");
  ASSERT_TRUE(within1s([&] { source.read(0.1); }, [&] { return recorder.bytes().size() >= 18; }));
  ::close(first_peer);
  ASSERT_TRUE(within1s([&] { source.read(0.1); }, [&] { return source.fd() < 0; }));
  ASSERT_EQ(recorder.warnings.size(), 1u);
  EXPECT_EQ(recorder.warnings[0], "INS link: peer closed the connection");
  EXPECT_TRUE(recorder.pieces.back().stream_break);  // a sentence cut at the drop ends there
  EXPECT_EQ(recorder.pieces.back().bytes, "");
  EXPECT_EQ(source.counters().losses, 1u);

  const int second_peer = connectAndSend("$PIXSE,ATITUD,1.0,2.0*00\r\n");
  ASSERT_TRUE(within1s([&] { source.read(0.1); }, [&] { return recorder.bytes().size() >= 18 + 26; }));
  ::close(second_peer);
  ::close(listener);
  EXPECT_EQ(recorder.bytes(), "$HEHDT,10.0,T*2C\r\n$PIXSE,ATITUD,1.0,2.0*00\r\n");
  const std::string connected = "INS link: connected to 127.0.0.1:" + std::to_string(port);
  EXPECT_EQ(recorder.info, std::vector<std::string>({connected, connected}));
  EXPECT_EQ(source.counters().opens, 2u);
  EXPECT_EQ(source.counters().bytes, 18u + 26u);
}

TEST(InsInputSource, TcpRefusedConnectionIsAWarningNamingTheLinkAndNotALoss) {
  const int closed = boundSocket(SOCK_STREAM);  // bound, not listening: connections are refused
  InsInputOptions options;
  options.source = "tcp";
  options.tcp.host = "127.0.0.1";
  options.tcp.port = boundPort(closed);
  Recorder recorder;
  InsInputSource source(options, recorder.hooks());
  ASSERT_OK(source.open());
  ASSERT_TRUE(within1s([&] { source.service(sss::core::monotonicUtime()); },
                       [&] { return !recorder.warnings.empty(); }));
  ::close(closed);
  EXPECT_EQ(recorder.warnings[0].rfind("INS link: ", 0), 0u) << recorder.warnings[0];
  EXPECT_NE(recorder.warnings[0].find("Connection refused"), std::string::npos) << recorder.warnings[0];
  EXPECT_EQ(source.fd(), -1);
  EXPECT_EQ(source.counters().opens, 0u);
  EXPECT_EQ(source.counters().losses, 0u);
}

// A serial line played by a pseudo-terminal, reached through a link the test can point elsewhere
// (as udev names a USB adapter that comes back under another device).
class InsInputSerialTest : public ::testing::Test {
 protected:
  void SetUp() override {
    link_ = (fs::temp_directory_path() / ("sss_ins_serial_" + std::to_string(::getpid()))).string();
    fs::remove(link_);
  }
  void TearDown() override {
    if (master_ >= 0) ::close(master_);
    fs::remove(link_);
  }
  // A new pseudo-terminal behind the link; false when the system has none to give.
  bool plugIn() {
    master_ = ::posix_openpt(O_RDWR | O_NOCTTY | O_CLOEXEC);
    if (master_ < 0 || ::grantpt(master_) != 0 || ::unlockpt(master_) != 0) return false;
    fs::remove(link_);
    fs::create_symlink(::ptsname(master_), link_);
    return true;
  }
  void unplug() {
    ::close(master_);
    master_ = -1;
  }
  void send(const std::string& bytes) {
    ASSERT_EQ(::write(master_, bytes.data(), bytes.size()), static_cast<ssize_t>(bytes.size()));
  }

  std::string link_;
  int master_ = -1;
};

TEST_F(InsInputSerialTest, ReadsThePortAndReopensItWhenItComesBack) {
  if (!plugIn()) GTEST_SKIP() << "no pseudo-terminal available";
  InsInputOptions options;
  options.source = "serial";
  options.serial_device = link_;
  options.serial_baud = 9600;
  Recorder recorder;
  InsInputSource source(options, recorder.hooks());
  ASSERT_OK(source.open());
  ASSERT_GE(source.fd(), 0);
  EXPECT_EQ(source.servicePeriodS(), 2.0);
  EXPECT_EQ(recorder.info, std::vector<std::string>({"reading INS from " + link_}));

  send("$HEHDT,10.0,T*2C\r\n");
  ASSERT_TRUE(within1s([&] { source.read(0.1); }, [&] { return recorder.bytes().size() >= 18; }));
  EXPECT_EQ(recorder.bytes(), "$HEHDT,10.0,T*2C\r\n");
  EXPECT_FALSE(recorder.pieces[0].stream_break);  // a serial line is one stream

  unplug();
  ASSERT_TRUE(within1s([&] { source.read(0.1); }, [&] { return source.fd() < 0; }));
  EXPECT_EQ(recorder.warnings, std::vector<std::string>({"serial port '" + link_ + "' closed; reopening"}));
  EXPECT_EQ(source.counters().losses, 1u);

  ASSERT_TRUE(plugIn());
  source.service(sss::core::monotonicUtime());
  ASSERT_GE(source.fd(), 0);
  EXPECT_EQ(recorder.info.size(), 2u);
  send("$PIXSE,ATITUD,1.0,2.0*00\r\n");
  ASSERT_TRUE(within1s([&] { source.read(0.1); }, [&] { return recorder.bytes().size() >= 18 + 26; }));
  EXPECT_EQ(recorder.bytes(), "$HEHDT,10.0,T*2C\r\n$PIXSE,ATITUD,1.0,2.0*00\r\n");
  EXPECT_EQ(source.counters().opens, 2u);
  EXPECT_TRUE(recorder.open_failures.empty());
}

TEST(InsInputSource, MissingSerialPortIsReportedWithItsNameAndTriedAgain) {
  InsInputOptions options;
  options.source = "serial";
  options.serial_device = "/nonexistent/ttyINS";
  Recorder recorder;
  InsInputSource source(options, recorder.hooks());
  EXPECT_OK(source.open());  // not fatal: the port may appear later
  EXPECT_EQ(source.fd(), -1);
  source.service(sss::core::monotonicUtime());
  const std::string error = "cannot open serial port '/nonexistent/ttyINS': No such file or directory";
  EXPECT_EQ(recorder.open_failures, std::vector<std::string>({error, error}));
  EXPECT_EQ(source.read(0.0), 0u);
  EXPECT_TRUE(recorder.info.empty() && recorder.warnings.empty());
}

TEST(InsInputSource, UnknownSourceIsAProgrammingError) {
  InsInputOptions options;
  options.source = "carrier-pigeon";
  EXPECT_THROW({ InsInputSource source(options, InsInputHooks{}); }, std::invalid_argument);
}

}  // namespace
}  // namespace sss::ins
