// Reading a YAML file (or a JSON one: JSON is YAML) with one message per failure: the file that
// cannot be opened, or the line of the syntax error.
#pragma once

#include <yaml-cpp/yaml.h>

#include <string>

#include "pipeline/core/status.hpp"

namespace sss::eval {

// format: what the file should be ("YAML", "JSON"), named in the syntax error's message.
sss::core::Result<YAML::Node> loadYamlFile(const std::string& path, const std::string& format = "YAML");

}  // namespace sss::eval
