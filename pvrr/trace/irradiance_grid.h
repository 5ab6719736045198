// An irradiance map over a receiver rectangle: what the reference's light tracer (light_tracer.h) deposits and
// what the caustic metrics (pvrr/analysis/caustic_metrics.h) compare. Header-only, no behaviour beyond
// indexing.
//
// Conventions:
// - The rectangle is centred on `centre`, spans width_m along the unit `u_axis` and height_m along the unit
//   `v_axis` (orthogonal to u_axis); its normal is u_axis x v_axis. Receiver coordinates (u, v) are metres from
//   the centre along those axes.
// - Cells: cells_u x cells_v equal cells; cell (i, j) covers u in [-w/2 + i cw, -w/2 + (i + 1) cw) and v in
//   [-h/2 + j ch, ...): i grows along +u, j along +v. Storage is row-major by j: index j * cells_u + i.
//   (Pictures show row j = cells_v - 1 at the top, so that +v points up.)
// - Irradiance is power per unit area of the rectangle (W/m^2 in the scene's light units, linear RGB per
//   channel); it equals the receiving surface's own irradiance where that surface lies in the rectangle's plane.
//   A curved receiver's grid (a height field over the rectangle's plane, DepositOptions::height_field in
//   light_tracer.h) holds the surface's own irradiance instead: per unit area of the surface, whose piece over a
//   cell is cellArea() / cos(theta); power() is then the plane's sum, under the surface's power.
//   The scalar irradiance of a cell is the mean of its three channels (a white light's power).
#pragma once
#include <vector>

#include "pvrr/base/math.h"

namespace pvrr {

struct ReceiverRect {
  Vec3 centre{0};
  Vec3 u_axis{1, 0, 0}, v_axis{0, 0, -1};  // unit, orthogonal
  double width_m = 1, height_m = 1;        // along u_axis, v_axis
  int cells_u = 128, cells_v = 128;

  Vec3 normal() const { return glm::cross(u_axis, v_axis); }
  double cellWidth() const { return width_m / cells_u; }
  double cellHeight() const { return height_m / cells_v; }
  double cellArea() const { return cellWidth() * cellHeight(); }
  // Receiver coordinates of a cell's centre, and of a world point (projected along the normal).
  Vec2 cellCentre(int i, int j) const {
    return Vec2(-0.5 * width_m + (i + 0.5) * cellWidth(), -0.5 * height_m + (j + 0.5) * cellHeight());
  }
  Vec2 toReceiver(const Vec3& p) const { return Vec2(glm::dot(p - centre, u_axis), glm::dot(p - centre, v_axis)); }
  Vec3 toWorld(const Vec2& uv) const { return centre + uv.x * u_axis + uv.y * v_axis; }
  bool contains(const Vec2& uv) const { return std::abs(uv.x) <= 0.5 * width_m && std::abs(uv.y) <= 0.5 * height_m; }
  // The same rectangle and cells (to the last bit): grids on it can be compared cell by cell.
  bool sameCells(const ReceiverRect& o) const {
    return centre == o.centre && u_axis == o.u_axis && v_axis == o.v_axis && width_m == o.width_m &&
           height_m == o.height_m && cells_u == o.cells_u && cells_v == o.cells_v;
  }
};

struct IrradianceGrid {
  ReceiverRect rect;
  std::vector<Vec3> irradiance;  // per cell, W/m^2 per channel
  // Per cell: the estimated variance of the scalar irradiance (the estimator's, not the picture's), or empty
  // when the grid does not come from a Monte Carlo estimate (analytic inputs).
  std::vector<double> variance;

  static IrradianceGrid zeros(const ReceiverRect& r) {
    IrradianceGrid g;
    g.rect = r;
    g.irradiance.assign(size_t(r.cells_u) * size_t(r.cells_v), Vec3(0));
    return g;
  }
  size_t index(int i, int j) const { return size_t(j) * size_t(rect.cells_u) + size_t(i); }
  double scalar(int i, int j) const {
    const Vec3& e = irradiance[index(i, j)];
    return (e.x + e.y + e.z) / 3.0;
  }
  std::vector<double> scalars() const {
    std::vector<double> s(irradiance.size());
    for (size_t k = 0; k < s.size(); ++k) s[k] = (irradiance[k].x + irradiance[k].y + irradiance[k].z) / 3.0;
    return s;
  }
  // Power on the grid, per channel: the sum of irradiance x cell area.
  Vec3 power() const {
    Vec3 p(0);
    for (const Vec3& e : irradiance) p += e;
    return p * rect.cellArea();
  }
};

}  // namespace pvrr
