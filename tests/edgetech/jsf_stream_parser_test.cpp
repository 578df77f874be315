// JSF framing: every good message survives garbage, bad markers, impossible byte counts,
// truncation and arbitrary chunking; faults are counted. Plus the fuzz regression corpus.
#include "drivers/edgetech/jsf_stream_parser.hpp"

#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>

#include "drivers/edgetech/jsf_file_reader.hpp"
#include "jsf_fuzz_target.hpp"
#include "jsf_test_data.hpp"

namespace sss::edgetech {
namespace {

std::vector<JsfMessage> parseAll(const std::vector<uint8_t>& stream, size_t chunk, JsfStreamParser& parser) {
  std::vector<JsfMessage> out;
  for (size_t offset = 0; offset < stream.size(); offset += chunk) {
    parser.feed(stream.data() + offset, std::min(chunk, stream.size() - offset), out);
  }
  parser.finish(out);
  return out;
}

std::vector<uint32_t> pingNumbers(const std::vector<JsfMessage>& messages) {
  std::vector<uint32_t> numbers;
  for (const JsfMessage& m : messages) {
    const sss::core::Result<SonarChannelRecord> r = decodeSonarData(m.header, m.body.data(), m.body.size());
    numbers.push_back(r.ok() ? r->ping_number : 0);
  }
  return numbers;
}

TEST(JsfStreamParser, CleanStreamInAnyChunkingGivesEveryMessage) {
  const auto messages = test::makeMessages(10);
  const std::vector<uint8_t> stream = test::concatenate(messages);
  for (size_t chunk : {size_t(1), size_t(7), size_t(1000), stream.size()}) {
    JsfStreamParser parser;
    const std::vector<JsfMessage> out = parseAll(stream, chunk, parser);
    ASSERT_EQ(out.size(), 20u) << "chunk " << chunk;
    EXPECT_EQ(out[5].stream_offset, test::concatenate({messages.begin(), messages.begin() + 5}).size());
    EXPECT_EQ(parser.counters().bytes_skipped, 0u);
    EXPECT_EQ(parser.counters().truncated_messages, 0u);
    EXPECT_EQ(parser.counters().resyncs, 0u);
  }
}

TEST(JsfStreamParser, ResyncsAfterGarbageBetweenMessages) {
  auto messages = test::makeMessages(4);
  std::vector<uint8_t> garbage(333);
  std::mt19937 rng(7);
  for (auto& g : garbage) g = static_cast<uint8_t>(rng());
  garbage[10] = 0x01;  // a lone start-marker half inside the garbage
  garbage[11] = 0x16;
  messages.insert(messages.begin() + 3, garbage);
  JsfStreamParser parser;
  const std::vector<JsfMessage> out = parseAll(test::concatenate(messages), 64, parser);
  ASSERT_EQ(out.size(), 8u);
  EXPECT_EQ(pingNumbers(out), (std::vector<uint32_t>{1000, 1000, 1001, 1001, 1002, 1002, 1003, 1003}));
  EXPECT_EQ(parser.counters().bytes_skipped, 333u);
  EXPECT_GE(parser.counters().resyncs, 1u);
  const auto faults = parser.takeNewFaultMessages();
  ASSERT_FALSE(faults.empty());
  EXPECT_NE(faults[0].find("JSF stream at byte"), std::string::npos);
  EXPECT_TRUE(parser.takeNewFaultMessages().empty());  // reported once
}

TEST(JsfStreamParser, WrongStartMarkerLosesOnlyThatMessage) {
  auto messages = test::makeMessages(3);
  messages[2][1] = 0x17;  // ping 1001 port: marker 0x1701
  JsfStreamParser parser;
  const std::vector<JsfMessage> out = parseAll(test::concatenate(messages), 100, parser);
  EXPECT_EQ(pingNumbers(out), (std::vector<uint32_t>{1000, 1000, 1001, 1002, 1002}));
  EXPECT_EQ(parser.counters().bytes_skipped, messages[2].size());
}

TEST(JsfStreamParser, ImpossibleByteCountIsSkippedWithoutAllocating) {
  auto messages = test::makeMessages(3);
  const int32_t huge = 2147483647;
  std::memcpy(messages[2].data() + 12, &huge, 4);
  JsfStreamParser parser;
  const std::vector<JsfMessage> out = parseAll(test::concatenate(messages), 4096, parser);
  EXPECT_EQ(pingNumbers(out), (std::vector<uint32_t>{1000, 1000, 1001, 1002, 1002}));
  EXPECT_EQ(parser.counters().bad_headers, 1u);
  const auto faults = parser.takeNewFaultMessages();
  ASSERT_EQ(faults.size(), 1u);  // one report for the whole skipped run (header and body)
  EXPECT_NE(faults[0].find("byte count 2147483647 is impossible"), std::string::npos);
}

TEST(JsfStreamParser, SampleCountDisagreeingWithByteCountIsABadHeader) {
  auto messages = test::makeMessages(2);
  messages[1][16 + 114] ^= 0x04;  // sample count changed, byte count not
  JsfStreamParser parser;
  const std::vector<JsfMessage> out = parseAll(test::concatenate(messages), 4096, parser);
  EXPECT_EQ(pingNumbers(out), (std::vector<uint32_t>{1000, 1001, 1001}));
  EXPECT_EQ(parser.counters().bad_headers, 1u);
}

TEST(JsfStreamParser, TruncatedMessageIsDroppedAndTheNextOneKept) {
  auto messages = test::makeMessages(3);
  messages[2].resize(messages[2].size() / 2);  // ping 1001 port cut in half
  for (size_t chunk : {size_t(1), size_t(300), size_t(100000)}) {
    JsfStreamParser parser;
    const std::vector<JsfMessage> out = parseAll(test::concatenate(messages), chunk, parser);
    EXPECT_EQ(pingNumbers(out), (std::vector<uint32_t>{1000, 1000, 1001, 1002, 1002})) << "chunk " << chunk;
    EXPECT_EQ(parser.counters().truncated_messages, 1u);
  }
}

TEST(JsfStreamParser, StreamEndingInsideAMessageCountsItTruncated) {
  auto messages = test::makeMessages(2);
  messages[3].resize(100);
  JsfStreamParser parser;
  const std::vector<JsfMessage> out = parseAll(test::concatenate(messages), 50, parser);
  EXPECT_EQ(out.size(), 3u);
  EXPECT_EQ(parser.counters().truncated_messages, 1u);
}

TEST(JsfStreamParser, SamplesThatLookLikeAHeaderNeverLoseTheMessage) {
  // Ping 1000 port carries, inside its samples, the bytes of a complete plausible header.
  auto messages = test::makeMessages(2);
  const std::vector<uint8_t> fake = test::concatenate({test::makeMessages(1)[0]});
  std::copy(fake.begin(), fake.begin() + 16 + 240, messages[0].begin() + 16 + 240 + 100);
  for (size_t chunk : {size_t(1), size_t(333), size_t(1 << 20)}) {
    JsfStreamParser parser;
    const std::vector<JsfMessage> out = parseAll(test::concatenate(messages), chunk, parser);
    ASSERT_EQ(out.size(), 4u) << "chunk " << chunk;
    EXPECT_EQ(out[0].body.size(), messages[0].size() - 16);
    EXPECT_EQ(parser.counters().truncated_messages, 0u);
  }
}

TEST(JsfStreamParser, LiveStreamHandsOutAMessageAsSoonAsItsLastByteArrives) {
  const auto messages = test::makeMessages(1);
  JsfStreamParser parser;
  std::vector<JsfMessage> out;
  parser.feed(messages[0].data(), messages[0].size() - 1, out);
  EXPECT_TRUE(out.empty());
  parser.feed(messages[0].data() + messages[0].size() - 1, 1, out);
  EXPECT_EQ(out.size(), 1u);  // no waiting for the next header
}

TEST(JsfFileReader, ReadsEveryMessageOfAFileAndReportsAMissingFile) {
  const auto messages = test::makeMessages(50, 3000);
  const std::string path = ::testing::TempDir() + "/reader_test.jsf";
  {
    std::ofstream file(path, std::ios::binary);
    const auto bytes = test::concatenate(messages);
    file.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  }
  JsfFileReader reader(path);
  ASSERT_TRUE(reader.isOpen()) << reader.error();
  JsfMessage message;
  int count = 0;
  while (reader.next(message)) ++count;
  EXPECT_EQ(count, 100);
  EXPECT_EQ(reader.bytesRead(), reader.fileSize());
  JsfFileReader missing("/nonexistent/file.jsf");
  EXPECT_FALSE(missing.isOpen());
  EXPECT_NE(missing.error().find("cannot open JSF file '/nonexistent/file.jsf'"), std::string::npos);
}

TEST(JsfFuzzRegression, CorpusAndMutationsRunClean) {
  int files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(JSF_CORPUS_DIR)) {
    std::ifstream file(entry.path(), std::ios::binary);
    const std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
    test::fuzzJsf(bytes.data(), bytes.size());
    ++files;
  }
  EXPECT_GT(files, 0);
  {
    // The older side-scan message 82, port and starboard (bytes written from its public layout):
    // both framed by their own sample count and decoded.
    std::ifstream file(std::string(JSF_CORPUS_DIR) + "/old_side_scan_82", std::ios::binary);
    const std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
    EXPECT_EQ(test::fuzzJsf(bytes.data(), bytes.size()), 2);
  }
  // Deterministic mutations of a valid stream: flips, insertions, deletions.
  const std::vector<uint8_t> valid = test::concatenate(test::makeMessages(6, 200));
  EXPECT_EQ(test::fuzzJsf(valid.data(), valid.size()), 12);
  std::mt19937 rng(12345);
  for (int round = 0; round < 300; ++round) {
    std::vector<uint8_t> mutated = valid;
    const int edits = 1 + static_cast<int>(rng() % 8);
    for (int e = 0; e < edits && !mutated.empty(); ++e) {
      const size_t pos = rng() % mutated.size();
      switch (rng() % 3) {
        case 0: mutated[pos] = static_cast<uint8_t>(rng()); break;
        case 1: mutated.insert(mutated.begin() + static_cast<std::ptrdiff_t>(pos), static_cast<uint8_t>(rng())); break;
        default: mutated.erase(mutated.begin() + static_cast<std::ptrdiff_t>(pos)); break;
      }
    }
    const int decoded = test::fuzzJsf(mutated.data(), mutated.size());
    EXPECT_LE(decoded, 12);
    EXPECT_GE(decoded, 12 - 2 * edits);  // each edit costs at most two messages
  }
}

}  // namespace
}  // namespace sss::edgetech
