// Reads a .jsf file message by message through the same stream parser as the TCP path, so a
// file with corrupt stretches is read exactly as a noisy link would be.
#pragma once

#include <cstdio>
#include <deque>
#include <memory>
#include <string>

#include "drivers/edgetech/jsf_stream_parser.hpp"

namespace sss::edgetech {

class JsfFileReader {
 public:
  // Opens path; error() says why when it fails.
  explicit JsfFileReader(const std::string& path, JsfParserOptions options = {});
  bool isOpen() const { return file_ != nullptr; }
  const std::string& error() const { return error_; }

  // The next message; false at the end of the file.
  bool next(JsfMessage& message);

  const JsfParserCounters& counters() const { return parser_.counters(); }
  std::vector<std::string> takeNewFaultMessages() { return parser_.takeNewFaultMessages(); }
  uint64_t bytesRead() const { return bytes_read_; }
  uint64_t fileSize() const { return file_size_; }

 private:
  struct FileCloser {
    void operator()(std::FILE* f) const { std::fclose(f); }
  };
  std::unique_ptr<std::FILE, FileCloser> file_;
  std::string error_;
  JsfStreamParser parser_;
  std::vector<JsfMessage> ready_;
  size_t ready_index_ = 0;
  bool finished_ = false;
  uint64_t bytes_read_ = 0;
  uint64_t file_size_ = 0;
};

}  // namespace sss::edgetech
