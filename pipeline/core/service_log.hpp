// What a process's service object (the node's logic without middleware) has to say: its log lines
// by level, handed back to the process, which writes them (sss::transport::writeServiceLog) and
// clears them. The services stay free of logging and their tests read what they would have said.
#pragma once

#include <string>
#include <vector>

namespace sss::core {

struct ServiceLog {
  std::vector<std::string> info;
  std::vector<std::string> warnings;
  std::vector<std::string> errors;
  bool empty() const { return info.empty() && warnings.empty() && errors.empty(); }
};

}  // namespace sss::core
