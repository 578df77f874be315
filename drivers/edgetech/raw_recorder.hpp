// Records the raw sonar byte stream exactly as received, in files rotated by size, so a mission
// can be re-processed from the sonar's own bytes. A write failure (disk full) is counted and
// reported, and never stops the driver.
#pragma once

#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>

namespace sss::edgetech {

struct RawRecorderOptions {
  std::string directory;                      // empty: recording off
  std::string prefix = "sonar";
  uint64_t max_file_bytes = 1ull << 30;       // rotate at 1 GiB
};

class RawRecorder {
 public:
  explicit RawRecorder(RawRecorderOptions options);
  bool enabled() const { return !options_.directory.empty(); }

  // Appends bytes; rotates first when the current file would pass max_file_bytes.
  // utime_us names a new file (wall-clock time of its first byte).
  void write(const uint8_t* data, size_t size, int64_t utime_us);

  uint64_t bytesWritten() const { return bytes_written_; }
  uint64_t filesOpened() const { return files_opened_; }
  uint64_t writeErrors() const { return write_errors_; }
  const std::string& currentPath() const { return current_path_; }
  // The first error's text (empty when none), for logging once.
  std::string takeNewError();

 private:
  struct FileCloser {
    void operator()(std::FILE* f) const { std::fclose(f); }
  };
  bool openNext(int64_t utime_us);

  RawRecorderOptions options_;
  std::unique_ptr<std::FILE, FileCloser> file_;
  std::string current_path_;
  uint64_t current_bytes_ = 0;
  uint64_t bytes_written_ = 0;
  uint64_t files_opened_ = 0;
  uint64_t write_errors_ = 0;
  std::string new_error_;
  bool error_reported_ = false;
};

}  // namespace sss::edgetech
