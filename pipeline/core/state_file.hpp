// What a process keeps across its own restarts (systemd's StateDirectory=): a small text file of
// `key value` lines under a first line naming its format, written atomically (a temporary file
// renamed over the old one), so a kill -9 at any moment leaves the old or the new file, never a
// torn one. For a few counters and numbers, not for bulk data.
#pragma once

#include <cstdio>
#include <functional>
#include <map>
#include <string>

#include "pipeline/core/status.hpp"

namespace sss::core {

// A directory a process writes to: `configured` when set, else the one systemd passes in the
// environment ($STATE_DIRECTORY for StateDirectory=, $LOGS_DIRECTORY for LogsDirectory=; its
// first entry: systemd joins several with ':'), else "" (nothing written). env_value may be null
// (the variable unset).
std::string resolveSystemdDirectory(const std::string& configured, const char* env_value);

// What a replaced file survives. The rename alone survives a kill of the process; surviving a
// power loss takes two fsyncs, which can block for tens of ms: not on a real-time thread.
enum class Durability { kSurvivesPowerLoss, kSurvivesProcessKill };

// Replaces path with what write_body writes (a temporary file renamed over path; with
// kSurvivesPowerLoss the file is fsynced before and its directory after): a kill at any moment
// leaves the old or the new file. An error when it cannot (the old file is then intact).
Status writeFileAtomically(const std::string& path, const std::function<bool(std::FILE*)>& write_body,
                           Durability durability = Durability::kSurvivesPowerLoss);
Status writeFileAtomically(const std::string& path, const std::string& bytes,
                           Durability durability = Durability::kSurvivesPowerLoss);
// fsync of the directory holding path (makes a rename durable); best effort.
void syncDirectoryOf(const std::string& path);

using StateValues = std::map<std::string, std::string>;

// Writes `format` then one `key value` line per entry to path (keys without spaces or newlines,
// values without newlines). An error when it cannot; the old file is then intact.
Status writeStateFile(const std::string& path, const std::string& format, const StateValues& values,
                      Durability durability = Durability::kSurvivesPowerLoss);

// Reads a file written by writeStateFile. An error when it is missing, of another format, or
// malformed (a line without a value, a duplicate key).
Result<StateValues> readStateFile(const std::string& path, const std::string& format);

// Numeric value of `key`; false when absent or not entirely a finite number / an integer.
bool stateNumber(const StateValues& values, const std::string& key, double& number);
bool stateInteger(const StateValues& values, const std::string& key, long long& number);

}  // namespace sss::core
