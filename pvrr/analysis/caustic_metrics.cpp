#include "pvrr/analysis/caustic_metrics.h"

#include <cmath>

#include "pvrr/base/error.h"

namespace pvrr {

namespace {

void checkMap(const IrradianceGrid& m, const char* what) {
  const ReceiverRect& r = m.rect;
  if (r.cells_u < 1 || r.cells_v < 1 || m.irradiance.size() != size_t(r.cells_u) * size_t(r.cells_v) ||
      !(r.width_m > 0) || !(r.height_m > 0))
    throw Error(std::string("caustic metrics: the ") + what + " map's values do not match its cells");
}

// The vertex offset (in cells, within [-0.5, 0.5]) of the parabola through log(a), log(b), log(c) at -1, 0, 1,
// b the largest; 0 when a neighbour is not positive.
double logParabolaOffset(double a, double b, double c) {
  if (!(a > 0) || !(c > 0) || !(b > 0)) return 0;
  const double la = std::log(a), lb = std::log(b), lc = std::log(c);
  const double den = la - 2 * lb + lc;
  if (!(den < 0)) return 0;
  const double x = 0.5 * (la - lc) / den;
  return std::max(-0.5, std::min(0.5, x));
}

}  // namespace

SpotMetrics spotMetrics(const IrradianceGrid& map, double spot_fraction) {
  checkMap(map, "measured");
  if (!(spot_fraction > 0) || spot_fraction > 1)
    throw Error("caustic metrics: the spot fraction must be in (0, 1], got " + std::to_string(spot_fraction));
  const ReceiverRect& r = map.rect;
  SpotMetrics s;
  const std::vector<double> e = map.scalars();
  for (int j = 0; j < r.cells_v; ++j)
    for (int i = 0; i < r.cells_u; ++i) {
      const double v = e[map.index(i, j)];
      s.total_power += v * r.cellArea();
      if (v > s.peak_irradiance) s.peak_irradiance = v, s.peak_i = i, s.peak_j = j;
    }
  if (!(s.peak_irradiance > 0)) return s;
  s.found = true;
  auto at = [&](int i, int j) {
    return (i < 0 || j < 0 || i >= r.cells_u || j >= r.cells_v) ? 0.0 : e[map.index(i, j)];
  };
  const int pi = s.peak_i, pj = s.peak_j;
  const double du = logParabolaOffset(at(pi - 1, pj), at(pi, pj), at(pi + 1, pj));
  const double dv = logParabolaOffset(at(pi, pj - 1), at(pi, pj), at(pi, pj + 1));
  s.peak_uv_m = r.cellCentre(pi, pj) + Vec2(du * r.cellWidth(), dv * r.cellHeight());
  s.peak_world = r.toWorld(s.peak_uv_m);
  Vec2 weighted(0);
  double weight = 0;
  const double threshold = spot_fraction * s.peak_irradiance;
  for (int j = 0; j < r.cells_v; ++j)
    for (int i = 0; i < r.cells_u; ++i) {
      const double v = e[map.index(i, j)];
      if (v < threshold) continue;
      ++s.spot_cells;
      s.spot_power += v * r.cellArea();
      weighted += v * r.cellCentre(i, j);
      weight += v;
    }
  s.spot_area_m2 = s.spot_cells * r.cellArea();
  s.centroid_uv_m = weighted / weight;
  return s;
}

IrradianceComparison compareIrradiance(const IrradianceGrid& test, const IrradianceGrid& reference,
                                       double spot_fraction) {
  checkMap(test, "test");
  checkMap(reference, "reference");
  if (!test.rect.sameCells(reference.rect))
    throw Error("caustic metrics: the test and reference maps lie on different receiver cells");
  IrradianceComparison c;
  c.test = spotMetrics(test, spot_fraction);
  c.reference = spotMetrics(reference, spot_fraction);
  if (!c.reference.found) throw Error("caustic metrics: the reference map holds no light");
  c.peak_distance_m = glm::length(c.test.peak_uv_m - c.reference.peak_uv_m);
  c.centroid_distance_m = glm::length(c.test.centroid_uv_m - c.reference.centroid_uv_m);
  const std::vector<double> a = test.scalars(), b = reference.scalars();
  const double threshold = spot_fraction * c.reference.peak_irradiance;
  double diff = 0, sum = 0;
  for (size_t k = 0; k < b.size(); ++k) {
    if (b[k] < threshold) continue;
    diff += std::abs(a[k] - b[k]);
    sum += b[k];
  }
  c.relative_l1_in_spot = diff / sum;
  c.power_ratio = c.test.total_power / c.reference.total_power;
  if (!c.test.found) c.peak_distance_m = c.centroid_distance_m = kInf;
  return c;
}

}  // namespace pvrr
