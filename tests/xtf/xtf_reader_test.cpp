// XtfReader on files written after the public layout: round trips of every field, pair selection,
// nav units, skipped packet types, corruption with resynchronisation, and the fuzz regression.
#include "drivers/xtf/xtf_reader.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>

#include "tests/xtf/xtf_fuzz_target.hpp"
#include "tests/xtf/xtf_test_data.hpp"

namespace sss {
namespace {

using sonar::DriverPing;

std::vector<DriverPing> readAll(xtf::XtfReader& reader) {
  std::vector<DriverPing> pings;
  DriverPing ping;
  while (reader.next(ping)) pings.push_back(ping);
  return pings;
}

std::string tempPath(const std::string& name) {
  return (std::filesystem::temp_directory_path() / ("sss_xtf_" + std::to_string(::getpid()) + "_" + name)).string();
}

TEST(XtfReader, RoundTripTwoChannelSixteenBitDegreesFromFile) {
  const xtf::XtfWriterOptions options = test::makeXtfOptions({100.0f}, 2, xtf::kNavUnitsLatLon);
  const std::string path = tempPath("roundtrip.xtf");
  {
    xtf::XtfWriter writer(path, options);
    ASSERT_TRUE(writer.isOpen());
    for (uint32_t p = 0; p < 5; ++p) ASSERT_TRUE(writer.write(test::makeXtfPing(options, p, 300)));
  }
  xtf::XtfReader reader(path);
  ASSERT_TRUE(reader.isOpen()) << reader.error();
  const std::vector<DriverPing> pings = readAll(reader);
  std::remove(path.c_str());
  ASSERT_EQ(pings.size(), 5u);
  for (uint32_t p = 0; p < 5; ++p) {
    const DriverPing& ping = pings[p];
    ASSERT_TRUE(ping.ping.complete());
    EXPECT_EQ(ping.ping.ping_number, p);
    EXPECT_EQ(ping.utime_us, test::kXtfFirstPingUs + test::kXtfPingPeriodUs * p);
    EXPECT_EQ(ping.sonar_utime_us, ping.utime_us);
    const sonar::SonarChannelRecord& port = *ping.ping.port;
    const sonar::SonarChannelRecord& starboard = *ping.ping.starboard;
    EXPECT_EQ(port.channel, sonar::kChannelPort);
    EXPECT_EQ(starboard.channel, sonar::kChannelStarboard);
    EXPECT_EQ(port.ping_time_us, ping.utime_us);
    ASSERT_EQ(port.samples.size(), 300u);
    ASSERT_EQ(starboard.samples.size(), 300u);
    for (size_t s = 0; s < 300; ++s) {
      ASSERT_EQ(port.samples[s], test::xtfSample(0, s, p, 2));
      ASSERT_EQ(starboard.samples[s], test::xtfSample(1, s, p, 2));
    }
    EXPECT_FLOAT_EQ(port.sound_speed_m_s, 1500.0f);  // stored 750: Isis' half speed
    EXPECT_NEAR(port.slantRangeM(300), 75.0, 1e-6);
    EXPECT_FLOAT_EQ(port.start_frequency_hz, 100000.0f);
    const uint16_t expected = sonar::kValidLatLon | sonar::kValidDepth | sonar::kValidAltitude |
                              sonar::kValidPitchRoll | sonar::kValidHeading | sonar::kValidSoundSpeed;
    EXPECT_EQ(port.validity, expected);
    EXPECT_DOUBLE_EQ(port.latitude_deg, 59.9 + 1e-5 * p);
    EXPECT_DOUBLE_EQ(port.longitude_deg, 10.7 + 2e-5 * p);
    EXPECT_NEAR(port.depth_m, 80.0, 1e-6);
    EXPECT_NEAR(port.altitude_m, 18.0, 1e-6);
    EXPECT_NEAR(port.heading_rad, 350.0 * M_PI / 180.0, 1e-6);
    EXPECT_NEAR(port.pitch_rad, 2.0 * M_PI / 180.0, 1e-6);   // nose up positive in both
    EXPECT_NEAR(port.roll_rad, -1.5 * M_PI / 180.0, 1e-6);   // starboard down positive in both
  }
  const xtf::XtfReaderCounters& counters = reader.counters();
  EXPECT_EQ(counters.pings, 5u);
  EXPECT_EQ(counters.corruptRecords(), 0u);
  EXPECT_EQ(counters.bytes_skipped, 0u);
  EXPECT_NE(reader.summary().find("16-bit"), std::string::npos);
  EXPECT_TRUE(reader.takeNewFaultMessages().empty());
}

TEST(XtfReader, MissingFileSaysWhy) {
  xtf::XtfReader reader("/nonexistent/x.xtf");
  EXPECT_FALSE(reader.isOpen());
  EXPECT_NE(reader.error().find("/nonexistent/x.xtf"), std::string::npos);
}

TEST(XtfReader, DualFrequencyEightBitSelectsPair) {
  // 4 channels: high-frequency pair first (CHANINFO 0/1, 410 kHz), low pair second (2/3, 120 kHz).
  const xtf::XtfWriterOptions options = test::makeXtfOptions({410.0f, 120.0f}, 1);
  const std::vector<uint8_t> bytes = test::makeXtfFile(options, 3, 150);
  for (const int pair : {0, 1}) {
    xtf::XtfReaderOptions reader_options;
    reader_options.pair_index = pair;
    xtf::XtfReader reader(bytes.data(), bytes.size(), reader_options);
    ASSERT_TRUE(reader.isOpen()) << reader.error();
    const std::vector<DriverPing> pings = readAll(reader);
    ASSERT_EQ(pings.size(), 3u);
    const size_t port_channel = pair == 0 ? 2 : 0;  // pair 0 = lowest frequency
    for (uint32_t p = 0; p < 3; ++p) {
      ASSERT_TRUE(pings[p].ping.complete());
      EXPECT_EQ(pings[p].ping.port->samples[17], test::xtfSample(port_channel, 17, p, 1));
      EXPECT_EQ(pings[p].ping.starboard->samples[17], test::xtfSample(port_channel + 1, 17, p, 1));
      EXPECT_FLOAT_EQ(pings[p].ping.port->start_frequency_hz, pair == 0 ? 120000.0f : 410000.0f);
    }
    EXPECT_NE(reader.summary().find("8-bit"), std::string::npos);
  }
  xtf::XtfReaderOptions missing;
  missing.pair_index = 2;
  xtf::XtfReader reader(bytes.data(), bytes.size(), missing);
  EXPECT_FALSE(reader.isOpen());
  EXPECT_NE(reader.error().find("2 side-scan pair"), std::string::npos);
}

TEST(XtfReader, EightChannelFileWithTwoHeaderBlocks) {
  const xtf::XtfWriterOptions options = test::makeXtfOptions({100.0f, 200.0f, 300.0f, 400.0f}, 2);
  const std::vector<uint8_t> bytes = test::makeXtfFile(options, 2, 50);
  xtf::XtfReaderOptions reader_options;
  reader_options.pair_index = 3;
  xtf::XtfReader reader(bytes.data(), bytes.size(), reader_options);
  ASSERT_TRUE(reader.isOpen()) << reader.error();
  EXPECT_EQ(reader.info().header_bytes, 2048u);
  const std::vector<DriverPing> pings = readAll(reader);
  ASSERT_EQ(pings.size(), 2u);
  EXPECT_EQ(pings[1].ping.starboard->samples[3], test::xtfSample(7, 3, 1, 2));
  EXPECT_EQ(reader.counters().bytes_before_first_packet, 0u);
}

TEST(XtfReader, MetresNavUnitsGiveNoLatLon) {
  const xtf::XtfWriterOptions options = test::makeXtfOptions({100.0f}, 2, xtf::kNavUnitsMetres);
  const std::vector<uint8_t> bytes = test::makeXtfFile(options, 2, 20);
  xtf::XtfReader reader(bytes.data(), bytes.size());
  ASSERT_TRUE(reader.isOpen()) << reader.error();
  const std::vector<DriverPing> pings = readAll(reader);
  ASSERT_EQ(pings.size(), 2u);
  EXPECT_FALSE(pings[0].ping.port->validity & sonar::kValidLatLon);
  EXPECT_EQ(pings[0].ping.port->latitude_deg, 0.0);
  EXPECT_TRUE(pings[0].ping.port->validity & sonar::kValidHeading);
  EXPECT_NE(reader.summary().find("metres"), std::string::npos);
}

TEST(XtfReader, SkipsOtherPacketTypesBySize) {
  const xtf::XtfWriterOptions options = test::makeXtfOptions({100.0f}, 2);
  std::vector<uint8_t> bytes = xtf::encodeFileHeader(options);
  for (uint32_t p = 0; p < 4; ++p) {
    test::appendBytes(bytes, xtf::encodeOtherPacket(3, 64));   // attitude
    test::appendBytes(bytes, xtf::encodeSonarPacket(options, test::makeXtfPing(options, p, 40)));
    // A notes packet whose body holds a 0xFACE lookalike: skipped by size, never parsed.
    std::vector<uint8_t> notes = xtf::encodeOtherPacket(1, 256);
    notes[100] = 0xCE;
    notes[101] = 0xFA;
    test::appendBytes(bytes, notes);
  }
  xtf::XtfReader reader(bytes.data(), bytes.size());
  ASSERT_TRUE(reader.isOpen());
  EXPECT_EQ(readAll(reader).size(), 4u);
  const xtf::XtfReaderCounters& counters = reader.counters();
  EXPECT_EQ(counters.packets_skipped, 8u);
  EXPECT_EQ(counters.skipped_by_type[3], 4u);
  EXPECT_EQ(counters.skipped_by_type[1], 4u);
  EXPECT_EQ(counters.corruptRecords(), 0u);
  EXPECT_EQ(counters.bytes_skipped, 0u);
}

TEST(XtfReader, ResyncsAfterGarbageTruncationAndImpossibleSizes) {
  const xtf::XtfWriterOptions options = test::makeXtfOptions({100.0f}, 2);
  std::vector<uint8_t> bytes = xtf::encodeFileHeader(options);
  const auto packet = [&](uint32_t p) { return xtf::encodeSonarPacket(options, test::makeXtfPing(options, p, 120)); };
  test::appendBytes(bytes, packet(0));
  test::appendBytes(bytes, std::vector<uint8_t>(333, 0x5A));  // garbage between packets
  test::appendBytes(bytes, packet(1));
  std::vector<uint8_t> impossible = packet(99);                 // NumBytesThisRecord = 2 GiB
  xtf::writeU32(impossible.data(), xtf::offset::kNumBytesThisRecord, 0x80000000u);
  test::appendBytes(bytes, impossible);
  test::appendBytes(bytes, packet(2));
  std::vector<uint8_t> cut = packet(98);                        // cut short by the next packet
  cut.resize(cut.size() / 2);
  test::appendBytes(bytes, cut);
  test::appendBytes(bytes, packet(3));
  std::vector<uint8_t> small = packet(97);                      // smaller than its own headers
  xtf::writeU32(small.data(), xtf::offset::kNumBytesThisRecord, 100);
  test::appendBytes(bytes, small);
  test::appendBytes(bytes, packet(4));
  std::vector<uint8_t> last = packet(96);                       // truncated by the end of the file
  last.resize(last.size() - 10);
  test::appendBytes(bytes, last);

  xtf::XtfReader reader(bytes.data(), bytes.size());
  ASSERT_TRUE(reader.isOpen());
  const std::vector<DriverPing> pings = readAll(reader);
  ASSERT_EQ(pings.size(), 5u);  // every good ping
  for (uint32_t p = 0; p < 5; ++p) {
    EXPECT_EQ(pings[p].ping.ping_number, p);
    EXPECT_EQ(pings[p].ping.port->samples[119], test::xtfSample(0, 119, p, 2));
  }
  const xtf::XtfReaderCounters& counters = reader.counters();
  EXPECT_EQ(counters.bad_headers, 2u);        // 2 GiB and 100-byte records
  EXPECT_EQ(counters.truncated_packets, 2u);  // cut by the next packet, cut by the end
  EXPECT_EQ(counters.sonar_decode_errors, 0u);
  EXPECT_EQ(counters.corruptRecords(), 4u);
  EXPECT_GE(counters.bytes_skipped, 333u);
  EXPECT_GE(counters.resyncs, 3u);
  EXPECT_EQ(reader.bytesRead(), bytes.size());
  const std::vector<std::string> faults = reader.takeNewFaultMessages();
  EXPECT_GE(faults.size(), 3u);  // garbage, bad header, truncated: once each
  EXPECT_TRUE(reader.takeNewFaultMessages().empty());
}

TEST(XtfReader, SmallReadChunksGiveTheSamePings) {
  const xtf::XtfWriterOptions options = test::makeXtfOptions({100.0f, 400.0f}, 1);
  std::vector<uint8_t> bytes = test::makeXtfFile(options, 6, 90);
  bytes.insert(bytes.begin() + 1024 + 500, 77, 0xFA);  // garbage inside the second packet
  for (const size_t chunk : {1, 7, 64, 4096}) {
    xtf::XtfReaderOptions reader_options;
    reader_options.read_chunk_bytes = chunk;
    xtf::XtfReader reader(bytes.data(), bytes.size(), reader_options);
    ASSERT_TRUE(reader.isOpen());
    EXPECT_EQ(readAll(reader).size(), 5u) << "chunk " << chunk;
    EXPECT_EQ(reader.counters().corruptRecords(), 1u) << "chunk " << chunk;
  }
}

TEST(XtfFuzzRegression, CorpusAndMutationsRunClean) {
  int files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(XTF_CORPUS_DIR)) {
    std::ifstream file(entry.path(), std::ios::binary);
    const std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
    test::fuzzXtf(bytes.data(), bytes.size());
    ++files;
  }
  EXPECT_GT(files, 0);
  // Deterministic mutations of a valid file's packets: flips, insertions, deletions.
  const xtf::XtfWriterOptions options = test::makeXtfOptions({100.0f}, 2);
  std::vector<uint8_t> valid = test::makeXtfFile(options, 8, 60);
  valid.push_back(0);  // the fuzz entry's last byte picks chunk and pair: pair 0
  ASSERT_EQ(test::fuzzXtf(valid.data(), valid.size()), 8);
  std::mt19937 rng(12345);
  for (int round = 0; round < 300; ++round) {
    std::vector<uint8_t> mutated = valid;
    const int edits = 1 + static_cast<int>(rng() % 8);
    for (int e = 0; e < edits; ++e) {
      const size_t pos = 1024 + rng() % (mutated.size() - 1025);  // keep the file header
      switch (rng() % 3) {
        case 0: mutated[pos] = static_cast<uint8_t>(rng()); break;
        case 1: mutated.insert(mutated.begin() + static_cast<std::ptrdiff_t>(pos), static_cast<uint8_t>(rng())); break;
        default: mutated.erase(mutated.begin() + static_cast<std::ptrdiff_t>(pos)); break;
      }
    }
    mutated.back() = 0;
    const int pings = test::fuzzXtf(mutated.data(), mutated.size());
    EXPECT_LE(pings, 8);
    EXPECT_GE(pings, 8 - 2 * edits);  // each edit costs at most two pings
  }
}

}  // namespace
}  // namespace sss
