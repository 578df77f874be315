// sss-process's configuration: the library options of every stage read from one file (the same
// file the live processes read), and small helpers of the runner. Internal to sss-process.
#pragma once

#include <optional>
#include <string>

#include "drivers/edgetech/sonar_driver.hpp"
#include "drivers/ins/fix_aligner.hpp"
#include "drivers/ins/ins_bridge.hpp"
#include "drivers/ins/position_fix.hpp"
#include "drivers/xtf/xtf_reader.hpp"
#include "pipeline/core/mission_origin.hpp"
#include "pipeline/core/status.hpp"
#include "pipeline/matcher/matcher_engine.hpp"
#include "pipeline/optimiser/optimiser_engine.hpp"
#include "pipeline/subframe/pictures.hpp"
#include "pipeline/subframe/subframe_buffer.hpp"

namespace sss::offline {

double wallSeconds();
double peakRssMib();
// Whether path ends with extension, ignoring case.
bool hasExtension(const std::string& path, const char* extension);

struct Options {
  // mission.origin_*: an override; unset, the first valid position of the navigation.
  std::optional<sss::core::MissionOrigin> origin;
  sss::edgetech::SonarDriverOptions sonar;
  sss::xtf::XtfReaderOptions xtf;
  sss::ins::InsBridgeOptions ins;
  sss::subframe::SubframeBufferOptions buffer;
  sss::matcher::MatcherEngineOptions matcher;
  sss::optimiser::OptimiserEngineOptions optimiser;
  sss::subframe::PictureOptions pictures;
  // Section `fixes`: how fix files are read, and the depth above which a GNSS fix is real (the
  // antenna is out of the water only at the surface; below, a receiver reports stale or no fixes).
  sss::ins::FixReaderOptions fix_reader;
  sss::ins::FixAlignerOptions fix_aligner;
  // Section `products`: the CRS of a projected input's grid (XTF does not record it), and whether
  // to write the GeoTIFFs.
  std::string projected_crs;
  bool write_geotiff = true;
};

// The library keys of each process's section; keys only a live process uses (ports, channels)
// are left alone here: each process's --check-config validates the whole file.
sss::core::Status readOptions(const std::string& path, Options& options);

}  // namespace sss::offline
