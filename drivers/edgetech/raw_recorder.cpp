// Raw stream recording with rotation, see raw_recorder.hpp.
#include "drivers/edgetech/raw_recorder.hpp"

#include <cerrno>
#include <cstring>
#include <ctime>
#include <filesystem>

namespace sss::edgetech {

RawRecorder::RawRecorder(RawRecorderOptions options) : options_(std::move(options)) {}

bool RawRecorder::openNext(int64_t utime_us) {
  file_.reset();
  const time_t seconds = static_cast<time_t>(utime_us / 1000000);
  tm utc{};
  gmtime_r(&seconds, &utc);
  char stamp[32];
  std::strftime(stamp, sizeof(stamp), "%Y%m%dT%H%M%SZ", &utc);
  std::error_code ec;
  std::filesystem::create_directories(options_.directory, ec);
  current_path_ = options_.directory + "/" + options_.prefix + "-" + stamp + "-" + std::to_string(files_opened_) + ".jsf";
  file_.reset(std::fopen(current_path_.c_str(), "wb"));
  current_bytes_ = 0;
  if (!file_) {
    ++write_errors_;
    if (!error_reported_) {
      new_error_ = "cannot create recording '" + current_path_ + "': " + std::strerror(errno) + "; recording paused";
      error_reported_ = true;
    }
    return false;
  }
  ++files_opened_;
  return true;
}

void RawRecorder::write(const uint8_t* data, size_t size, int64_t utime_us) {
  if (!enabled() || size == 0) return;
  if (!file_ || current_bytes_ + size > options_.max_file_bytes) {
    if (!openNext(utime_us)) return;
  }
  // Flushed per write: what the sonar sent must be on disk even if this process is killed.
  const size_t written = std::fwrite(data, 1, size, file_.get());
  std::fflush(file_.get());
  current_bytes_ += written;
  bytes_written_ += written;
  if (written != size) {
    ++write_errors_;
    if (!error_reported_) {
      new_error_ = "writing '" + current_path_ + "' failed: " + std::strerror(errno);
      error_reported_ = true;
    }
    file_.reset();  // try a fresh file on the next write
  }
}

std::string RawRecorder::takeNewError() {
  std::string error;
  error.swap(new_error_);
  return error;
}

}  // namespace sss::edgetech
