// Antimeridian cuts and ring orientation for GeoJSON, see geojson_geometry.hpp.
#include "products/geojson_geometry.hpp"

#include <algorithm>
#include <cmath>

namespace sss::products {
namespace {

// The 360-degree band a continuous longitude lies in: band b holds [-180 + 360 b, 180 + 360 b).
int bandOf(double lon_deg) { return static_cast<int>(std::floor((lon_deg + 180.0) / 360.0)); }

LonLat shifted(const LonLat& p, int band) { return {p.lon_deg - 360.0 * band, p.lat_deg}; }

// Where the segment a -> b meets the meridian lon_deg (a and b on either side of it).
LonLat crossing(const LonLat& a, const LonLat& b, double lon_deg) {
  const double t = (lon_deg - a.lon_deg) / (b.lon_deg - a.lon_deg);
  return {lon_deg, a.lat_deg + t * (b.lat_deg - a.lat_deg)};
}

bool same(const LonLat& a, const LonLat& b) { return a.lon_deg == b.lon_deg && a.lat_deg == b.lat_deg; }

void appendUnlessRepeated(std::vector<LonLat>& piece, const LonLat& p) {
  if (piece.empty() || !same(piece.back(), p)) piece.push_back(p);
}

// Sutherland-Hodgman against one meridian: keeps the side where inside(lon) holds.
template <typename Inside>
std::vector<LonLat> clipOpenRing(const std::vector<LonLat>& ring, double meridian_deg, Inside inside) {
  std::vector<LonLat> out;
  for (size_t i = 0; i < ring.size(); ++i) {
    const LonLat& current = ring[i];
    const LonLat& previous = ring[(i + ring.size() - 1) % ring.size()];
    const bool current_in = inside(current.lon_deg), previous_in = inside(previous.lon_deg);
    if (current_in != previous_in) appendUnlessRepeated(out, crossing(previous, current, meridian_deg));
    if (current_in) appendUnlessRepeated(out, current);
  }
  if (out.size() > 1 && same(out.front(), out.back())) out.pop_back();
  return out;
}

}  // namespace

double unwrapLongitudeNear(double lon_deg, double reference_lon_deg) {
  return reference_lon_deg + std::remainder(lon_deg - reference_lon_deg, 360.0);
}

std::vector<LonLat> counterClockwise(std::vector<LonLat> ring) {
  double twice_area = 0.0;  // shoelace
  for (size_t i = 0; i + 1 < ring.size(); ++i)
    twice_area += ring[i].lon_deg * ring[i + 1].lat_deg - ring[i + 1].lon_deg * ring[i].lat_deg;
  if (twice_area < 0.0) std::reverse(ring.begin(), ring.end());
  return ring;
}

std::vector<std::vector<LonLat>> cutLineAtAntimeridian(const std::vector<LonLat>& continuous_line) {
  std::vector<std::vector<LonLat>> pieces;
  if (continuous_line.empty()) return pieces;
  std::vector<LonLat> piece;
  int band = bandOf(continuous_line.front().lon_deg);
  piece.push_back(shifted(continuous_line.front(), band));
  for (size_t i = 1; i < continuous_line.size(); ++i) {
    const LonLat& a = continuous_line[i - 1];
    const LonLat& b = continuous_line[i];
    const int target = bandOf(b.lon_deg);
    while (band != target) {  // one meridian at a time (a segment crosses at most one in practice)
      const int step = target > band ? 1 : -1;
      const double meridian_deg = step > 0 ? 180.0 + 360.0 * band : -180.0 + 360.0 * band;
      const LonLat at = crossing(a, b, meridian_deg);
      appendUnlessRepeated(piece, shifted(at, band));
      if (piece.size() > 1) pieces.push_back(piece);
      band += step;
      piece = {shifted(at, band)};
    }
    appendUnlessRepeated(piece, shifted(b, band));
  }
  if (piece.size() > 1) pieces.push_back(piece);
  return pieces;
}

std::vector<std::vector<LonLat>> cutRingAtAntimeridian(const std::vector<LonLat>& continuous_ring) {
  std::vector<LonLat> open(continuous_ring);
  if (open.size() > 1 && same(open.front(), open.back())) open.pop_back();
  std::vector<std::vector<LonLat>> pieces;
  if (open.size() < 3) return pieces;
  const auto [west, east] = std::minmax_element(open.begin(), open.end(),
                                                [](const LonLat& a, const LonLat& b) { return a.lon_deg < b.lon_deg; });
  const int first_band = bandOf(west->lon_deg), last_band = bandOf(east->lon_deg);
  for (int band = first_band; band <= last_band; ++band) {
    std::vector<LonLat> piece = open;
    if (first_band != last_band) {
      const double west_deg = -180.0 + 360.0 * band, east_deg = 180.0 + 360.0 * band;
      piece = clipOpenRing(piece, west_deg, [&](double lon) { return lon >= west_deg; });
      piece = clipOpenRing(piece, east_deg, [&](double lon) { return lon <= east_deg; });
    }
    if (piece.size() < 3) continue;  // only touches the band
    for (LonLat& p : piece) p = shifted(p, band);
    piece.push_back(piece.front());  // closed, as GeoJSON rings are
    pieces.push_back(std::move(piece));
  }
  return pieces;
}

}  // namespace sss::products
