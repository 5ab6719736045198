// Differential geometry of parametric surfaces: unit normals (with limits at poles and collapsed edges) and
// principal curvatures from the first and second fundamental forms.
//
// Sources: do Carmo, "Differential Geometry of Curves and Surfaces" §3-3 (shape operator, Weingarten
// equations); the limit normal at a degenerate point is the first non-vanishing term of the Taylor series of
// du × dv approached from inside the parameter domain.
#include "cad/surface.h"

#include <algorithm>
#include <cmath>

namespace pvrr::cad {
namespace {

// |du × dv| below this fraction of |du||dv| (an angle of 1e-10 rad between du and dv), or one derivative
// below this fraction of the other, counts as degenerate: a pole or a collapsed edge. Surfaces here evaluate
// their derivatives to near full relative precision close to a pole (NURBS evaluation is relative to a
// nearby control point), so the cross product is trustworthy down to this level; the normal's change over a
// parameter step this small is far below any tolerance we test (1e-9 rad).
constexpr double kDegenerate = 1e-10;

// Curvature needs the second fundamental form N = n·dvv, whose relative accuracy near a pole degrades as
// eps / (distance to the pole in parameter fraction). Within this fraction of the domain's width of an edge
// where the surface is nearly degenerate, curvature is evaluated at this distance inside instead; the
// roundoff there is ~eps / 1e-5 ≈ 2e-11 relative. For surfaces whose curvature varies, the value at a pole
// is thus the value 1e-5 of the domain width inside it.
constexpr double kPoleOffset = 1e-5;
// Nearly degenerate for curvature: |du × dv| below this fraction of max(|du|, |dv|)^2.
constexpr double kNearDegenerate = 1e-4;

bool isDegenerate(const Vec3& du, const Vec3& dv, double cross_len) {
  const double lu = glm::length(du), lv = glm::length(dv);
  return !(cross_len > kDegenerate * lu * lv) || !(std::min(lu, lv) > kDegenerate * std::max(lu, lv));
}

// Sign (+1 or -1) of the parameter step that points from t into [t0, t1].
double inwardSign(double t, double t0, double t1) { return (t - t0 <= t1 - t) ? 1.0 : -1.0; }

}  // namespace

// Normal with the limit approached along parameter steps of signs (su, sv): the expansion of du × dv about
// (u, v) for a step (h, k) is
//   du × dv + h (duu × dv + du × duv) + k (duv × dv + du × dvv) + O(2),
// and, where du and dv both vanish (an apex), (h duu + k duv) × (h duv + k dvv) + O(3).
Vec3 normalFromDerivs(const SurfaceDerivs& d, double su, double sv) {
  const Vec3 c = glm::cross(d.du, d.dv);
  const double lc = glm::length(c);
  if (!isDegenerate(d.du, d.dv, lc)) return c / lc;

  const double scale = std::max({glm::length(d.du), glm::length(d.dv), glm::length(d.duu),
                                 glm::length(d.duv), glm::length(d.dvv)});
  if (!(scale > 0) || !std::isfinite(scale)) return Vec3(0);
  // Tiny relative to the derivative scale squared: the term vanished in exact arithmetic.
  const double tiny = 1e-14 * scale * scale;

  const Vec3 a = glm::cross(d.duu, d.dv) + glm::cross(d.du, d.duv);
  const Vec3 b = glm::cross(d.duv, d.dv) + glm::cross(d.du, d.dvv);
  const Vec3 n1 = su * a + sv * b;
  const double l1 = glm::length(n1);
  if (l1 > tiny) return n1 / l1;

  const Vec3 n2 = glm::cross(su * d.duu + sv * d.duv, su * d.duv + sv * d.dvv);
  const double l2 = glm::length(n2);
  if (l2 > tiny) return n2 / l2;
  return Vec3(0);
}

Vec3 normalFromDerivs(const SurfaceDerivs& d) { return normalFromDerivs(d, 1.0, 1.0); }

// Shape operator in the orthonormal tangent frame (e1, e2) of the QR factorisation [du dv] = [e1 e2] Rm,
// Rm = [[a11, a12], [0, a22]]: S = -Rm^-T II Rm^-1 with II = [[n·duu, n·duv], [n·duv, n·dvv]]. The minus sign
// gives the convention of surface.h (+1/R for a sphere with outward normal, whose duu points inwards).
// Working in an orthonormal frame keeps S symmetric, so its eigen-decomposition is a plane rotation.
Curvature curvatureFromDerivs(const SurfaceDerivs& d, const Vec3& n) {
  Curvature k;
  const double a11 = glm::length(d.du);
  if (!(a11 > 0) || !std::isfinite(a11)) return k;
  const Vec3 e1 = d.du / a11;
  const Vec3 e2 = glm::normalize(glm::cross(n, e1));
  const double a12 = glm::dot(d.dv, e1);
  const double a22 = glm::dot(d.dv, e2);
  if (!(std::abs(a22) > 1e-300) || !std::isfinite(a22)) return k;

  const double L = glm::dot(n, d.duu), M = glm::dot(n, d.duv), N = glm::dot(n, d.dvv);
  // Rm^-1 = [[1/a11, -a12/(a11 a22)], [0, 1/a22]] = [[r11, r12], [0, r22]].
  const double r11 = 1.0 / a11, r12 = -a12 / (a11 * a22), r22 = 1.0 / a22;
  // S = -(Rm^-T II Rm^-1); Rm^-T = [[r11, 0], [r12, r22]].
  const double s11 = -(r11 * r11 * L);
  const double s12 = -(r11 * (L * r12 + M * r22));
  const double s22 = -(r12 * r12 * L + 2.0 * r12 * r22 * M + r22 * r22 * N);

  const double mean = 0.5 * (s11 + s22);
  const double half_diff = 0.5 * (s11 - s22);
  const double radius = std::hypot(half_diff, s12);
  k.k1 = mean + radius;
  k.k2 = mean - radius;
  // The eigenvector of the larger eigenvalue of [[s11, s12], [s12, s22]] is at angle atan2(2 s12, s11 - s22)/2.
  const double angle = 0.5 * std::atan2(2.0 * s12, s11 - s22);
  const double ca = std::cos(angle), sa = std::sin(angle);
  k.dir1 = ca * e1 + sa * e2;
  k.dir2 = -sa * e1 + ca * e2;  // = n × dir1
  if (!std::isfinite(k.k1) || !std::isfinite(k.k2)) return Curvature{};
  return k;
}

namespace {
// Moves (u, v) kPoleOffset of the domain's width inside when d is nearly degenerate and the point lies
// within that distance of an edge (see kPoleOffset); returns whether it moved.
bool moveOffPole(const ParamDomain& dom, const SurfaceDerivs& d, double& u, double& v) {
  const double l = std::max(glm::length(d.du), glm::length(d.dv));
  if (glm::length(glm::cross(d.du, d.dv)) > kNearDegenerate * l * l) return false;
  const double du_in = kPoleOffset * (dom.u1 - dom.u0), dv_in = kPoleOffset * (dom.v1 - dom.v0);
  const double u2 = std::clamp(u, dom.u0 + du_in, dom.u1 - du_in);
  const double v2 = std::clamp(v, dom.v0 + dv_in, dom.v1 - dv_in);
  if (u2 == u && v2 == v) return false;
  u = u2;
  v = v2;
  return true;
}

Vec3 defaultNormal(const ParamDomain& dom, const SurfaceDerivs& d, double u, double v) {
  return normalFromDerivs(d, inwardSign(u, dom.u0, dom.u1), inwardSign(v, dom.v0, dom.v1));
}
}  // namespace

Vec3 Surface::normal(double u, double v) const { return defaultNormal(domain(), evaluate(u, v), u, v); }

Curvature Surface::curvature(double u, double v) const {
  SurfaceDerivs d = evaluate(u, v);
  if (moveOffPole(domain(), d, u, v)) d = evaluate(u, v);
  return curvatureFromDerivs(d, normal(u, v));
}

SurfacePoint Surface::sample(double u, double v, bool with_curvature) const {
  SurfacePoint s;
  s.p = evaluate(u, v).p;
  s.n = normal(u, v);
  if (with_curvature) s.k = curvature(u, v);
  return s;
}

SurfacePoint sampleWithDefaults(const Surface& s, double u, double v, const SurfaceDerivs& d, bool with_curvature) {
  const ParamDomain dom = s.domain();
  SurfacePoint r;
  r.p = d.p;
  r.n = defaultNormal(dom, d, u, v);
  if (with_curvature) {
    if (moveOffPole(dom, d, u, v)) {
      const SurfaceDerivs d2 = s.evaluate(u, v);
      r.k = curvatureFromDerivs(d2, defaultNormal(dom, d2, u, v));
    } else {
      r.k = curvatureFromDerivs(d, r.n);
    }
  }
  return r;
}

}  // namespace pvrr::cad
