// Corrected copies of JSF and XTF files, see corrected_copy.hpp. The file is copied whole, then
// each ping's navigation fields are overwritten in place at the offsets the project's own reader
// found: every byte the readers do not attribute to a ping's navigation stays as it was.
#include "products/corrected_copy.hpp"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <vector>

#include "drivers/edgetech/jsf_file_reader.hpp"
#include "drivers/edgetech/jsf_format.hpp"
#include "drivers/xtf/xtf_reader.hpp"
#include "drivers/xtf/xtf_writer.hpp"

namespace sss::products {

using sss::core::Status;
namespace {

constexpr double kRadToDeg = 180.0 / M_PI;

struct FileCloser {
  void operator()(std::FILE* f) const { std::fclose(f); }
};
using File = std::unique_ptr<std::FILE, FileCloser>;

// The copy to patch: in_path copied to out_path and opened for update.
sss::core::Result<File> copyForUpdate(const std::string& in_path, const std::string& out_path) {
  std::error_code ec;
  if (std::filesystem::equivalent(in_path, out_path, ec)) {
    return Status::error("the corrected copy " + out_path + " would overwrite its input; write it to another folder");
  }
  std::filesystem::copy_file(in_path, out_path, std::filesystem::copy_options::overwrite_existing, ec);
  if (ec) return Status::error("cannot copy " + in_path + " to " + out_path + ": " + ec.message());
  File file(std::fopen(out_path.c_str(), "r+b"));
  if (!file) return Status::error("cannot open " + out_path + " for update");
  return file;
}

bool patch(std::FILE* file, uint64_t offset, const uint8_t* bytes, size_t size) {
  return std::fseek(file, static_cast<long>(offset), SEEK_SET) == 0 && std::fwrite(bytes, 1, size, file) == size;
}

bool read(std::FILE* file, uint64_t offset, uint8_t* bytes, size_t size) {
  return std::fseek(file, static_cast<long>(offset), SEEK_SET) == 0 && std::fread(bytes, 1, size, file) == size;
}

// Closes and removes the half-written copy.
Status fail(File& file, const std::string& out_path, const std::string& message) {
  file.reset();
  std::error_code ec;
  std::filesystem::remove(out_path, ec);
  return Status::error(message);
}

double wrapDegrees(double degrees) {
  double wrapped = std::fmod(degrees, 360.0);
  return wrapped < 0.0 ? wrapped + 360.0 : wrapped;
}

}  // namespace

Status writeCorrectedJsf(const std::string& in_path, const std::string& out_path, const NavigationAt& navigation,
                         CorrectedCopyCounters& counters, bool laybacks_applied) {
  sss::edgetech::JsfFileReader reader(in_path);
  if (!reader.isOpen()) {
    return Status::error(reader.error());
  }
  sss::core::Result<File> copy = copyForUpdate(in_path, out_path);
  if (!copy) return copy.status();
  File out = std::move(*copy);
  sss::edgetech::JsfMessage message;
  while (reader.next(message)) {
    if (message.header.message_type == sss::edgetech::kJsfOldSideScanData) ++counters.records_without_position_field;
    if (message.header.message_type != sss::edgetech::kJsfSonarData) continue;
    const sss::core::Result<sss::sonar::SonarChannelRecord> decoded =
        sss::edgetech::decodeSonarData(message.header, message.body.data(), message.body.size());
    const std::optional<PingNavigation> nav =
        decoded.ok() ? navigation(decoded->ping_time_us) : std::nullopt;
    if (!nav) {
      ++counters.records_without_pose;
      continue;
    }
    sss::sonar::SonarChannelRecord record = *decoded;
    record.projected_position = nav->projected;
    record.latitude_deg = nav->latitude_deg;
    record.longitude_deg = nav->longitude_deg;
    record.easting_m = nav->easting_m;
    record.northing_m = nav->northing_m;
    record.depth_m = nav->depth_m;
    record.heading_rad = nav->heading_rad;
    record.pitch_rad = nav->pitch_rad;
    record.roll_rad = nav->roll_rad;
    // The original validity bits (the decoder may have cleared some), with the fields now written.
    uint16_t validity = static_cast<uint16_t>(message.body[30] | (message.body[31] << 8));
    validity |= sss::sonar::kValidHeading | sss::sonar::kValidDepth | sss::sonar::kValidPitchRoll;
    if (!nav->projected) validity |= sss::sonar::kValidLatLon;
    record.validity = validity;
    std::vector<uint8_t> header(message.body.begin(), message.body.begin() + sss::edgetech::kSonarDataHeaderSize);
    sss::edgetech::encodeSonarNavigation(record, header.data());
    if (laybacks_applied && record.layback_m > 0.0) sss::edgetech::encodeSonarLayback(0.0f, header.data());
    if (!patch(out.get(), message.stream_offset + sss::edgetech::kJsfHeaderSize, header.data(), header.size())) {
      return fail(out, out_path, "cannot write " + out_path);
    }
    ++counters.records_corrected;
  }
  if (std::fclose(out.release()) != 0) return fail(out, out_path, "cannot write " + out_path);
  return Status::success();
}

Status writeCorrectedXtf(const std::string& in_path, const std::string& out_path, const NavigationAt& navigation,
                         CorrectedCopyCounters& counters, const sss::xtf::XtfReaderOptions& reader_options,
                         bool laybacks_applied) {
  sss::xtf::XtfReader reader(in_path, reader_options);
  if (!reader.isOpen()) {
    return Status::error(reader.error());
  }
  sss::core::Result<File> copy = copyForUpdate(in_path, out_path);
  if (!copy) return copy.status();
  File out = std::move(*copy);
  sss::sonar::DriverPing ping;
  std::vector<uint8_t> header(sss::xtf::kPingHeaderBytes);
  while (reader.next(ping)) {
    const std::optional<PingNavigation> nav = navigation(ping.utime_us);
    if (!nav) {
      ++counters.records_without_pose;
      continue;
    }
    const uint64_t offset = reader.lastPingOffset();
    if (!read(out.get(), offset, header.data(), header.size())) {
      return fail(out, out_path, "cannot read back " + out_path);
    }
    sss::xtf::XtfPingInput fields;
    fields.sensor_y = nav->projected ? nav->northing_m : nav->latitude_deg;
    fields.sensor_x = nav->projected ? nav->easting_m : nav->longitude_deg;
    fields.depth_m = static_cast<float>(nav->depth_m);
    fields.pitch_deg = static_cast<float>(nav->pitch_rad * kRadToDeg);
    fields.roll_deg = static_cast<float>(nav->roll_rad * kRadToDeg);
    fields.heading_deg = static_cast<float>(wrapDegrees(nav->heading_rad * kRadToDeg));
    sss::xtf::encodePingNavigation(fields, header.data());
    const auto& side = ping.ping.port ? *ping.ping.port : *ping.ping.starboard;
    if (laybacks_applied && side.layback_m > 0.0) sss::xtf::encodePingLayback(0.0f, header.data());
    if (!patch(out.get(), offset, header.data(), header.size())) {
      return fail(out, out_path, "cannot write " + out_path);
    }
    ++counters.records_corrected;
  }
  if (std::fclose(out.release()) != 0) return fail(out, out_path, "cannot write " + out_path);
  return Status::success();
}

}  // namespace sss::products
