#include "pvrr/analysis/fov_radius.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <vector>

#include "pvrr/analysis/fov.h"
#include "pvrr/base/error.h"
#include "pvrr/base/format.h"

namespace pvrr {

namespace {

// Samples of the central arc for its length and the measuring points' positions along it: the arc's length
// converges as 1/n^2; 400 samples put the points well within a micrometre of their place on a 0.2 m mirror.
constexpr int kArcSamples = 400;
// A foot's Newton iteration stops when both of its conditions hold to this (metres): far below any reading's
// significance (a 1.2 m radius from a 20 mm half span moves by 1e-10 relative per 1e-14 m of sag).
constexpr double kFootTol_m = 1e-14;
constexpr int kFootIterations = 60;
// The section's 2 x 2 Jacobian is singular where the surface is tangent to the section plane's normal; below
// this relative determinant the foot is not found.
constexpr double kMinRelativeDeterminant = 1e-8;
// Three points this close to collinear (|a x b| / (|a| |b|)) read as flat: a radius beyond 1e12 half spans.
constexpr double kCollinear = 1e-12;

struct Frame {
  Vec3 p, n, along, across;
  Vec2 uv;
};

bool onSurface(const Element& el, const cad::ParamDomain& dom, Vec2 uv) {
  return el.has_outline ? el.outline.contains(uv, 1e-12) : dom.contains(uv.x, uv.y, 1e-12);
}

// The surface point whose offset from f.p has the component `along_m` along `dir` and 0 along `plane_normal`
// (the foot in the normal section spanned by f.n and dir). Newton in (u, v) from f.uv.
struct Foot {
  Vec3 p;
  Vec2 uv;
};
std::optional<Foot> foot(const cad::Surface& s, const Frame& f, const Vec3& dir, double along_m) {
  const Vec3 plane_normal = glm::normalize(glm::cross(f.n, dir));
  Vec2 uv = f.uv;
  for (int it = 0; it < kFootIterations; ++it) {
    const cad::SurfaceDerivs d = s.evaluate(uv.x, uv.y);
    const Vec3 q = d.p - f.p;
    const Vec2 F(glm::dot(q, dir) - along_m, glm::dot(q, plane_normal));
    if (std::abs(F.x) < kFootTol_m && std::abs(F.y) < kFootTol_m) return Foot{d.p, uv};
    const double a = glm::dot(d.du, dir), b = glm::dot(d.dv, dir), c = glm::dot(d.du, plane_normal),
                 e = glm::dot(d.dv, plane_normal);
    const double det = a * e - b * c;
    if (!(std::abs(det) > kMinRelativeDeterminant * glm::length(d.du) * glm::length(d.dv))) return std::nullopt;
    uv -= Vec2(e * F.x - b * F.y, -c * F.x + a * F.y) / det;
    if (!std::isfinite(uv.x) || !std::isfinite(uv.y)) return std::nullopt;
  }
  return std::nullopt;
}

// The signed radius of the circle through p and the feet a, b (> 0 when they fall behind the front: convex).
double circleRadius(const Vec3& p, const Vec3& n, const Vec3& a, const Vec3& b) {
  const Vec3 u = a - p, v = b - p;
  const double cr = glm::length(glm::cross(u, v)), lu = glm::length(u), lv = glm::length(v);
  if (cr <= kCollinear * lu * lv) return kInf;
  const double r = lu * lv * glm::length(u - v) / (2 * cr);
  return glm::dot(u + v, n) < 0 ? r : -r;
}

}  // namespace

Annex7Radius annex7Radius(const Element& el, double half_span_m) {
  PVRR_CHECK(half_span_m > 0);
  const cad::Surface& s = el.frontSurface();
  const cad::ParamDomain dom = s.domain();
  Annex7Radius out;
  // The two central arcs; the longer one is measured along.
  auto arc = [&](bool along_u, std::vector<Vec2>& sq, std::vector<double>& len) {
    sq.clear();
    len.assign(1, 0.0);
    Vec3 prev(0);
    for (int i = 0; i <= kArcSamples; ++i) {
      const double t = -1 + 2.0 * i / kArcSamples;
      sq.push_back(along_u ? Vec2(t, 0) : Vec2(0, t));
      const Vec2 uv = mirrorParameters(el, sq.back());
      const Vec3 p = s.evaluate(uv.x, uv.y).p;
      if (i > 0) len.push_back(len.back() + glm::length(p - prev));
      prev = p;
    }
  };
  std::vector<Vec2> sq_u, sq_v;
  std::vector<double> len_u, len_v;
  arc(true, sq_u, len_u);
  arc(false, sq_v, len_v);
  out.arc_along_u = len_u.back() >= len_v.back();
  const std::vector<Vec2>& sq = out.arc_along_u ? sq_u : sq_v;
  const std::vector<double>& len = out.arc_along_u ? len_u : len_v;
  out.arc_length_m = len.back();

  const double fractions[3] = {1.0 / 3, 0.5, 2.0 / 3};
  for (int k = 0; k < 3; ++k) {
    const double target = fractions[k] * out.arc_length_m;
    const size_t i = size_t(std::upper_bound(len.begin(), len.end(), target) - len.begin());
    const size_t i1 = std::min(std::max<size_t>(i, 1), len.size() - 1);
    const double w = (target - len[i1 - 1]) / std::max(len[i1] - len[i1 - 1], 1e-300);
    Annex7Radius::Point& pt = out.points[size_t(k)];
    pt.square = sq[i1 - 1] + (sq[i1] - sq[i1 - 1]) * w;
  }

  // Every foot must lie on the reflecting surface (its outline, or the CAD face's domain): a shorter span where
  // one does not.
  for (int tries = 0;; ++tries) {
    const double span = half_span_m * std::ldexp(1.0, -tries);
    bool on_surface = true;
    for (Annex7Radius::Point& pt : out.points) {
      Frame f;
      f.uv = mirrorParameters(el, pt.square);
      const cad::SurfacePoint sp = s.sample(f.uv.x, f.uv.y, false);
      f.p = sp.p;
      f.n = glm::normalize(sp.n);
      // The arc's direction at the point, in the tangent plane (a central difference along the arc).
      const Vec2 step = out.arc_along_u ? Vec2(1e-4, 0) : Vec2(0, 1e-4);
      const Vec2 a = mirrorParameters(el, pt.square + step), b = mirrorParameters(el, pt.square - step);
      Vec3 t = s.evaluate(a.x, a.y).p - s.evaluate(b.x, b.y).p;
      f.along = glm::normalize(t - glm::dot(t, f.n) * f.n);
      f.across = glm::normalize(glm::cross(f.n, f.along));
      double radii[2];
      for (int dir = 0; dir < 2; ++dir) {
        const Vec3& d = dir == 0 ? f.along : f.across;
        const std::optional<Foot> fa = foot(s, f, d, span), fb = foot(s, f, d, -span);
        if (!fa || !fb)
          throw Error(el.name + ": the R46 Annex 7 measurement finds no spherometer foot " + fmt("%.4g", span) +
                      " m from the measuring point at (" + fmt("%.3f", pt.square.x) + ", " + fmt("%.3f", pt.square.y) +
                      ") of the parameter square");
        on_surface = on_surface && onSurface(el, dom, fa->uv) && onSurface(el, dom, fb->uv);
        radii[dir] = circleRadius(f.p, f.n, fa->p, fb->p);
      }
      pt.p = f.p;
      pt.r_along_m = radii[0];
      pt.r_across_m = radii[1];
      pt.r_p_m = 0.5 * (radii[0] + radii[1]);
    }
    out.half_span_m = span;
    if (on_surface) break;
    if (tries >= 4)
      throw Error(el.name + ": the R46 Annex 7 measurement's spherometer feet fall off the reflecting surface even " +
                  "at a half span of " + fmt("%.4g", span) + " m");
  }
  out.r_m = (out.points[0].r_p_m + out.points[1].r_p_m + out.points[2].r_p_m) / 3;
  for (const Annex7Radius::Point& pt : out.points) {
    auto dev = [](double a, double ref) {
      return std::isfinite(a) && std::isfinite(ref) ? std::abs(a - ref) / std::abs(ref) : 0.0;
    };
    out.max_principal_deviation =
        std::max({out.max_principal_deviation, dev(pt.r_along_m, pt.r_p_m), dev(pt.r_across_m, pt.r_p_m)});
    out.max_point_deviation = std::max(out.max_point_deviation, dev(pt.r_p_m, out.r_m));
  }
  return out;
}

}  // namespace pvrr
