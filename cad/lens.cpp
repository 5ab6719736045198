// Lens solids: validation that both sags exist over the outline and that the surfaces do not meet inside it.
#include "cad/lens.h"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

#include "cad/error.h"

namespace pvrr::cad {
namespace {

// Sampling density of the checks: the region is sampled as the outline's fromSquare() image of a
// kRegionSamples^2 grid (boundary included), and the boundary by kBoundarySamples points along the square's
// perimeter (the box corners, hence sharp rectangle corners, among them). Sag surfaces are smooth, so a
// crossing that fits between samples this dense would be a contact of depth far below any lens tolerance.
constexpr int kRegionSamples = 129;
constexpr int kBoundarySamples = 2048;

std::string num(double x) {
  std::ostringstream os;
  os << std::setprecision(6) << x;
  return os.str();
}

std::vector<Vec2> boundaryPoints(const Outline& o) {
  std::vector<Vec2> pts;
  pts.reserve(kBoundarySamples);
  const int per_side = kBoundarySamples / 4;
  for (int k = 0; k < per_side; ++k) {
    const double t = -1.0 + 2.0 * k / per_side;
    pts.push_back(o.fromSquare({t, -1.0}));
    pts.push_back(o.fromSquare({1.0, t}));
    pts.push_back(o.fromSquare({-t, 1.0}));
    pts.push_back(o.fromSquare({-1.0, -t}));
  }
  return pts;
}

std::vector<Vec2> regionPoints(const Outline& o) {
  std::vector<Vec2> pts;
  pts.reserve(size_t(kRegionSamples) * kRegionSamples + kBoundarySamples);
  for (int i = 0; i < kRegionSamples; ++i)
    for (int j = 0; j < kRegionSamples; ++j)
      pts.push_back(o.fromSquare({-1.0 + 2.0 * i / (kRegionSamples - 1), -1.0 + 2.0 * j / (kRegionSamples - 1)}));
  const std::vector<Vec2> b = boundaryPoints(o);
  pts.insert(pts.end(), b.begin(), b.end());
  return pts;
}

// Sag difference Zb - Zf at (x, y): the thickness there is centre_thickness + this.
double sagGap(const SagSurface& front, const SagSurface& back, Vec2 p) {
  return back.sag(p.x, p.y).z - front.sag(p.x, p.y).z;
}

}  // namespace

// front z = z_front - Zf, back z = z_back - Zb.
double LensSolid::thicknessAt(double x, double y) const {
  return (front->zVertex() - front->sag(x, y).z) - (back->zVertex() - back->sag(x, y).z);
}

double LensSolid::minimumThickness() const {
  double m = kInf;
  for (const Vec2& p : regionPoints(outline)) m = std::min(m, thicknessAt(p.x, p.y));
  return m;
}

double LensSolid::edgeThicknessMin() const {
  double m = kInf;
  for (const Vec2& p : boundaryPoints(outline)) m = std::min(m, thicknessAt(p.x, p.y));
  return m;
}

LensSolid makeLens(SagSurfacePtr front_shape_at_zero, SagSurfacePtr back_shape_at_zero, Outline outline,
                   double centre_thickness, double min_edge_thickness, const std::string& what) {
  if (!front_shape_at_zero || !back_shape_at_zero) throw Error(what + ": lens needs both a front and a back surface");
  if (!(centre_thickness >= 0) || !std::isfinite(centre_thickness))
    throw Error(what + ": centre thickness must be finite and >= 0, got " + num(centre_thickness) + " m");
  if (!(min_edge_thickness >= 0) || !std::isfinite(min_edge_thickness))
    throw Error(what + ": minimum edge thickness must be finite and >= 0, got " + num(min_edge_thickness) + " m");

  const std::vector<Vec2> region = regionPoints(outline);
  for (const auto& [name, s] : {std::make_pair("front", front_shape_at_zero), std::make_pair("back", back_shape_at_zero)})
    for (const Vec2& p : region)
      if (!s->defined(p.x, p.y))
        throw Error(what + ": " + name + " surface (" + s->describe() + ") is undefined at (x, y) = (" + num(p.x) +
                    ", " + num(p.y) + ") m inside the outline (" + outline.describe() + ")");

  if (min_edge_thickness > 0) {
    double gap_min = kInf;
    for (const Vec2& p : boundaryPoints(outline))
      gap_min = std::min(gap_min, sagGap(*front_shape_at_zero, *back_shape_at_zero, p));
    centre_thickness = std::max(centre_thickness, min_edge_thickness - gap_min);
  }

  LensSolid lens;
  lens.front = front_shape_at_zero->withVertex(0.0);
  lens.back = back_shape_at_zero->withVertex(-centre_thickness);
  lens.outline = outline;
  lens.centre_thickness = centre_thickness;

  double worst = kInf;
  Vec2 at(0);
  for (const Vec2& p : region) {
    const double t = lens.thicknessAt(p.x, p.y);
    if (t < worst) {
      worst = t;
      at = p;
    }
  }
  if (!(worst > 0))
    throw Error(what + ": the surfaces cross or touch inside the outline: thickness " + num(worst) +
                " m at (x, y) = (" + num(at.x) + ", " + num(at.y) + ") m (front " + lens.front->describe() +
                ", back " + lens.back->describe() + ", centre thickness " + num(centre_thickness) + " m)");
  return lens;
}

}  // namespace pvrr::cad
