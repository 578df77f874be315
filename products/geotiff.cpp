// GeoTIFF survey products on GDAL, see geotiff.hpp.
#include "products/geotiff.hpp"

#include <GeographicLib/UTMUPS.hpp>
#include <cpl_conv.h>
#include <cpl_error.h>
#include <cpl_string.h>
#include <gdal.h>
#include <gdal_utils.h>
#include <ogr_srs_api.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <memory>
#include <mutex>

namespace sss::products {

using sss::core::Status;

namespace {

void registerGdalOnce() {
  static std::once_flag once;
  std::call_once(once, [] { GDALAllRegister(); });
}

// GDAL reports through a global error handler; collect the last message instead of printing it.
class QuietGdalErrors {
 public:
  QuietGdalErrors() {
    CPLPushErrorHandler(CPLQuietErrorHandler);
    CPLErrorReset();
  }
  ~QuietGdalErrors() { CPLPopErrorHandler(); }
  static std::string last() {
    const char* message = CPLGetLastErrorMsg();
    return message && *message ? message : "GDAL gave no reason";
  }
};

struct DatasetCloser {
  void operator()(void* dataset) const {
    if (dataset) GDALClose(static_cast<GDALDatasetH>(dataset));
  }
};
using Dataset = std::unique_ptr<void, DatasetCloser>;

struct SrsDeleter {
  void operator()(void* srs) const {
    if (srs) OSRDestroySpatialReference(static_cast<OGRSpatialReferenceH>(srs));
  }
};
using Srs = std::unique_ptr<void, SrsDeleter>;

std::string toWkt(OGRSpatialReferenceH srs) {
  char* wkt = nullptr;
  OSRExportToWkt(srs, &wkt);
  std::string text = wkt ? wkt : "";
  CPLFree(wkt);
  return text;
}

// The mission frame as a projected CRS: PROJ's ellipsoidal orthographic projection at the origin
// is the tangent plane's (east, north), the same as GeographicLib's LocalCartesian that puts every
// position into the mission frame (they agree to 1e-8 m 3 km out).
Srs tangentPlaneSrs(const sss::core::MissionOrigin& origin) {
  Srs srs(OSRNewSpatialReference(nullptr));
  char proj[256];
  std::snprintf(proj, sizeof proj, "+proj=ortho +lat_0=%.12f +lon_0=%.12f +x_0=0 +y_0=0 +ellps=WGS84 +units=m +no_defs",
                origin.latitude_deg, origin.longitude_deg);
  if (OSRImportFromProj4(static_cast<OGRSpatialReferenceH>(srs.get()), proj) != OGRERR_NONE) return nullptr;
  return srs;
}

// An in-memory single-band dataset holding the raster, geo-referenced in its own grid.
sss::core::Result<Dataset> memoryDataset(const FrameRaster& raster, double easting_offset_m,
                                         double northing_offset_m, OGRSpatialReferenceH srs) {
  GDALDriverH mem = GDALGetDriverByName("MEM");
  if (!mem) {
    return Status::error("GDAL has no MEM driver");
  }
  const bool is_byte = raster.type == RasterType::kByte;
  Dataset dataset(GDALCreate(mem, "", raster.cols, raster.rows, 1, is_byte ? GDT_Byte : GDT_Float32, nullptr));
  if (!dataset) {
    return Status::error(QuietGdalErrors::last());
  }
  GDALDatasetH handle = static_cast<GDALDatasetH>(dataset.get());
  double transform[6] = {easting_offset_m + raster.east_left_edge_m, raster.resolution_m, 0.0,
                         northing_offset_m + raster.north_top_edge_m, 0.0, -raster.resolution_m};
  GDALSetGeoTransform(handle, transform);
  if (srs) GDALSetProjection(handle, toWkt(srs).c_str());
  GDALRasterBandH band = GDALGetRasterBand(handle, 1);
  const double nodata = is_byte ? 0.0 : raster.nodata_value;
  GDALSetRasterNoDataValue(band, nodata);
  CPLErr written = CE_None;
  if (is_byte) {
    std::vector<uint8_t> bytes(raster.values.size());
    for (size_t i = 0; i < bytes.size(); ++i) {
      const float v = raster.values[i];
      bytes[i] = std::isfinite(v) ? static_cast<uint8_t>(std::clamp(std::lround(v), 1L, 255L)) : 0;
    }
    written = GDALRasterIO(band, GF_Write, 0, 0, raster.cols, raster.rows, bytes.data(), raster.cols, raster.rows,
                           GDT_Byte, 0, 0);
  } else {
    std::vector<float> floats(raster.values);
    for (float& v : floats) {
      if (!std::isfinite(v)) v = static_cast<float>(nodata);
    }
    written = GDALRasterIO(band, GF_Write, 0, 0, raster.cols, raster.rows, floats.data(), raster.cols, raster.rows,
                           GDT_Float32, 0, 0);
  }
  if (written != CE_None) {
    return Status::error(QuietGdalErrors::last());
  }
  return dataset;
}

// GDAL's argv-style option lists.
class Argv {
 public:
  Argv& add(const std::string& value) {
    list_ = CSLAddString(list_, value.c_str());
    return *this;
  }
  ~Argv() { CSLDestroy(list_); }
  char** get() const { return list_; }

