// Atomic key-value state files; see state_file.hpp.
#include "pipeline/core/state_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>

namespace sss::core {

std::string resolveSystemdDirectory(const std::string& configured, const char* env_value) {
  if (!configured.empty() || env_value == nullptr) return configured;
  const std::string directories(env_value);
  return directories.substr(0, directories.find(':'));
}

Status writeStateFile(const std::string& path, const std::string& format, const StateValues& values,
                      Durability durability) {
  std::ostringstream text;
  text << format << '\n';
  for (const auto& [key, value] : values) {
    if (key.empty() || key.find_first_of(" \n") != std::string::npos || value.find('\n') != std::string::npos) {
      return Status::error("state key '" + key + "' or its value cannot be written as one line");
    }
    text << key << ' ' << value << '\n';
  }
  return writeFileAtomically(path, text.str(), durability);
}

void syncDirectoryOf(const std::string& path) {
  // Some file systems refuse fsync on directories: best effort.
  const size_t slash = path.find_last_of('/');
  const std::string directory = slash == std::string::npos ? "." : (slash == 0 ? "/" : path.substr(0, slash));
  const int dir = ::open(directory.c_str(), O_RDONLY | O_DIRECTORY);
  if (dir >= 0) {
    ::fsync(dir);
    ::close(dir);
  }
}

Status writeFileAtomically(const std::string& path, const std::function<bool(std::FILE*)>& write_body,
                           Durability durability) {
  const bool sync = durability == Durability::kSurvivesPowerLoss;
  const std::string temporary = path + ".tmp";
  std::FILE* file = std::fopen(temporary.c_str(), "wb");
  if (!file) {
    return Status::error(temporary + ": cannot open for writing: " + std::strerror(errno));
  }
  const bool written = write_body(file) && std::fflush(file) == 0 && (!sync || ::fsync(::fileno(file)) == 0);
  const int write_errno = errno;
  if (std::fclose(file) != 0 || !written) {
    std::remove(temporary.c_str());
    return Status::error(temporary + ": write failed: " + std::strerror(write_errno) + "; the previous file is kept");
  }
  if (std::rename(temporary.c_str(), path.c_str()) != 0) {
    const int rename_errno = errno;
    std::remove(temporary.c_str());
    return Status::error(path + ": rename failed: " + std::strerror(rename_errno));
  }
  if (sync) syncDirectoryOf(path);
  return Status::success();
}

Status writeFileAtomically(const std::string& path, const std::string& bytes, Durability durability) {
  return writeFileAtomically(
      path, [&](std::FILE* file) { return std::fwrite(bytes.data(), 1, bytes.size(), file) == bytes.size(); },
      durability);
}

Result<StateValues> readStateFile(const std::string& path, const std::string& format) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return Status::error(path + ": cannot open (" + std::strerror(errno) + ")");
  std::string line;
  if (!std::getline(in, line) || line != format) {
    return Status::error(path + ": not a '" + format + "' file (first line '" + line.substr(0, 60) + "')");
  }
  StateValues values;
  int number = 1;
  while (std::getline(in, line)) {
    ++number;
    const size_t space = line.find(' ');
    if (space == 0 || space == std::string::npos || space + 1 >= line.size()) {
      return Status::error(path + ": line " + std::to_string(number) + " is not 'key value'");
    }
    if (!values.emplace(line.substr(0, space), line.substr(space + 1)).second) {
      return Status::error(path + ": line " + std::to_string(number) + " repeats key '" + line.substr(0, space) + "'");
    }
  }
  return values;
}

bool stateNumber(const StateValues& values, const std::string& key, double& number) {
  const auto it = values.find(key);
  if (it == values.end()) return false;
  char* end = nullptr;
  const double parsed = std::strtod(it->second.c_str(), &end);
  if (end == it->second.c_str() || *end != '\0' || !std::isfinite(parsed)) return false;
  number = parsed;
  return true;
}

bool stateInteger(const StateValues& values, const std::string& key, long long& number) {
  const auto it = values.find(key);
  if (it == values.end()) return false;
  char* end = nullptr;
  errno = 0;
  const long long parsed = std::strtoll(it->second.c_str(), &end, 10);
  if (end == it->second.c_str() || *end != '\0' || errno == ERANGE) return false;
  number = parsed;
  return true;
}

}  // namespace sss::core
