// Cuts recorded sensor files into the time-stamped chunks the real sensor would send: one JSF
// message per chunk (at its ping time), one INS output burst per chunk (at its epoch time).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "pipeline/core/status.hpp"
#include "tools/emulators/stream_server.hpp"

namespace sss::emulators {

// Every framed message of a .jsf file, re-encoded byte for byte; fails when the file is unreadable.
sss::core::Result<std::vector<TimedChunk>> loadJsfChunks(const std::string& path);
// The NMEA lines of an INS file grouped into bursts ending with $PIXSE,STATUS (the iXblue
// output period), each stamped with the epoch time the INS assembler reads from it.
sss::core::Result<std::vector<TimedChunk>> loadInsChunks(const std::string& path);
// The absolute fixes of a fixes.nmea file (sss-sim), one chunk per fix (ZDA + GGA + GST, re-encoded;
// GNSS talker GP, USBL II), stamped with its time; fixes without a date take reference_utime_us's day.
sss::core::Result<std::vector<TimedChunk>> loadFixChunks(const std::string& path, int64_t reference_utime_us);

}  // namespace sss::emulators
