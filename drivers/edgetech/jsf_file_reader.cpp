// .jsf file reader, see jsf_file_reader.hpp.
#include "drivers/edgetech/jsf_file_reader.hpp"

#include <cerrno>
#include <cstring>

namespace sss::edgetech {

JsfFileReader::JsfFileReader(const std::string& path, JsfParserOptions options) : parser_(options) {
  file_.reset(std::fopen(path.c_str(), "rb"));
  if (!file_) {
    error_ = "cannot open JSF file '" + path + "': " + std::strerror(errno);
    return;
  }
  if (std::fseek(file_.get(), 0, SEEK_END) == 0) {
    const long size = std::ftell(file_.get());
    file_size_ = size > 0 ? static_cast<uint64_t>(size) : 0;
    std::fseek(file_.get(), 0, SEEK_SET);
  }
}

bool JsfFileReader::next(JsfMessage& message) {
  std::vector<uint8_t> chunk(1 << 20);
  while (ready_index_ >= ready_.size()) {
    if (!file_ || finished_) return false;
    ready_.clear();
    ready_index_ = 0;
    const size_t n = std::fread(chunk.data(), 1, chunk.size(), file_.get());
    bytes_read_ += n;
    if (n > 0) parser_.feed(chunk.data(), n, ready_);
    if (n < chunk.size()) {
      if (std::ferror(file_.get())) error_ = std::string("read error: ") + std::strerror(errno);
      parser_.finish(ready_);
      finished_ = true;
    }
  }
  message = std::move(ready_[ready_index_++]);
  return true;
}

}  // namespace sss::edgetech
