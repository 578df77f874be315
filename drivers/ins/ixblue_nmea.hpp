// iXblue INS NMEA 0183 output ("standard" $PIXSE family + $--HDT, $--ZDA, DVL $--DPT): one
// navigation state <-> the sentences of one INS output period, and typed parsing of each sentence.
//
// Sentences used (fields after the address; see drivers/ins/README.md for sources):
//   $HEHDT,h.hhh,T                      true heading, deg, 0..360 clockwise from north
//   $PIXSE,ATITUD,r.rrr,p.ppp           roll, pitch, deg, iXblue vessel frame: roll + = port side UP
//                                       (= starboard down, same as FRD), pitch + = bow DOWN
//                                       (opposite of FRD): pitch_rad = -pitch_deg * pi / 180
//   $PIXSE,POSITI,lat,lon,alt           deg (8 decimals), deg, altitude m positive UP:
//                                       depth_m = -alt
//   $PIXSE,SPEED_,e.eee,n.nnn,u.uuu     velocity east, north, UP, m/s: velocity_down = -u
//   $PIXSE,TIME__,hhmmss.ssssss         UTC time of day of the burst's data
//   $PIXSE,STDHRP,h.hhh,r.rrr,p.ppp     one-sigma heading, roll, pitch, deg
//   $PIXSE,STDPOS,la.la,lo.lo,al.al     one-sigma latitude, longitude (m), altitude (m)
//   $PIXSE,STDSPD,e.eee,n.nnn,u.uuu     one-sigma velocity east, north, up, m/s
//   $SDDPT,d.ddd,o.ooo[,r.r]            DVL altitude above seabed = depth below transducer d, m
//                                       (offset o not applied: lever arms belong to the bridge)
//   $INZDA,hhmmss.ss,dd,mm,yyyy,zh,zm   UTC date (TIME__ carries no date)
//   $PIXSE,ALGSTS,hhhhhhhh,llllllll     algorithm status words (kept, not interpreted)
//   $PIXSE,STATUS,hhhhhhhh,llllllll     system status words; the LAST sentence of a burst
// Recognised and ignored: $PIXSE UTMWGS, HEAVE_, HT_STS. Any talker is accepted for HDT/ZDA/DPT.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

