// What a run yields, and why not: the findings that explain an empty stage (cause and fix, in
// chain order), and summary.json. Internal to sss-process.
#pragma once

#include <string>
#include <vector>

#include "tools/process/offline_options.hpp"
#include "tools/process/offline_runner.hpp"

namespace sss::offline {

// One line per stage that yielded nothing, naming the cause and the fix, in chain order; the
// first explains the rest. Empty when every stage produced something.
std::vector<std::string> explainRun(const OfflineSummary& s, const Options& options);
// The same for the fixes of --fixes files.
std::vector<std::string> explainFixes(const FixSummary& f, const Options& options);
sss::core::Status writeSummaryJson(const std::string& path, const OfflineRequest& request, const OfflineSummary& s);

}  // namespace sss::offline
