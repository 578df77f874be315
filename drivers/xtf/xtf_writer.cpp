// XTF writer for tests and fuzz seeds, see xtf_writer.hpp.
#include "drivers/xtf/xtf_writer.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <ctime>

namespace sss::xtf {

namespace {

void writeString(uint8_t* bytes, const std::string& text, size_t field_size) {
  std::memcpy(bytes, text.data(), std::min(text.size(), field_size));  // full fields carry no zero
}

void writeSample(uint8_t* bytes, float value, uint16_t bytes_per_sample) {
  const double v = std::isfinite(value) ? std::max(0.0, std::round(static_cast<double>(value))) : 0.0;
  switch (bytes_per_sample) {
    case 1: bytes[0] = static_cast<uint8_t>(std::min(v, 255.0)); break;
    case 2: writeU16(bytes, 0, static_cast<uint16_t>(std::min(v, 65535.0))); break;
    default: writeU32(bytes, 0, static_cast<uint32_t>(std::min(v, 4294967295.0))); break;
  }
}

}  // namespace

std::vector<uint8_t> encodeFileHeader(const XtfWriterOptions& options) {
  const size_t end = kChannelInfoOffset + kChannelInfoBytes * options.channels.size();
  const size_t size = std::max(kFileHeaderBlockBytes, (end + kFileHeaderBlockBytes - 1) / kFileHeaderBlockBytes * kFileHeaderBlockBytes);
  std::vector<uint8_t> bytes(size, 0);
  bytes[0] = kXtfFileFormat;
  bytes[1] = 1;  // SystemType: "set to 1"
  writeString(bytes.data() + 2, options.recording_program, 8);
  writeString(bytes.data() + 10, "1", 8);
  writeString(bytes.data() + 18, options.sonar_name, 16);
  writeU16(bytes.data(), offset::kNavUnits, options.nav_units);
  writeU16(bytes.data(), 34, options.sonar_type);
  uint16_t sonar = 0;
  uint16_t bathymetry = 0;
  for (const XtfWriterChannel& c : options.channels) (c.type_of_channel == kChannelBathymetry ? bathymetry : sonar)++;
  writeU16(bytes.data(), offset::kNumberOfSonarChannels, sonar);
  writeU16(bytes.data(), offset::kNumberOfBathymetryChannels, bathymetry);
  for (size_t i = 0; i < options.channels.size(); ++i) {
    const XtfWriterChannel& c = options.channels[i];
    uint8_t* block = bytes.data() + kChannelInfoOffset + kChannelInfoBytes * i;
    block[offset::kTypeOfChannel] = c.type_of_channel;
    block[offset::kSubChannelNumber] = static_cast<uint8_t>(i);
    writeU16(block, offset::kCorrectionFlags, 1);  // slant range
    writeU16(block, offset::kUniPolar, c.uni_polar);
    writeU16(block, offset::kBytesPerSample, c.bytes_per_sample);
    writeU32(block, offset::kLegacyNumSamples, 1024);  // pyxtf: "for compatibility with old viewers"
    writeString(block + offset::kChannelName, c.name, 16);
    writeF32(block, offset::kChannelFrequency, c.frequency);
    block[offset::kSampleFormat] = c.sample_format;
  }
  return bytes;
}

void encodePingLayback(float layback_m, uint8_t* p) { writeF32(p, offset::kLayback, layback_m); }

void encodePingNavigation(const XtfPingInput& ping, uint8_t* p) {
  writeF64(p, offset::kSensorY, ping.sensor_y);
  writeF64(p, offset::kSensorX, ping.sensor_x);
  writeF32(p, offset::kSensorDepth, ping.depth_m);
  writeF32(p, offset::kSensorPitch, ping.pitch_deg);
  writeF32(p, offset::kSensorRoll, ping.roll_deg);
  writeF32(p, offset::kSensorHeading, ping.heading_deg);
}

std::vector<uint8_t> encodeSonarPacket(const XtfWriterOptions& options, const XtfPingInput& ping) {
  size_t size = kPingHeaderBytes;
  for (const XtfChannelData& channel : ping.channels) {
    const uint16_t bytes_per_sample = channel.channel_number < options.channels.size()
                                          ? options.channels[channel.channel_number].bytes_per_sample
                                          : uint16_t{1};
    size += kPingChannelHeaderBytes + channel.samples.size() * bytes_per_sample;
  }
  std::vector<uint8_t> bytes(size, 0);
  uint8_t* p = bytes.data();
  writeU16(p, offset::kMagic, kXtfMagic);
  p[offset::kHeaderType] = kHeaderSonar;
  writeU16(p, offset::kNumChansToFollow, static_cast<uint16_t>(ping.channels.size()));
  writeU32(p, offset::kNumBytesThisRecord, static_cast<uint32_t>(size));

  const int64_t seconds = ping.ping_time_us / 1000000;
  const std::time_t t = static_cast<std::time_t>(seconds);
  std::tm utc{};
  gmtime_r(&t, &utc);
  writeU16(p, offset::kYear, static_cast<uint16_t>(utc.tm_year + 1900));
  p[offset::kMonth] = static_cast<uint8_t>(utc.tm_mon + 1);
  p[offset::kDay] = static_cast<uint8_t>(utc.tm_mday);
  p[offset::kHour] = static_cast<uint8_t>(utc.tm_hour);
  p[offset::kMinute] = static_cast<uint8_t>(utc.tm_min);
  p[offset::kSecond] = static_cast<uint8_t>(utc.tm_sec);
  p[offset::kHSeconds] = static_cast<uint8_t>((ping.ping_time_us % 1000000) / 10000);
  writeU16(p, offset::kJulianDay, static_cast<uint16_t>(utc.tm_yday + 1));
  writeU32(p, offset::kPingNumber, ping.ping_number);
  writeF32(p, offset::kSoundVelocity, ping.sound_velocity);
  writeF32(p, offset::kSensorPrimaryAltitude, ping.altitude_m);
  writeF64(p, offset::kShipY, ping.ship_y);
  writeF64(p, offset::kShipX, ping.ship_x);
  encodePingLayback(ping.layback_m, p);
  encodePingNavigation(ping, p);

  size_t at = kPingHeaderBytes;
  for (const XtfChannelData& channel : ping.channels) {
    const uint16_t bytes_per_sample = channel.channel_number < options.channels.size()
                                          ? options.channels[channel.channel_number].bytes_per_sample
                                          : uint16_t{1};
    uint8_t* header = p + at;
    writeU16(header, offset::kChannelNumber, channel.channel_number);
    writeF32(header, offset::kSlantRange, channel.slant_range_m);
    writeF32(header, offset::kTimeDelay, channel.time_delay_s);
    const float duration_s = channel.time_duration_s > 0.0f || ping.sound_velocity <= 0.0f
                                 ? channel.time_duration_s
                                 : channel.slant_range_m / ping.sound_velocity;
    writeF32(header, offset::kTimeDuration, duration_s);
    if (channel.channel_number < options.channels.size()) {
      writeU16(header, offset::kChanFrequency, static_cast<uint16_t>(options.channels[channel.channel_number].frequency));
    }
    writeU32(header, offset::kNumSamples, static_cast<uint32_t>(channel.samples.size()));
    writeU16(header, offset::kWeight, static_cast<uint16_t>(channel.weight));
    at += kPingChannelHeaderBytes;
    for (const float sample : channel.samples) {
      writeSample(p + at, sample, bytes_per_sample);
      at += bytes_per_sample;
    }
  }
  return bytes;
}

std::vector<uint8_t> encodeOtherPacket(uint8_t header_type, size_t total_bytes) {
  std::vector<uint8_t> bytes(std::max(total_bytes, kPacketStartBytes), 0);
  writeU16(bytes.data(), offset::kMagic, kXtfMagic);
  bytes[offset::kHeaderType] = header_type;
  writeU32(bytes.data(), offset::kNumBytesThisRecord, static_cast<uint32_t>(bytes.size()));
  return bytes;
}

XtfWriter::XtfWriter(const std::string& path, XtfWriterOptions options) : options_(std::move(options)) {
  file_.reset(std::fopen(path.c_str(), "wb"));
  if (file_ && !writeBytes(encodeFileHeader(options_))) file_.reset();
}

bool XtfWriter::write(const XtfPingInput& ping) { return writeBytes(encodeSonarPacket(options_, ping)); }

bool XtfWriter::writeBytes(const std::vector<uint8_t>& bytes) {
  return file_ && std::fwrite(bytes.data(), 1, bytes.size(), file_.get()) == bytes.size();
}

}  // namespace sss::xtf