namespace sss::ins {

// InsState::validity bits. The low bits match sss_msgs::nav_t (VALID_* = 1..32, STALE_* =
// 256..2048) so the bridge can copy them; bits 16 and up are extras the bridge maps or masks.
constexpr uint32_t kValidPosition = 1u << 0;
constexpr uint32_t kValidAttitude = 1u << 1;  // roll and pitch
constexpr uint32_t kValidHeading = 1u << 2;
constexpr uint32_t kValidVelocity = 1u << 3;
constexpr uint32_t kValidDepth = 1u << 4;
constexpr uint32_t kValidAltitude = 1u << 5;
constexpr uint32_t kStalePosition = 1u << 8;
constexpr uint32_t kStaleHeading = 1u << 9;
constexpr uint32_t kStaleVelocity = 1u << 10;
constexpr uint32_t kStaleAltitude = 1u << 11;
constexpr uint32_t kValidPositionStd = 1u << 16;  // latitude/longitude/depth std (STDPOS)
constexpr uint32_t kValidAttitudeStd = 1u << 17;  // heading/roll/pitch std (STDHRP)
constexpr uint32_t kValidVelocityStd = 1u << 18;  // velocity std (STDSPD)
constexpr uint32_t kStaleAttitude = 1u << 20;
constexpr uint32_t kStaleDepth = 1u << 21;
constexpr uint32_t kValidAll = kValidPosition | kValidAttitude | kValidHeading | kValidVelocity |
                               kValidDepth | kValidAltitude | kValidPositionStd |
                               kValidAttitudeStd | kValidVelocityStd;
constexpr uint32_t kStaleAll =
    kStalePosition | kStaleHeading | kStaleVelocity | kStaleAltitude | kStaleAttitude | kStaleDepth;

struct InsState {
  int64_t utime_us = 0;  // measurement time, us since epoch (UTC)
  double latitude_deg = 0, longitude_deg = 0, depth_m = 0 /*positive down*/,
         altitude_m = -1 /*above seabed, <0 unknown*/;
  double roll_rad = 0, pitch_rad = 0, heading_rad = 0;  // NED/FRD: roll starboard-down +, pitch
                                                        // bow-up +, heading clockwise from north
  double velocity_north_m_s = 0, velocity_east_m_s = 0, velocity_down_m_s = 0;
  double latitude_std_m = 0, longitude_std_m = 0, depth_std_m = 0;
  double roll_std_rad = 0, pitch_std_rad = 0, heading_std_rad = 0;
  double velocity_north_std_m_s = 0, velocity_east_std_m_s = 0, velocity_down_std_m_s = 0;
  double altitude_std_m = 0;  // not carried by the protocol: InsAssemblerOptions supplies it
  uint32_t validity = 0;      // kValid* / kStale* bits
};

// All sentences of one INS epoch, each "$...*HH\r\n", in the order the INS sends them:
// HEHDT, ATITUD, POSITI, SPEED_, TIME__, STDHRP, STDPOS, STDSPD, SDDPT, INZDA, ALGSTS, STATUS.
// A sentence group is written only when its validity bit is set (kValidAll writes everything):
// HDT <- kValidHeading; ATITUD <- kValidAttitude; POSITI <- kValidPosition or kValidDepth;
// SPEED_ <- kValidVelocity; STDHRP <- kValidAttitudeStd; STDPOS <- kValidPositionStd;
// STDSPD <- kValidVelocityStd; SDDPT <- kValidAltitude and altitude_m >= 0. TIME__, ZDA,
// ALGSTS (zero) and STATUS (zero) are always written. Resolution: lat/lon 1e-8 deg, angles
// 0.001 deg, depth and altitude 1 mm, velocity 1 mm/s, position std 1 cm, time 1 us.
// Values beyond the protocol's ranges are clamped (heading wrapped to [0, 360)).
std::string encodeInsState(const InsState& state);

// ---- sentence level ------------------------------------------------------------------------

// XOR of the bytes between '$' and '*' (the NMEA 0183 checksum).
uint8_t nmeaChecksum(std::string_view body);
// "$" + body + "*HH\r\n".
std::string frameSentence(std::string_view body);

struct HeadingSentence {  // $--HDT
  double heading_deg = 0;  // [0, 360)
};
struct AttitudeSentence {  // $PIXSE,ATITUD, iXblue signs (see the file comment)
  double roll_deg = 0;     // + port side up
  double pitch_deg = 0;    // + bow down
};
struct PositionSentence {  // $PIXSE,POSITI
  double latitude_deg = 0;
  double longitude_deg = 0;  // normalised to [-180, 180)
  double altitude_m = 0;     // + up
};
struct SpeedSentence {  // $PIXSE,SPEED_
  double east_m_s = 0, north_m_s = 0, up_m_s = 0;
};
struct TimeSentence {  // $PIXSE,TIME__
  int64_t time_of_day_us = 0;
};
struct AttitudeStdSentence {  // $PIXSE,STDHRP
  double heading_std_deg = 0, roll_std_deg = 0, pitch_std_deg = 0;
};
struct PositionStdSentence {  // $PIXSE,STDPOS
  double latitude_std_m = 0, longitude_std_m = 0, altitude_std_m = 0;
};
struct SpeedStdSentence {  // $PIXSE,STDSPD
  double east_std_m_s = 0, north_std_m_s = 0, up_std_m_s = 0;
};
struct DepthBelowTransducerSentence {  // $--DPT
  bool has_depth = false;  // an empty depth field is how a DVL says "no bottom lock"
  double depth_m = 0;
};
struct DateTimeSentence {  // $--ZDA
  int64_t time_of_day_us = 0;
  int year = 0, month = 0, day = 0;
};
struct StatusSentence {  // $PIXSE,ALGSTS or $PIXSE,STATUS
  bool algorithm = false;  // true: ALGSTS, false: STATUS
  uint32_t word_lsb = 0, word_msb = 0;
};
struct IgnoredSentence {};  // recognised, carries nothing we use (UTMWGS, HEAVE_, HT_STS)

using ParsedSentence =
    std::variant<HeadingSentence, AttitudeSentence, PositionSentence, SpeedSentence, TimeSentence,
                 AttitudeStdSentence, PositionStdSentence, SpeedStdSentence,
                 DepthBelowTransducerSentence, DateTimeSentence, StatusSentence, IgnoredSentence>;

enum class SentenceError {
  kNone = 0,
  kUnsupported,       // a sentence we do not know (not an error of the stream; counted)
  kWrongFieldCount,
  kEmptyField,
  kNotANumber,
  kOutOfRange,
};
constexpr int kSentenceErrorCount = 6;
const char* sentenceErrorName(SentenceError error);

struct SentenceParseResult {
  SentenceError error = SentenceError::kNone;
  std::string error_text;  // what, which field, which value (empty when error == kNone)
  ParsedSentence sentence;  // meaningful only when error == kNone
};

// Parses a checked sentence body (between '$' and '*', as NmeaStreamParser yields it).
// Never throws on bad input; a bad field rejects the whole sentence.
SentenceParseResult parseSentence(std::string_view body);

// Splits at ',' (fields may be empty).
std::vector<std::string_view> splitFields(std::string_view body);

// Calendar helpers (proleptic Gregorian, UTC).
int64_t daysFromCivil(int year, int month, int day);
void civilFromDays(int64_t days, int& year, int& month, int& day);

}  // namespace sss::ins
