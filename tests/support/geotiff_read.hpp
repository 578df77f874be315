// Reads a GeoTIFF back with GDAL for tests: CRS, geotransform, nodata, overviews and the band's
// values, and converts a WGS-84 position into the file's pixel. Header-only; link GDAL::GDAL.
#pragma once

#include <GeographicLib/UTMUPS.hpp>
#include <cpl_conv.h>
#include <gdal.h>
#include <ogr_srs_api.h>

#include <cmath>
#include <cstdlib>
#include <mutex>
#include <string>
#include <vector>

namespace sss::test {

struct GeoTiffReadBack {
  bool ok = false;
  std::string error;
  std::string wkt;
  int epsg = 0;  // from the CRS's authority code, 0 when none
  double transform[6] = {0, 0, 0, 0, 0, 0};
  int rows = 0, cols = 0;
  bool has_nodata = false;
  double nodata = 0.0;
  std::string data_type;  // "Byte", "Float32", ...
  int overviews = 0;
  std::string description;
  std::vector<double> values;  // rows x cols, row-major

  double at(int row, int col) const { return values[static_cast<size_t>(row) * cols + col]; }
  // The pixel (row, col) holding map coordinates (x, y); false outside the raster.
  bool pixelOf(double x, double y, int& row, int& col) const {
    col = static_cast<int>(std::floor((x - transform[0]) / transform[1]));
    row = static_cast<int>(std::floor((y - transform[3]) / transform[5]));
    return row >= 0 && col >= 0 && row < rows && col < cols;
  }
  // The centre of pixel (row, col) in map coordinates.
  double centreX(int col) const { return transform[0] + (col + 0.5) * transform[1]; }
  double centreY(int row) const { return transform[3] + (row + 0.5) * transform[5]; }
};

inline GeoTiffReadBack readGeoTiff(const std::string& path) {
  static std::once_flag once;
  std::call_once(once, [] { GDALAllRegister(); });
  GeoTiffReadBack r;
  GDALDatasetH dataset = GDALOpen(path.c_str(), GA_ReadOnly);
  if (!dataset) {
    r.error = "GDAL cannot open " + path;
    return r;
  }
  r.rows = GDALGetRasterYSize(dataset);
  r.cols = GDALGetRasterXSize(dataset);
  GDALGetGeoTransform(dataset, r.transform);
  r.wkt = GDALGetProjectionRef(dataset);
  if (!r.wkt.empty()) {
    OGRSpatialReferenceH srs = OSRNewSpatialReference(r.wkt.c_str());
    if (srs) {
      OSRAutoIdentifyEPSG(srs);
      const char* code = OSRGetAuthorityCode(srs, nullptr);
      if (code) r.epsg = std::atoi(code);
      OSRDestroySpatialReference(srs);
    }
  }
  const char* description = GDALGetMetadataItem(dataset, "TIFFTAG_IMAGEDESCRIPTION", nullptr);
  if (description) r.description = description;
  GDALRasterBandH band = GDALGetRasterBand(dataset, 1);
  int has_nodata = 0;
  r.nodata = GDALGetRasterNoDataValue(band, &has_nodata);
  r.has_nodata = has_nodata != 0;
  r.data_type = GDALGetDataTypeName(GDALGetRasterDataType(band));
  r.overviews = GDALGetOverviewCount(band);
  r.values.resize(static_cast<size_t>(r.rows) * r.cols);
  r.ok = GDALRasterIO(band, GF_Read, 0, 0, r.cols, r.rows, r.values.data(), r.cols, r.rows, GDT_Float64, 0, 0) == CE_None;
  if (!r.ok) r.error = "GDAL cannot read the band of " + path;
  GDALClose(dataset);
  return r;
}

// UTM (easting, northing) of a WGS-84 position in a given zone (EPSG 326zz / 327zz).
inline void utmOf(double latitude_deg, double longitude_deg, int epsg, double& easting_m, double& northing_m) {
  const bool north = epsg < 32700;
  const int zone = epsg % 100;
  int zone_out = 0;
  bool north_out = true;
  double gamma = 0.0, k = 0.0;
  GeographicLib::UTMUPS::Forward(latitude_deg, longitude_deg, zone_out, north_out, easting_m, northing_m, gamma, k,
                                 zone);
  if (north_out != north) northing_m += north ? -10000000.0 : 10000000.0;
}

}  // namespace sss::test
