// JSF fuzz entry, see jsf_fuzz_target.hpp.
#include "jsf_fuzz_target.hpp"

#include <cstdlib>

#include "drivers/edgetech/jsf_navigation.hpp"
#include "drivers/edgetech/jsf_stream_parser.hpp"

namespace sss::test {

int fuzzJsf(const uint8_t* data, size_t size) {
  using namespace sss::edgetech;
  // The first byte picks the chunk size, so chunk boundaries fall everywhere.
  const size_t chunk = size > 0 ? 1 + data[0] % 97 : 1;
  JsfParserOptions options;
  options.max_body_bytes = 1 << 16;  // keep the fuzzer's memory small; same code paths
  JsfStreamParser parser(options);
  std::vector<JsfMessage> messages;
  for (size_t offset = 0; offset < size; offset += chunk) {
    parser.feed(data + offset, std::min(chunk, size - offset), messages);
  }
  parser.finish(messages);
  int decoded = 0;
  for (const JsfMessage& message : messages) {
    if (message.body.size() != static_cast<size_t>(message.header.byte_count)) std::abort();
    if (message.header.message_type == kJsfSonarData) {
      const sss::core::Result<SonarChannelRecord> result = decodeSonarData(message.header, message.body.data(), message.body.size());
      if (result) ++decoded;
    } else if (message.header.message_type == kJsfOldSideScanData) {
      const sss::core::Result<SonarChannelRecord> result =
          decodeOldSideScanData(message.header, message.body.data(), message.body.size());
      if (result) ++decoded;
    } else if (isNavigationType(message.header.message_type)) {
      static_cast<void>(decodeNavigation(message.header, message.body.data(), message.body.size()));
    }
  }
  if (parser.counters().messages != messages.size()) std::abort();
  return decoded;
}

}  // namespace sss::test
