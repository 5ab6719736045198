// The parametric surface interface every mirror and lens surface implements, and the differential geometry
// derived from it.
//
// Conventions (the one place they are written down for cad/):
// - Lengths are in the surface's own units (metres once a scene has built it).
// - The unit normal points along du × dv. Optical surfaces are built so that it points to the element's
//   front (towards the observer for a mirror, towards the eye for a lens's eye-side surface).
// - Curvature sign: positive where the surface bends away from its normal (convex as seen from the side the
//   normal points to). A sphere of radius R with outward normal has k1 = k2 = +1/R.
#pragma once
#include <memory>
#include <string>

#include "pvrr/base/math.h"

namespace pvrr::cad {

struct ParamDomain {
  double u0 = 0, u1 = 1, v0 = 0, v1 = 1;
  bool contains(double u, double v, double tol = 0) const {
    return u >= u0 - tol && u <= u1 + tol && v >= v0 - tol && v <= v1 + tol;
  }
};

// Position and derivatives up to second order at (u, v).
struct SurfaceDerivs {
  Vec3 p, du, dv, duu, duv, dvv;
};

// Principal curvatures k1 >= k2 (sign convention above) with unit principal directions in 3D.
struct Curvature {
  double k1 = 0, k2 = 0;
  Vec3 dir1{0}, dir2{0};
  double mean() const { return 0.5 * (k1 + k2); }
  double gaussian() const { return k1 * k2; }
};

// Position, unit normal and (when asked for) principal curvatures at one parameter point.
struct SurfacePoint {
  Vec3 p{0}, n{0};
  Curvature k;
};

class Surface {
 public:
  virtual ~Surface() = default;
  virtual ParamDomain domain() const = 0;
  virtual SurfaceDerivs evaluate(double u, double v) const = 0;
  // Unit normal along du × dv. Where du × dv vanishes (a pole, a collapsed edge) the normal is taken from
  // the limit approached from inside the domain, never from a zero cross product.
  virtual Vec3 normal(double u, double v) const;
  // Default: from evaluate() and normal(). Within 1e-5 of the domain width of an edge where du × dv (nearly)
  // vanishes, it is evaluated 1e-5 of the width inside, so a pole gets a finite value (exact for a sphere).
  virtual Curvature curvature(double u, double v) const;
  // One line for messages and reports, e.g. "sphere R=-1.2 m" or "NURBS 3x4, 6x5 poles".
  virtual std::string describe() const = 0;
  // evaluate(u, v).p, normal(u, v) and, when with_curvature, curvature(u, v) in one call (the tessellators'
  // inner loop). The default makes those calls; a subclass may override it to share one evaluation, and
  // must then return bit-identical values.
  virtual SurfacePoint sample(double u, double v, bool with_curvature) const;
};

using SurfacePtr = std::shared_ptr<const Surface>;

// Normal from derivatives; falls back to the second-order limit when |du × dv| is tiny relative to
// |du||dv|. Returns a zero vector only if every fallback fails.
// At a degenerate point the limit is the one approached by increasing u and v (a pole at u0 or v0).
Vec3 normalFromDerivs(const SurfaceDerivs& d);
// The same with the limit approached along a parameter step of signs (step_u_sign, step_v_sign) (each +1 or
// -1): the direction from the point into the domain. Surface::normal() picks them from domain().
Vec3 normalFromDerivs(const SurfaceDerivs& d, double step_u_sign, double step_v_sign);
// Curvature from the first and second fundamental forms with the given unit normal.
Curvature curvatureFromDerivs(const SurfaceDerivs& d, const Vec3& n);
// What the default Surface::normal() and Surface::curvature() give at (u, v), from d = s.evaluate(u, v)
// already made: for subclasses that keep those defaults and override sample().
SurfacePoint sampleWithDefaults(const Surface& s, double u, double v, const SurfaceDerivs& d, bool with_curvature);

}  // namespace pvrr::cad
