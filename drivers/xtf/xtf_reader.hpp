// Reads Triton XTF side-scan files (or the same bytes from memory) into the driver's ping
// records: one DriverPing per sonar packet, other packet types skipped by size, corrupt stretches
// counted and resynchronised on the next plausible 0xFACE packet, memory bounded by one record.
#pragma once

#include <array>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "drivers/sonar/sonar_ping.hpp"
#include "drivers/xtf/xtf_format.hpp"

namespace sss::xtf {

struct XtfReaderOptions {
  // Which side-scan pair to read: 0 = lowest frequency (see sideScanPairs), 1 = the next, ...
  int pair_index = 0;
  // Larger NumBytesThisRecord values are corrupt and never buffered (a 4-channel 16-bit ping of
  // 64k samples per channel is 0.5 MiB).
  uint32_t max_record_bytes = 64u * 1024u * 1024u;
  // Used when SoundVelocity is neither ~750 (Isis' half speed) nor ~1500 m/s.
  float fallback_sound_speed_m_s = 1500.0f;
  // Read channels flagged UniPolar = 0 as signed samples (magnitude taken). Off by default:
  // side-scan writers commonly leave the flag 0 while storing unsigned intensities (pyxtf
  // always reads unsigned).
  bool polar_as_signed = false;
  // The file header's NavUnits, unless set here: kNavUnitsMetres (0) or kNavUnitsLatLon (3), for a
  // file whose header says one and whose pings hold the other (-1: as the file says).
  int nav_units = -1;
  // A towfish's Layback over positions that are the ship's: handed on with the ping to be applied
  // along the heading (SonarDecodeOptions::apply_layback; false: positions as recorded).
  bool apply_layback = true;
  size_t read_chunk_bytes = 256 * 1024;
};

// XtfReaderOptions::nav_units for a configuration's name of it: "latlon", "metres", else (the
// configurations' "file") -1.
inline int xtfNavUnitsFromName(const std::string& name) {
  return name == "latlon" ? kNavUnitsLatLon : name == "metres" ? kNavUnitsMetres : -1;
}

struct XtfReaderCounters {
  uint64_t packets = 0;                 // framed packets of any type
  uint64_t pings = 0;                   // DriverPings handed out
  uint64_t packets_skipped = 0;         // packets of other header types, skipped by size
  std::array<uint64_t, 256> skipped_by_type{};  // the same, per HeaderType
  uint64_t pings_without_pair = 0;      // sonar packets without the chosen port/starboard channel
  uint64_t sonar_decode_errors = 0;     // sonar packets whose contents are inconsistent
  uint64_t bad_headers = 0;             // 0xFACE with an impossible size or channel count
  uint64_t truncated_packets = 0;       // cut short by the next packet or by the end of the file
  uint64_t bytes_skipped = 0;           // bytes between packets that belong to none
  uint64_t resyncs = 0;                 // runs of skipped bytes
  uint64_t sound_speed_fallbacks = 0;   // pings that used fallback_sound_speed_m_s
  uint64_t navigation_packets = 0;      // attitude (3), navigation (42), raw position (107) decoded
  uint64_t pings_ship_coordinates = 0;  // pings positioned by ShipY/X (SensorY/X unset)
  uint64_t pings_layback_to_apply = 0;  // Layback over the ship's position: handed on (layback_m)
  uint64_t pings_layback_in_position = 0;  // Layback with SensorY/X apart from ShipY/X: already applied
  uint64_t pings_weighted = 0;          // samples scaled by 2^-Weight (EdgeTech sonar types)
  uint64_t bytes_before_first_packet = 0;  // header padding or an unexpected header size
  // Corrupt records in the file: impossible headers, truncated packets, undecodable pings.
  uint64_t corruptRecords() const { return bad_headers + truncated_packets + sonar_decode_errors; }
};

class XtfReader {
 public:
  // Opens a file; isOpen() false and error() says why when it is not a usable XTF file.
  explicit XtfReader(const std::string& path, XtfReaderOptions options = {});
  // Reads the same way from bytes in memory (copied), for the fuzzer and tests.
  XtfReader(const uint8_t* data, size_t size, XtfReaderOptions options = {});

  bool isOpen() const { return open_; }
  const std::string& error() const { return error_; }
  const XtfFileInfo& info() const { return info_; }
  // The chosen pair's CHANINFO indices (port or starboard -1 when the file has only one side).
  const ChannelPair& pair() const { return pair_; }

  // The next sonar ping; false at the end of the data.
  bool next(sss::sonar::DriverPing& ping);
  // Byte offset in the file of the sonar packet the last next() gave (to patch it in a copy).
  uint64_t lastPingOffset() const { return last_ping_offset_; }
  // The navigation packets (types 3, 42, 107) read since the last call, in file order: those
  // before the ping next() just gave.
  std::vector<XtfNavigationRecord> takeNavigation();

  const XtfReaderCounters& counters() const { return counters_; }
  // Faults since the last call, one text per kind the first time it happens (log these).
  std::vector<std::string> takeNewFaultMessages();
  // One line with the per-file facts: channels, sample sizes, nav units, pings, skipped, corrupt.
  std::string summary() const;
  uint64_t bytesRead() const { return bytes_read_; }

 private:
  void openWith();
  size_t readSome(uint8_t* destination, size_t size);
  // Makes at least `count` bytes available from start_; false when the data ends first.
  bool ensure(size_t count);
  bool plausibleHeaderAt(size_t position) const;
  size_t findPlausibleHeader(size_t from, size_t to) const;  // in [from, to), or npos
  void skipBytes(size_t count, const std::string& kind);
  void consume(size_t count);
  void reportOnce(const std::string& kind, const std::string& message);
  uint64_t offsetOf(size_t position) const { return consumed_offset_ + (position - start_); }

  struct FileCloser {
    void operator()(std::FILE* f) const { std::fclose(f); }
  };
  XtfReaderOptions options_;
  std::unique_ptr<std::FILE, FileCloser> file_;
  std::vector<uint8_t> memory_;
  size_t memory_position_ = 0;
  bool open_ = false;
  bool end_of_data_ = false;
  std::string error_;
  XtfFileInfo info_;
  ChannelPair pair_;
  SonarDecodeOptions decode_;
  std::vector<uint8_t> buffer_;
  size_t start_ = 0;              // first unconsumed byte in buffer_
  uint64_t consumed_offset_ = 0;  // file offset of buffer_[start_]
  uint64_t bytes_read_ = 0;
  uint64_t last_ping_offset_ = 0;
  bool first_packet_found_ = false;
  bool skipping_ = false;
  XtfReaderCounters counters_;
  std::vector<XtfNavigationRecord> navigation_;
  std::vector<std::string> reported_kinds_;
  std::vector<std::string> new_faults_;
  std::string source_name_;
};

}  // namespace sss::xtf