 private:
  char** list_ = nullptr;
};

std::string crsName(OGRSpatialReferenceH srs) {
  const char* name = OSRGetName(srs);
  return name ? name : "";
}

std::string number(double value) {
  char text[64];
  std::snprintf(text, sizeof text, "%.17g", value);
  return text;
}

void addCreationOptions(Argv& argv, const FrameRaster& raster) {
  argv.add("-co").add("TILED=YES").add("-co").add("COMPRESS=DEFLATE");
  argv.add("-co").add(raster.type == RasterType::kByte ? "PREDICTOR=1" : "PREDICTOR=3");
}

Status addOverviews(GDALDatasetH dataset, const FrameRaster& raster, int& count) {
  count = 0;
  const int largest = std::max(GDALGetRasterXSize(dataset), GDALGetRasterYSize(dataset));
  if (largest <= kOverviewMinSizePx) return Status::success();
  std::vector<int> levels;
  for (int level = 2; largest / level >= 256; level *= 2) levels.push_back(level);
  if (levels.empty()) return Status::success();
  if (GDALBuildOverviews(dataset, raster.categorical ? "NEAREST" : "AVERAGE", static_cast<int>(levels.size()),
                         levels.data(), 0, nullptr, nullptr, nullptr) != CE_None) {
    return Status::error("cannot build overviews: " + QuietGdalErrors::last());
  }
  count = static_cast<int>(levels.size());
  return Status::success();
}

}  // namespace

FrameRaster rasterOverCentredGrid(int rows, int cols, double resolution_m, double north_min_m, double east_min_m) {
  FrameRaster raster;
  raster.rows = rows;
  raster.cols = cols;
  raster.resolution_m = resolution_m;
  raster.north_top_edge_m = north_min_m + (rows - 0.5) * resolution_m;
  raster.east_left_edge_m = east_min_m - 0.5 * resolution_m;
  raster.values.assign(static_cast<size_t>(std::max(rows, 0)) * static_cast<size_t>(std::max(cols, 0)),
                       std::numeric_limits<float>::quiet_NaN());
  return raster;
}

Status isKnownCrs(const std::string& crs) {
  registerGdalOnce();
  QuietGdalErrors quiet;
  Srs srs(OSRNewSpatialReference(nullptr));
  if (OSRSetFromUserInput(static_cast<OGRSpatialReferenceH>(srs.get()), crs.c_str()) == OGRERR_NONE) {
    return Status::success();
  }
  return Status::error("'" + crs + "' is not a CRS GDAL knows (" + QuietGdalErrors::last() + "); use e.g. EPSG:32633");
}

int utmEpsgCode(double latitude_deg, double longitude_deg) {
  const int zone = GeographicLib::UTMUPS::StandardZone(latitude_deg, longitude_deg);
  const bool north = latitude_deg >= 0.0;
  if (zone == GeographicLib::UTMUPS::UPS) return north ? 32661 : 32761;
  return (north ? 32600 : 32700) + zone;
}

Status writeGeoTiff(const std::string& path, const FrameRaster& raster, const RasterFrame& frame, GeoTiffInfo* info) {
  if (raster.rows <= 0 || raster.cols <= 0 ||
      raster.values.size() != static_cast<size_t>(raster.rows) * static_cast<size_t>(raster.cols) ||
      !(raster.resolution_m > 0.0)) {
    return Status::error(path + ": empty or inconsistent raster (" + std::to_string(raster.rows) + " x " +
                         std::to_string(raster.cols) + ")");
  }
  if (!frame.projected && !frame.origin) {
    return Status::error(path + ": the mission frame has no origin on Earth, so the raster cannot be placed");
  }
  registerGdalOnce();
  QuietGdalErrors quiet;
  GeoTiffInfo written;
  Dataset output;
  if (frame.projected) {
    // The file's own grid: copy with the offsets, in the user's CRS when one is named.
    Srs srs;
    if (!frame.projected_crs.empty()) {
      srs.reset(OSRNewSpatialReference(nullptr));
      if (OSRSetFromUserInput(static_cast<OGRSpatialReferenceH>(srs.get()), frame.projected_crs.c_str()) !=
          OGRERR_NONE) {
        return Status::error(path + ": products.projected_crs '" + frame.projected_crs +
                             "' is not a CRS GDAL knows (use e.g. EPSG:32633)");
      }
    }
    sss::core::Result<Dataset> memory = memoryDataset(raster, frame.grid_easting_offset_m,
                                                      frame.grid_northing_offset_m,
                                                      static_cast<OGRSpatialReferenceH>(srs.get()));
    if (!memory) return Status::error(path + ": " + memory.message());
    Argv argv;
    addCreationOptions(argv, raster);
    GDALTranslateOptions* options = GDALTranslateOptionsNew(argv.get(), nullptr);
    output.reset(GDALTranslate(path.c_str(), static_cast<GDALDatasetH>(memory->get()), options, nullptr));
    GDALTranslateOptionsFree(options);
    if (srs) {
      OGRSpatialReferenceH handle = static_cast<OGRSpatialReferenceH>(srs.get());
      written.crs_name = crsName(handle);
      OSRAutoIdentifyEPSG(handle);
      const char* code = OSRGetAuthorityCode(handle, nullptr);
      if (code) written.epsg = std::atoi(code);
    }
  } else {
    // The tangent plane warped into the origin's UTM zone, on a grid aligned to the resolution.
    Srs plane = tangentPlaneSrs(*frame.origin);
    if (!plane) {
      return Status::error(path + ": cannot describe the tangent plane at the origin: " + QuietGdalErrors::last());
    }
    sss::core::Result<Dataset> memory =
        memoryDataset(raster, 0.0, 0.0, static_cast<OGRSpatialReferenceH>(plane.get()));
    if (!memory) return Status::error(path + ": " + memory.message());
    const int epsg = utmEpsgCode(frame.origin->latitude_deg, frame.origin->longitude_deg);
    const std::string nodata = raster.type == RasterType::kByte ? "0" : number(raster.nodata_value);
    Argv argv;
    argv.add("-of").add("GTiff").add("-t_srs").add("EPSG:" + std::to_string(epsg));
    argv.add("-tr").add(number(raster.resolution_m)).add(number(raster.resolution_m)).add("-tap");
    argv.add("-r").add("near").add("-et").add("0.01").add("-srcnodata").add(nodata).add("-dstnodata").add(nodata);
    argv.add("-overwrite");
    addCreationOptions(argv, raster);
    GDALWarpAppOptions* options = GDALWarpAppOptionsNew(argv.get(), nullptr);
    GDALDatasetH source = static_cast<GDALDatasetH>(memory->get());
    output.reset(GDALWarp(path.c_str(), nullptr, 1, &source, options, nullptr));
    GDALWarpAppOptionsFree(options);
    written.epsg = epsg;
  }
  if (!output) {
    return Status::error("cannot write " + path + ": " + QuietGdalErrors::last());
  }
  GDALDatasetH handle = static_cast<GDALDatasetH>(output.get());
  if (!raster.description.empty()) GDALSetMetadataItem(handle, "TIFFTAG_IMAGEDESCRIPTION", raster.description.c_str(), nullptr);
  if (frame.origin) {
    GDALSetMetadataItem(handle, "SSS_ORIGIN_LATITUDE_DEG", number(frame.origin->latitude_deg).c_str(), nullptr);
    GDALSetMetadataItem(handle, "SSS_ORIGIN_LONGITUDE_DEG", number(frame.origin->longitude_deg).c_str(), nullptr);
  }
  if (const Status overviews = addOverviews(handle, raster, written.overview_count); !overviews) {
    return Status::error(path + ": " + overviews.message);
  }
  if (written.crs_name.empty() && written.epsg != 0) {
    const char* wkt = GDALGetProjectionRef(handle);
    Srs srs(OSRNewSpatialReference(wkt));
    if (srs) written.crs_name = crsName(static_cast<OGRSpatialReferenceH>(srs.get()));
  }
  written.rows = GDALGetRasterYSize(handle);
  written.cols = GDALGetRasterXSize(handle);
  output.reset();  // flushes and closes
  if (CPLGetLastErrorType() == CE_Failure) {
    return Status::error("cannot write " + path + ": " + QuietGdalErrors::last());
  }
  if (info) *info = written;
  return Status::success();
}

}  // namespace sss::products
