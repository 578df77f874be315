// NMEA stream framing: checksums, line endings, garbage, chunking, over-long lines, binary.
#include "drivers/ins/nmea_stream_parser.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace sss::ins {
namespace {

const std::string kHdt = "$HEHDT,116.581,T*25\r\n";
const std::string kAtt = "$PIXSE,ATITUD,-1.641,-0.490*6D\r\n";
const std::string kPos = "$PIXSE,POSITI,53.10245714,8.83994382,-0.115*71\r\n";

std::vector<std::string> feedByteByByte(NmeaStreamParser& parser, const std::string& bytes) {
  std::vector<std::string> out;
  for (char c : bytes) {
    const auto byte = static_cast<uint8_t>(c);
    parser.feed(&byte, 1, out);
  }
  return out;
}

TEST(NmeaStreamParser, YieldsVerifiedBodies) {
  NmeaStreamParser parser;
  const auto sentences = parser.feed(kHdt + kAtt + kPos);
  ASSERT_EQ(sentences.size(), 3u);
  EXPECT_EQ(sentences[0], "HEHDT,116.581,T");
  EXPECT_EQ(sentences[1], "PIXSE,ATITUD,-1.641,-0.490");
  EXPECT_EQ(parser.counters().sentences, 3);
  EXPECT_EQ(parser.rejectedSentences(), 0);
}

TEST(NmeaStreamParser, RejectsAndCountsChecksumFailure) {
  NmeaStreamParser parser;
  const auto sentences = parser.feed("$HEHDT,116.581,T*26\r\n" + kAtt + "$HEHDT,1,T*2\r\n");
  ASSERT_EQ(sentences.size(), 1u);
  EXPECT_EQ(sentences[0], "PIXSE,ATITUD,-1.641,-0.490");
  EXPECT_EQ(parser.counters().bad_checksum, 2);
  // The first message names the offset, the received and the computed checksum.
  EXPECT_NE(parser.firstErrors().bad_checksum.find("byte 0"), std::string::npos);
  EXPECT_NE(parser.firstErrors().bad_checksum.find("*26"), std::string::npos);
  EXPECT_NE(parser.firstErrors().bad_checksum.find("25"), std::string::npos);
}

TEST(NmeaStreamParser, AcceptsLowerCaseChecksumHex) {
  NmeaStreamParser parser;
  EXPECT_EQ(parser.feed("$PIXSE,ATITUD,-1.641,-0.490*6d\r\n").size(), 1u);
}

TEST(NmeaStreamParser, RejectsAndCountsMissingChecksum) {
  NmeaStreamParser parser;
  const auto sentences = parser.feed("$HEHDT,116.581,T\r\n" + kAtt);
  EXPECT_EQ(sentences.size(), 1u);
  EXPECT_EQ(parser.counters().missing_checksum, 1);
  EXPECT_FALSE(parser.firstErrors().missing_checksum.empty());
}

TEST(NmeaStreamParser, HandlesEveryLineEnding) {
  NmeaStreamParser parser;
  const std::string body = "$HEHDT,116.581,T*25";
  const auto sentences =
      parser.feed(body + "\r\n" + body + "\n" + body + "\r" + body + "\n\r" + body + "\r\n\r\n");
  EXPECT_EQ(sentences.size(), 5u);
  EXPECT_EQ(parser.rejectedSentences(), 0);
  EXPECT_EQ(parser.counters().garbage_bytes, 0);
}

TEST(NmeaStreamParser, ResyncsAfterGarbageBetweenSentences) {
  const std::string clean = kHdt + kAtt + kPos;
  const std::string dirty =
      "noise\x01\xff" + kHdt + "#garbage*12\r\n" + kAtt + std::string("\0\0\0", 3) + kPos + "x";
  NmeaStreamParser clean_parser, dirty_parser;
  const auto expected = clean_parser.feed(clean);
  EXPECT_EQ(dirty_parser.feed(dirty), expected);
  EXPECT_EQ(dirty_parser.rejectedSentences(), 0);
  EXPECT_EQ(dirty_parser.counters().garbage_bytes, 7 + 11 + 3 + 1);
  EXPECT_FALSE(dirty_parser.firstErrors().garbage.empty());
}

TEST(NmeaStreamParser, ByteByByteAndEverySplitGiveIdenticalOutput) {
  const std::string stream = "junk" + kHdt + kAtt + "$PIXSE,BAD*00\r\n" + kPos + "$HEHDT,1";
  NmeaStreamParser whole;
  const auto expected = whole.feed(stream);
  ASSERT_EQ(expected.size(), 3u);

  NmeaStreamParser single;
  EXPECT_EQ(feedByteByByte(single, stream), expected);
  EXPECT_EQ(single.counters().bad_checksum, whole.counters().bad_checksum);
  EXPECT_EQ(single.counters().garbage_bytes, whole.counters().garbage_bytes);

  for (size_t split = 0; split <= stream.size(); ++split) {
    NmeaStreamParser parser;
    auto out = parser.feed(stream.substr(0, split));
    for (auto& s : parser.feed(stream.substr(split))) out.push_back(s);
    EXPECT_EQ(out, expected) << "split at " << split;
  }
}

TEST(NmeaStreamParser, DropsOverlongLineAndResyncsAtNextDollar) {
  NmeaStreamParser parser;  // 256-byte limit
  const std::string overlong = "$PIXSE," + std::string(400, 'A') + "*00\r\n";
  const auto sentences = parser.feed(overlong + kHdt);
  ASSERT_EQ(sentences.size(), 1u);
  EXPECT_EQ(sentences[0], "HEHDT,116.581,T");
  EXPECT_EQ(parser.counters().overlong, 1);
  EXPECT_NE(parser.firstErrors().overlong.find("256"), std::string::npos);
}

TEST(NmeaStreamParser, LongestAllowedLineIsAccepted) {
  NmeaStreamOptions options;
  options.max_sentence_bytes = 40;
  // '$' + body + "*HH" + CR LF = 40 bytes: exactly the limit.
  std::string body = "PIXSE,ATITUD,1.000,2.000";
  body += std::string(34 - body.size(), '0');
  NmeaStreamParser parser(options);
  unsigned checksum = 0;
  for (unsigned char c : body) checksum ^= c;
  char hex[3];
  std::snprintf(hex, sizeof(hex), "%02X", checksum);
  const std::string line = "$" + body + "*" + hex + "\r\n";
  EXPECT_EQ(parser.feed(line).size(), 1u);
  EXPECT_EQ(parser.counters().overlong, 0);
  EXPECT_EQ(parser.feed("$" + body + "0*" + hex + "\r\n").size(), 0u);
  EXPECT_EQ(parser.counters().overlong, 1);
}

TEST(NmeaStreamParser, DropsSentenceWithEmbeddedNulOrBinary) {
  NmeaStreamParser parser;
  const std::string with_nul = std::string("$HEHDT,11\0" "6.581,T*25\r\n", 22);
  const auto sentences = parser.feed(with_nul + "$HEHDT,\x80\x81*00\r\n" + kAtt);
  ASSERT_EQ(sentences.size(), 1u);
  EXPECT_EQ(parser.counters().bad_character, 2);
  EXPECT_NE(parser.firstErrors().bad_character.find("0x00"), std::string::npos);
}

TEST(NmeaStreamParser, CountsSentenceCutByNewDollar) {
  NmeaStreamParser parser;
  const auto sentences = parser.feed("$PIXSE,ATITUD,-1.6" + kHdt);
  ASSERT_EQ(sentences.size(), 1u);
  EXPECT_EQ(parser.counters().truncated, 1);
}

TEST(NmeaStreamParser, FlushTerminatesDatagramWithoutLineEnd) {
  NmeaStreamParser parser;
  EXPECT_TRUE(parser.feed("$HEHDT,116.581,T*25").empty());
  std::vector<std::string> out;
  parser.flush(out);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0], "HEHDT,116.581,T");
}

}  // namespace
}  // namespace sss::ins
