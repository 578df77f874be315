// XTF reader: file header, packet framing with resynchronisation, sonar packets to DriverPing;
// see xtf_reader.hpp.
#include "drivers/xtf/xtf_reader.hpp"

#include <algorithm>
#include <cerrno>
#include <cstring>

namespace sss::xtf {

namespace {
constexpr size_t kNotFound = static_cast<size_t>(-1);

std::string navUnitsName(uint16_t units) {
  if (units == kNavUnitsLatLon) return "lat/long degrees";
  if (units == kNavUnitsMetres) return "metres (projected)";
  return "unknown (" + std::to_string(units) + ")";
}
}  // namespace

XtfReader::XtfReader(const std::string& path, XtfReaderOptions options) : options_(options), source_name_(path) {
  file_.reset(std::fopen(path.c_str(), "rb"));
  if (!file_) {
    error_ = "cannot open XTF file '" + path + "': " + std::strerror(errno);
    return;
  }
  openWith();
}

XtfReader::XtfReader(const uint8_t* data, size_t size, XtfReaderOptions options)
    : options_(options), memory_(data, data + size), source_name_("<memory>") {
  openWith();
}

size_t XtfReader::readSome(uint8_t* destination, size_t size) {
  if (file_) return std::fread(destination, 1, size, file_.get());
  const size_t count = std::min(size, memory_.size() - memory_position_);
  if (count > 0) std::memcpy(destination, memory_.data() + memory_position_, count);
  memory_position_ += count;
  return count;
}

bool XtfReader::ensure(size_t count) {
  if (buffer_.size() - start_ >= count) return true;
  if (end_of_data_) return false;
  if (start_ > 0) {
    buffer_.erase(buffer_.begin(), buffer_.begin() + static_cast<std::ptrdiff_t>(start_));
    start_ = 0;
  }
  while (buffer_.size() < count && !end_of_data_) {
    const size_t want = std::max(count - buffer_.size(), std::max<size_t>(options_.read_chunk_bytes, 1));
    const size_t old_size = buffer_.size();
    buffer_.resize(old_size + want);
    const size_t got = readSome(buffer_.data() + old_size, want);
    buffer_.resize(old_size + got);
    bytes_read_ += got;
    if (got == 0) end_of_data_ = true;
  }
  return buffer_.size() >= count;
}

void XtfReader::consume(size_t count) {
  start_ += count;
  consumed_offset_ += count;
}

void XtfReader::openWith() {
  if (!ensure(kFileHeaderBlockBytes)) {
    error_ = "XTF '" + source_name_ + "': " + std::to_string(buffer_.size()) +
             " bytes, shorter than the 1024-byte file header; not an XTF file";
    return;
  }
  const size_t header_bytes = requiredHeaderBytes(buffer_.data(), buffer_.size());
  if (header_bytes > kFileHeaderBlockBytes) ensure(header_bytes);
  sss::core::Result<XtfFileInfo> header = parseFileHeader(buffer_.data(), buffer_.size());
  if (!header) {
    error_ = "XTF '" + source_name_ + "': " + header.message();
    return;
  }
  info_ = std::move(*header);
  if (options_.nav_units >= 0) info_.nav_units = static_cast<uint16_t>(options_.nav_units);
  const std::vector<ChannelPair> pairs = sideScanPairs(info_);
  if (pairs.empty()) {
    error_ = "XTF '" + source_name_ + "': no side-scan channel among its " + std::to_string(info_.channels.size()) +
             " channel(s) (" + std::to_string(info_.bathymetry_channels) +
             " bathymetry): a multibeam or sub-bottom record; sss-slam needs a side-scan port/starboard pair";
    return;
  }
  if (options_.pair_index < 0 || static_cast<size_t>(options_.pair_index) >= pairs.size()) {
    error_ = "XTF '" + source_name_ + "': " + std::to_string(pairs.size()) + " side-scan pair(s) among " +
             std::to_string(info_.channels.size()) + " channels, pair " + std::to_string(options_.pair_index) +
             " requested; choose pair_index below " + std::to_string(pairs.size());
    return;
  }
  pair_ = pairs[static_cast<size_t>(options_.pair_index)];
  for (const int index : {pair_.port, pair_.starboard}) {
    if (index >= 0 && info_.channels[static_cast<size_t>(index)].sample_type == SampleType::kUnsupported) {
      const XtfChannelInfo& c = info_.channels[static_cast<size_t>(index)];
      error_ = "XTF '" + source_name_ + "': channel " + std::to_string(index) + " stores " +
               std::to_string(c.bytes_per_sample) + "-byte samples in format " + std::to_string(c.sample_format) +
               ", which this reader does not decode";
      return;
    }
  }
  decode_.port_channel = pair_.port;
  decode_.starboard_channel = pair_.starboard;
  decode_.subsystem = static_cast<uint8_t>(sss::sonar::kSubsystemSideScanLow + std::min(options_.pair_index, 1));
  decode_.fallback_sound_speed_m_s = options_.fallback_sound_speed_m_s;
  decode_.polar_as_signed = options_.polar_as_signed;
  decode_.apply_layback = options_.apply_layback;
  consume(std::min(info_.header_bytes, buffer_.size() - start_));
  open_ = true;
}

bool XtfReader::plausibleHeaderAt(size_t position) const {
  if (buffer_.size() - position < kPacketStartBytes) return false;
  const std::optional<PacketHeader> header = decodePacketHeader(buffer_.data() + position);
  if (!header || header->num_bytes < kPacketStartBytes || header->num_bytes > options_.max_record_bytes) return false;
  if (header->header_type == kHeaderSonar) {
    // A sonar packet holds its 256-byte ping header and one 64-byte header per channel.
    if (header->num_chans_to_follow == 0 || header->num_chans_to_follow > kMaxChannels) return false;
    if (header->num_bytes < kPingHeaderBytes + kPingChannelHeaderBytes * header->num_chans_to_follow) return false;
  }
  return true;
}

size_t XtfReader::findPlausibleHeader(size_t from, size_t to) const {
  to = std::min(to, buffer_.size());
  for (size_t position = from; position + 1 < to; ++position) {
    if (buffer_[position] == (kXtfMagic & 0xFF) && buffer_[position + 1] == (kXtfMagic >> 8) &&
        plausibleHeaderAt(position)) {
      return position;
    }
  }
  return kNotFound;
}

void XtfReader::skipBytes(size_t count, const std::string& kind) {
  if (!first_packet_found_) {
    // Before the first packet: a header longer than its channel count implies, not corruption.
    counters_.bytes_before_first_packet += count;
  } else {
    if (!skipping_) {
      skipping_ = true;
      ++counters_.resyncs;
      reportOnce(kind, "XTF '" + source_name_ + "' at byte " + std::to_string(consumed_offset_) +
                           ": bytes that belong to no packet; skipping to the next 0xFACE packet");
    }
    counters_.bytes_skipped += count;
  }
  consume(count);
}

std::vector<XtfNavigationRecord> XtfReader::takeNavigation() {
  std::vector<XtfNavigationRecord> records;
  records.swap(navigation_);
  return records;
}

bool XtfReader::next(sss::sonar::DriverPing& ping) {
  if (!open_) return false;
  while (true) {
    if (!ensure(kPacketStartBytes)) {
      const size_t rest = buffer_.size() - start_;
      if (rest >= 2 && readU16(buffer_.data(), start_) == kXtfMagic) {
        ++counters_.truncated_packets;
        reportOnce("truncated", "XTF '" + source_name_ + "' at byte " + std::to_string(consumed_offset_) +
                                    ": the data ends inside a packet header; dropped");
        consume(rest);
      } else if (rest > 0) {
        skipBytes(rest, "garbage");
      }
      return false;
    }
    if (!plausibleHeaderAt(start_)) {
      if (readU16(buffer_.data(), start_) == kXtfMagic) {
        const PacketHeader header = *decodePacketHeader(buffer_.data() + start_);
        ++counters_.bad_headers;
        reportOnce("bad_header", "XTF '" + source_name_ + "' packet at byte " + std::to_string(consumed_offset_) +
                                     ": type " + std::to_string(header.header_type) + " with " +
                                     std::to_string(header.num_bytes) + " bytes and " +
                                     std::to_string(header.num_chans_to_follow) + " channels is impossible (limit " +
                                     std::to_string(options_.max_record_bytes) + " bytes); skipping to the next packet");
        skipBytes(1, "garbage");
        continue;
      }
      // Jump to the next candidate magic in what is buffered (keep a last byte that may start one).
      size_t next = start_ + 1;
      while (next + 1 < buffer_.size() &&
             !(buffer_[next] == (kXtfMagic & 0xFF) && buffer_[next + 1] == (kXtfMagic >> 8))) {
        ++next;
      }
      skipBytes(next - start_, "garbage");
      continue;
    }
    const PacketHeader header = *decodePacketHeader(buffer_.data() + start_);
    const size_t size = header.num_bytes;
    if (!ensure(size)) {
      // The data ends inside this packet: drop it, but keep any whole packet its false size hid.
      const size_t inner = findPlausibleHeader(start_ + 1, buffer_.size());
      ++counters_.truncated_packets;
      reportOnce("truncated", "XTF '" + source_name_ + "' packet at byte " + std::to_string(consumed_offset_) +
                                  " needs " + std::to_string(size) + " bytes, the data ends after " +
                                  std::to_string(buffer_.size() - start_) + "; dropped");
      consume((inner != kNotFound ? inner : buffer_.size()) - start_);
      continue;
    }
    // Packets follow each other without gaps (padding counts in NumBytesThisRecord). When the
    // bytes after this one are no packet, a packet starting inside it means it was cut short.
    if (ensure(size + 2) && readU16(buffer_.data(), start_ + size) != kXtfMagic) {
      const size_t inner = findPlausibleHeader(start_ + kPacketStartBytes, start_ + size);
      if (inner != kNotFound) {
        ++counters_.truncated_packets;
        reportOnce("truncated", "XTF '" + source_name_ + "' packet at byte " + std::to_string(consumed_offset_) +
                                    " is cut short by the packet at byte " + std::to_string(offsetOf(inner)) +
                                    "; dropped");
        consume(inner - start_);
        continue;
      }
    }
    first_packet_found_ = true;
    skipping_ = false;
    ++counters_.packets;
    const uint64_t packet_offset = consumed_offset_;
    if (header.header_type == kHeaderAttitude || header.header_type == kHeaderNavigation ||
        header.header_type == kHeaderPosRawNavigation) {
      if (auto record = decodeNavigationPacket(buffer_.data() + start_, size)) {
        ++counters_.navigation_packets;
        // Bounded: a file of navigation without pings must not grow this without end.
        if (navigation_.size() < 100000) navigation_.push_back(*record);
        consume(size);
        continue;
      }
    }
    if (header.header_type != kHeaderSonar) {
      ++counters_.packets_skipped;
      ++counters_.skipped_by_type[header.header_type];
      consume(size);
      continue;
    }
    SonarDecodeResult result = decodeSonarPacket(info_, decode_, buffer_.data() + start_, size);
    consume(size);
    if (result.sound_speed_fallback) {
      ++counters_.sound_speed_fallbacks;
      reportOnce("sound_speed", "XTF '" + source_name_ + "' ping at byte " + std::to_string(packet_offset) +
                                    ": SoundVelocity is neither ~750 nor ~1500 m/s; using " +
                                    std::to_string(options_.fallback_sound_speed_m_s) + " m/s");
    }
    if (!result.error.empty()) {
      ++counters_.sonar_decode_errors;
      reportOnce("decode", "XTF '" + source_name_ + "' packet at byte " + std::to_string(packet_offset) + ": " +
                               result.error + "; ping dropped");
      continue;
    }
    if (result.no_selected_channel) {
      ++counters_.pings_without_pair;
      reportOnce("no_pair", "XTF '" + source_name_ + "' sonar packet at byte " + std::to_string(packet_offset) +
                                " carries neither channel of the chosen pair; skipped");
      continue;
    }
    ++counters_.pings;
    if (result.ship_coordinates) ++counters_.pings_ship_coordinates;
    if (result.layback_to_apply) ++counters_.pings_layback_to_apply;
    if (result.weight_applied) ++counters_.pings_weighted;
    if (result.layback_in_position) ++counters_.pings_layback_in_position;
    ping = std::move(*result.ping);
    last_ping_offset_ = packet_offset;
    return true;
  }
}

void XtfReader::reportOnce(const std::string& kind, const std::string& message) {
  if (std::find(reported_kinds_.begin(), reported_kinds_.end(), kind) == reported_kinds_.end()) {
    reported_kinds_.push_back(kind);
    new_faults_.push_back(message);
  }
}

std::vector<std::string> XtfReader::takeNewFaultMessages() {
  std::vector<std::string> faults;
  faults.swap(new_faults_);
  return faults;
}

std::string XtfReader::summary() const {
  std::string text = "XTF '" + source_name_ + "'";
  if (!open_) return text + ": " + error_;
  text += " (" + info_.recording_program + ", sonar '" + info_.sonar_name + "'): " +
          std::to_string(info_.channels.size()) + " channels (" + std::to_string(info_.sonar_channels) + " sonar, " +
          std::to_string(info_.bathymetry_channels) + " bathymetry), pair " + std::to_string(options_.pair_index) +
          " = port " + std::to_string(pair_.port) + " / starboard " + std::to_string(pair_.starboard) + ", ";
  const int any = pair_.port >= 0 ? pair_.port : pair_.starboard;
  text += std::to_string(8 * info_.channels[static_cast<size_t>(any)].bytes_per_sample) + "-bit samples, nav units " +
          navUnitsName(info_.nav_units) + "; " + std::to_string(counters_.pings) + " pings, " +
          std::to_string(counters_.packets_skipped) + " packets skipped by type";
  std::string types;
  for (size_t type = 0; type < counters_.skipped_by_type.size(); ++type) {
    if (counters_.skipped_by_type[type] == 0) continue;
    types += (types.empty() ? "" : ", ") + std::to_string(type) + ": " + std::to_string(counters_.skipped_by_type[type]);
  }
  if (!types.empty()) text += " (" + types + ")";
  if (counters_.pings_layback_to_apply > 0)
    text += ", " + std::to_string(counters_.pings_layback_to_apply) + " pings with a Layback over the ship's position";
  if (counters_.pings_weighted > 0)
    text += ", " + std::to_string(counters_.pings_weighted) + " pings scaled by their channels' Weight (sonar type " +
            std::to_string(info_.sonar_type) + ")";
  if (counters_.pings_layback_in_position > 0)
    text += ", " + std::to_string(counters_.pings_layback_in_position) + " pings with a Layback already in SensorY/X";
  text += ", " + std::to_string(counters_.corruptRecords()) + " corrupt records (" +
          std::to_string(counters_.bad_headers) + " impossible headers, " + std::to_string(counters_.truncated_packets) +
          " truncated, " + std::to_string(counters_.sonar_decode_errors) + " undecodable), " +
          std::to_string(counters_.bytes_skipped) + " bytes skipped, " + std::to_string(counters_.pings_without_pair) +
          " sonar packets without the pair";
  return text;
}

}  // namespace sss::xtf
