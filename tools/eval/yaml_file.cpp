// YAML file reading, see yaml_file.hpp.
#include "tools/eval/yaml_file.hpp"

namespace sss::eval {

sss::core::Result<YAML::Node> loadYamlFile(const std::string& path, const std::string& format) {
  try {
    return YAML::LoadFile(path);
  } catch (const YAML::BadFile&) {
    return sss::core::Status::error(path + ": cannot open; check the path");
  } catch (const YAML::Exception& e) {
    return sss::core::Status::error(path + ":" + std::to_string(e.mark.line + 1) + ": not valid " + format + ": " + e.msg);
  }
}

}  // namespace sss::eval
