// DDS: writer and reader in separate participants (and processes) on an isolated domain, on
// loopback, exchange a navigation correction with reliable, keep-last, transient-local QoS: a
// reader that joins after the write still gets the newest sample.
#include "pipeline/transport/dds.hpp"

#include <gtest/gtest.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstring>

#include "dds_correction_fixture.hpp"

extern char** environ;

namespace sss::transport::dds {
namespace {

// A domain id of our own per test process: parallel tests and other DDS users stay apart.
uint32_t isolatedDomainId() { return 100 + static_cast<uint32_t>(getpid() % 100); }

void expectSameCorrection(const sss_dds_NavigationCorrection& a, const sss_dds_NavigationCorrection& b) {
  EXPECT_EQ(std::memcmp(&a, &b, sizeof(a)), 0);
}

TEST(Dds, QosIsReliableKeepLastTransientLocal) {
  Qos qos(QosSettings{});
  dds_reliability_kind_t reliability;
  dds_duration_t blocking;
  ASSERT_TRUE(dds_qget_reliability(qos.get(), &reliability, &blocking));
  EXPECT_EQ(reliability, DDS_RELIABILITY_RELIABLE);
  dds_history_kind_t history;
  int32_t depth = 0;
  ASSERT_TRUE(dds_qget_history(qos.get(), &history, &depth));
  EXPECT_EQ(history, DDS_HISTORY_KEEP_LAST);
  EXPECT_EQ(depth, 1);
  dds_durability_kind_t durability;
  ASSERT_TRUE(dds_qget_durability(qos.get(), &durability));
  EXPECT_EQ(durability, DDS_DURABILITY_TRANSIENT_LOCAL);
}

TEST(Dds, LateReaderInAnotherParticipantGetsTheNewestCorrection) {
  const uint32_t domain = isolatedDomainId();
  Participant writer_participant(domain, loopbackConfigXml());
  ASSERT_TRUE(writer_participant.good()) << writer_participant.error();
  Topic<sss_dds_NavigationCorrection> writer_topic(writer_participant, &sss_dds_NavigationCorrection_desc, "sss_correction");
  Writer<sss_dds_NavigationCorrection> writer(writer_participant, writer_topic);
  ASSERT_TRUE(writer.good()) << writer.error();
  ASSERT_TRUE(writer.write(sss::test::makeCorrection(1000)));
  ASSERT_TRUE(writer.write(sss::test::makeCorrection(2000)));

  // The reader joins after both writes.
  Participant reader_participant(domain);
  ASSERT_TRUE(reader_participant.good()) << reader_participant.error();
  Topic<sss_dds_NavigationCorrection> reader_topic(reader_participant, &sss_dds_NavigationCorrection_desc, "sss_correction");
  Reader<sss_dds_NavigationCorrection> reader(reader_participant, reader_topic);
  ASSERT_TRUE(reader.good()) << reader.error();
  sss_dds_NavigationCorrection received{};
  ASSERT_TRUE(reader.waitAndTake(received, 10.0));
  expectSameCorrection(received, sss::test::makeCorrection(2000));
  sss_dds_NavigationCorrection extra{};
  EXPECT_FALSE(reader.take(extra)) << "keep-last 1 must deliver only the newest";

  // Live samples after the join arrive too.
  ASSERT_TRUE(writer.write(sss::test::makeCorrection(3000)));
  ASSERT_TRUE(reader.waitAndTake(received, 10.0));
  EXPECT_EQ(received.utime_us, 3000);
}

TEST(Dds, LateReaderInAnotherProcessGetsTheNewestCorrection) {
  const uint32_t domain = isolatedDomainId();
  int to_child[2], from_child[2];
  ASSERT_EQ(::pipe(to_child), 0);
  ASSERT_EQ(::pipe(from_child), 0);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, to_child[0], STDIN_FILENO);
  posix_spawn_file_actions_adddup2(&actions, from_child[1], STDOUT_FILENO);
  posix_spawn_file_actions_addclose(&actions, to_child[1]);
  posix_spawn_file_actions_addclose(&actions, from_child[0]);
  const std::string domain_arg = std::to_string(domain);
  char* argv[] = {const_cast<char*>(DDS_PUBLISHER_PATH), const_cast<char*>(domain_arg.c_str()),
                  const_cast<char*>("5000"), nullptr};
  pid_t child = 0;
  ASSERT_EQ(posix_spawn(&child, DDS_PUBLISHER_PATH, &actions, nullptr, argv, environ), 0);
  posix_spawn_file_actions_destroy(&actions);
  ::close(to_child[0]);
  ::close(from_child[1]);

  // Wait until the other process has written both samples, then join as a late reader.
  char line[32] = {};
  ssize_t n = ::read(from_child[0], line, sizeof(line) - 1);
  ASSERT_GT(n, 0) << "publisher process did not start";
  ASSERT_EQ(std::string(line, static_cast<size_t>(n)), "written\n");

  Participant participant(domain, loopbackConfigXml());
  ASSERT_TRUE(participant.good()) << participant.error();
  Topic<sss_dds_NavigationCorrection> topic(participant, &sss_dds_NavigationCorrection_desc, "sss_correction");
  Reader<sss_dds_NavigationCorrection> reader(participant, topic);
  sss_dds_NavigationCorrection received{};
  const bool got = reader.waitAndTake(received, 15.0);

  ::close(to_child[1]);  // lets the publisher leave
  int status = 0;
  ::waitpid(child, &status, 0);
  ::close(from_child[0]);
  ASSERT_TRUE(got) << "no correction from the other process over loopback";
  expectSameCorrection(received, sss::test::makeCorrection(5001));
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0);
}

}  // namespace
}  // namespace sss::transport::dds
