// Test helper: joins DDS domain argv[1] on loopback, publishes corrections with utime argv[2]
// and argv[2]+1 (keep-last 1 keeps only the second), prints "written", then waits for stdin to
// close (the test process tells it to go) before leaving.
#include <cstdio>
#include <cstdlib>
#include <string>

#include "dds_correction_fixture.hpp"
#include "pipeline/transport/dds.hpp"

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: %s DOMAIN_ID UTIME_US\n", argv[0]);
    return 2;
  }
  namespace dds = sss::transport::dds;
  const uint32_t domain_id = static_cast<uint32_t>(std::atoi(argv[1]));
  const int64_t utime_us = std::atoll(argv[2]);
  dds::Participant participant(domain_id, dds::loopbackConfigXml());
  dds::Topic<sss_dds_NavigationCorrection> topic(participant, &sss_dds_NavigationCorrection_desc, "sss_correction");
  dds::Writer<sss_dds_NavigationCorrection> writer(participant, topic);
  if (!participant.good() || !topic.good() || !writer.good()) {
    std::fprintf(stderr, "DDS setup failed: %s %s %s\n", participant.error().c_str(), topic.error().c_str(),
                 writer.error().c_str());
    return 1;
  }
  if (!writer.write(sss::test::makeCorrection(utime_us)) || !writer.write(sss::test::makeCorrection(utime_us + 1))) {
    std::fprintf(stderr, "DDS write failed\n");
    return 1;
  }
  std::printf("written\n");
  std::fflush(stdout);
  char buffer[64];
  while (std::fgets(buffer, sizeof(buffer), stdin) != nullptr) {
  }
  return 0;
}
