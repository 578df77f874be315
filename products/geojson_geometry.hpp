// What RFC 7946 asks of GeoJSON geometry beyond listing vertices: lines and rings cut where they cross
// the antimeridian (§3.1.9; a GIS otherwise draws a survey at 180 E as a stroke across the globe) and
// polygon rings counterclockwise (§3.1.6, the right-hand rule).
#pragma once

#include <vector>

namespace sss::products {

// A vertex in degrees. The input of the cuts is continuous: its longitude runs on past +-180 (179.9,
// 180.1, ...) instead of wrapping; every output vertex is wrapped into [-180, 180].
struct LonLat {
  double lon_deg = 0.0;
  double lat_deg = 0.0;
};

// The line's pieces between the meridians 180 + k 360 it crosses; a crossing vertex (latitude
// interpolated along the segment) ends one piece at +-180 and starts the next at the opposite sign.
// A line that crosses nothing comes back as one piece.
std::vector<std::vector<LonLat>> cutLineAtAntimeridian(const std::vector<LonLat>& continuous_line);

// A closed ring (first vertex == last) clipped to each 360-degree band it spans; every piece closed.
// Exact for the convex and the gently curved footprints written here (Sutherland-Hodgman against the
// band's two meridians).
std::vector<std::vector<LonLat>> cutRingAtAntimeridian(const std::vector<LonLat>& continuous_ring);

// The ring (first vertex == last) counterclockwise on a longitude-east, latitude-north plot: as it is
// when its signed area is positive, else reversed.
std::vector<LonLat> counterClockwise(std::vector<LonLat> ring);

// The longitude equal to lon_deg (modulo 360) nearest reference_lon_deg: a survey's longitudes taken
// near its origin's run on continuously through the antimeridian, as the cuts above expect.
double unwrapLongitudeNear(double lon_deg, double reference_lon_deg);

}  // namespace sss::products
