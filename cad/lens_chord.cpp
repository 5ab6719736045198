// The straight chord through a lens's glass: Newton on the other surface's sag along the line, started from
// the thickness at the entry point, and a bisection on the outline where the line leaves through the edge.
#include "cad/lens_chord.h"

#include <cmath>

namespace pvrr::cad {
namespace {

constexpr int kNewtonSteps = 40;
constexpr int kBisections = 60;
// A root is accepted when the line is this close to the other surface (metres).
constexpr double kOnSurface_m = 1e-12;

}  // namespace

std::optional<LensChord> chordInside(const LensSolid& lens, int surface, const Vec3& p, const Vec3& d) {
  // Into the glass: below the front (-z), above the back (+z).
  const double into = surface == 0 ? -1.0 : 1.0;
  Vec3 e = glm::normalize(d);
  if (e.z * into < 0) e = -e;
  if (!(e.z * into > 1e-9)) return std::nullopt;
  const SagSurface& other = surface == 0 ? *lens.back : *lens.front;
  // How far inside the glass the point p + s e lies, measured along z from the other surface (> 0 inside),
  // and its derivative in s; NaN where the other sag is undefined.
  auto depth = [&](double s, double* slope) {
    const Vec3 q = p + s * e;
    if (!other.defined(q.x, q.y)) return std::nan("");
    const SagDerivs z = other.sag(q.x, q.y);
    const double surface_z = other.zVertex() - z.z;
    // surface_z's derivative along the line is -(zx ex + zy ey).
    if (slope) *slope = surface == 0 ? e.z + z.zx * e.x + z.zy * e.y : -(z.zx * e.x + z.zy * e.y) - e.z;
    return surface == 0 ? q.z - surface_z : surface_z - q.z;
  };
  double s = std::abs(lens.thicknessAt(p.x, p.y) / e.z);
  bool found = false;
  for (int i = 0; i < kNewtonSteps; ++i) {
    double slope = 0;
    const double g = depth(s, &slope);
    if (!std::isfinite(g) || !(std::abs(slope) > 1e-15)) break;
    if (std::abs(g) < kOnSurface_m) {
      found = true;
      break;
    }
    s -= g / slope;
  }
  if (!found || !(s > 0)) return std::nullopt;
  const Vec3 exit = p + s * e;
  if (lens.outline.contains(Vec2(exit.x, exit.y))) return LensChord{s, false};
  // The line leaves the outline's prism first: bisect on the outline between the entry (inside) and the
  // other surface's point (outside).
  double lo = 0, hi = s;
  for (int i = 0; i < kBisections; ++i) {
    const double mid = 0.5 * (lo + hi);
    const Vec3 q = p + mid * e;
    (lens.outline.contains(Vec2(q.x, q.y)) ? lo : hi) = mid;
  }
  return LensChord{lo, true};
}

}  // namespace pvrr::cad
