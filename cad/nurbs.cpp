// Rational B-spline surfaces: validation, evaluation up to second derivatives, and exact rational patches of
// spheres, cylinders and tori.
//
// Source: L. Piegl and W. Tiller, "The NURBS Book", 2nd ed.: FindSpan (A2.1), DersBasisFuns (A2.3), rational
// surface derivatives (eq. 4.20, the quotient rule on homogeneous coordinates), circular arcs as rational
// quadratics (§7.3) and surfaces of revolution (§8.5).
#include "cad/nurbs.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <iomanip>
#include <sstream>

#include "pvrr/base/error.h"

namespace pvrr::cad {
namespace {

// Evaluation uses fixed-size stack arrays (no allocation per call); degrees above this are rejected.
constexpr int kMaxDegree = 15;

std::string num(double x) {
  std::ostringstream os;
  os << std::setprecision(17) << x;
  return os.str();
}

// Knot span index i with knots[i] <= t < knots[i+1], for t in the domain [knots[p], knots[n+1]] (n = count
// - 1); at the domain's end, the last span of non-zero length.
int findSpan(const std::vector<double>& knots, int p, int count, double t) {
  const int n = count - 1;
  if (t >= knots[size_t(n + 1)]) {
    int k = n;
    while (k > p && knots[size_t(k)] == knots[size_t(k + 1)]) --k;
    return k;
  }
  if (t <= knots[size_t(p)]) {
    int k = p;
    while (k < n && knots[size_t(k)] == knots[size_t(k + 1)]) ++k;
    return k;
  }
  // Largest k in [p, n] with knots[k] <= t.
  const auto first = knots.begin() + p, last = knots.begin() + n + 1;
  return int(std::upper_bound(first, last, t) - knots.begin()) - 1;
}

// Basis functions N_{span-p+j, p}(t) and their first two derivatives, ders[k][j] (A2.3 with n = 2).
void dersBasisFuns(int span, double t, int p, const std::vector<double>& U, double ders[3][kMaxDegree + 1]) {
  double ndu[kMaxDegree + 1][kMaxDegree + 1];
  double left[kMaxDegree + 1], right[kMaxDegree + 1];
  double a[2][kMaxDegree + 1];
  ndu[0][0] = 1.0;
  for (int j = 1; j <= p; ++j) {
    left[j] = t - U[size_t(span + 1 - j)];
    right[j] = U[size_t(span + j)] - t;
    double saved = 0.0;
    for (int r = 0; r < j; ++r) {
      ndu[j][r] = right[r + 1] + left[j - r];
      const double temp = ndu[r][j - 1] / ndu[j][r];
      ndu[r][j] = saved + right[r + 1] * temp;
      saved = left[j - r] * temp;
    }
    ndu[j][j] = saved;
  }
  for (int j = 0; j <= p; ++j) ders[0][j] = ndu[j][p];
  const int nd = std::min(2, p);
  for (int r = 0; r <= p; ++r) {
    int s1 = 0, s2 = 1;
    a[0][0] = 1.0;
    for (int k = 1; k <= nd; ++k) {
      double d = 0.0;
      const int rk = r - k, pk = p - k;
      if (r >= k) {
        a[s2][0] = a[s1][0] / ndu[pk + 1][rk];
        d = a[s2][0] * ndu[rk][pk];
      }
      const int j1 = rk >= -1 ? 1 : -rk;
      const int j2 = (r - 1 <= pk) ? k - 1 : p - r;
      for (int j = j1; j <= j2; ++j) {
        a[s2][j] = (a[s1][j] - a[s1][j - 1]) / ndu[pk + 1][rk + j];
        d += a[s2][j] * ndu[rk + j][pk];
      }
      if (r <= pk) {
        a[s2][k] = -a[s1][k - 1] / ndu[pk + 1][r];
        d += a[s2][k] * ndu[r][pk];
      }
      ders[k][r] = d;
      std::swap(s1, s2);
    }
  }
  int r = p;
  for (int k = 1; k <= nd; ++k) {
    for (int j = 0; j <= p; ++j) ders[k][j] *= r;
    r *= (p - k);
  }
  for (int k = nd + 1; k <= 2; ++k)
    for (int j = 0; j <= p; ++j) ders[k][j] = 0.0;
}

void validateKnots(const std::string& what, const char* name, const std::vector<double>& knots, int degree,
                   int count) {
  const size_t expected = size_t(count) + size_t(degree) + 1;
  if (knots.size() != expected)
    throw Error(what + ": " + name + " has " + std::to_string(knots.size()) + " values; expected count + degree + 1 = " +
                std::to_string(expected));
  for (size_t i = 0; i < knots.size(); ++i)
    if (!std::isfinite(knots[i])) throw Error(what + ": " + name + "[" + std::to_string(i) + "] is not finite");
  for (size_t i = 1; i < knots.size(); ++i)
    if (knots[i] < knots[i - 1])
      throw Error(what + ": " + name + " decrease at index " + std::to_string(i) + " (" + num(knots[i - 1]) +
                  " then " + num(knots[i]) + "); knots must be non-decreasing");
  for (size_t i = 0; i < knots.size();) {
    size_t j = i;
    while (j < knots.size() && knots[j] == knots[i]) ++j;
    if (int(j - i) > degree + 1)
      throw Error(what + ": " + name + " value " + num(knots[i]) + " has multiplicity " + std::to_string(j - i) +
                  "; at most degree + 1 = " + std::to_string(degree + 1) + " is allowed");
    i = j;
  }
  if (!(knots[size_t(count)] > knots[size_t(degree)]))
    throw Error(what + ": " + name + " give a zero-length domain [" + num(knots[size_t(degree)]) + ", " +
                num(knots[size_t(count)]) + "]");
}

// A circular arc from angle a0 to a1 (radians, a1 > a0, at most a full turn) as a rational quadratic B-spline
// on the unit circle: segments of at most a quarter turn, double interior knots, parameter in [0, 1].
struct Arc {
  std::vector<Vec2> points;  // (cos, sin)-plane coordinates, not weighted
  std::vector<double> weights;
  std::vector<double> knots;
};

Arc makeArc(double a0, double a1) {
  const double sweep = a1 - a0;
  const int segments = std::max(1, int(std::ceil(sweep / (0.5 * kPi) - 1e-12)));
  const double step = sweep / segments;
  const double w_mid = std::cos(0.5 * step);
  Arc arc;
  arc.knots = {0, 0, 0};
  for (int s = 0; s < segments; ++s) {
    const double t0 = a0 + s * step, tm = t0 + 0.5 * step;
    if (s == 0) {
      arc.points.emplace_back(std::cos(t0), std::sin(t0));
      arc.weights.push_back(1.0);
    }
    // The middle point is the intersection of the end tangents, at distance 1/cos(step/2) along the bisector.
    arc.points.push_back(Vec2(std::cos(tm), std::sin(tm)) / w_mid);
    arc.weights.push_back(w_mid);
    const double t1 = (s + 1 == segments) ? a1 : t0 + step;
    arc.points.emplace_back(std::cos(t1), std::sin(t1));
    arc.weights.push_back(1.0);
    if (s + 1 < segments) {
      const double k = double(s + 1) / segments;
      arc.knots.push_back(k);
      arc.knots.push_back(k);
    }
  }
  arc.knots.insert(arc.knots.end(), {1, 1, 1});
  return arc;
}

// Exact-angle cos/sin at quarter turns keep the control points of the standard arcs exact (cos(pi/2) is not
// 0 in floating point); a point whose coordinate is within 1e-15 of 0 is snapped.
Vec2 snap(Vec2 p) {
  if (std::abs(p.x) < 1e-15) p.x = 0;
  if (std::abs(p.y) < 1e-15) p.y = 0;
  return p;
}

}  // namespace

NurbsSurface::NurbsSurface(NurbsDefinition def, const std::string& what) : def_(std::move(def)) {
  NurbsDefinition& d = def_;
  if (d.degree_u < 1 || d.degree_v < 1)
    throw Error(what + ": degree must be >= 1, got " + std::to_string(d.degree_u) + " x " +
                std::to_string(d.degree_v));
  if (d.degree_u > kMaxDegree || d.degree_v > kMaxDegree)
    throw Error(what + ": degree " + std::to_string(std::max(d.degree_u, d.degree_v)) +
                " exceeds the supported maximum " + std::to_string(kMaxDegree));
  if (d.count_u < d.degree_u + 1 || d.count_v < d.degree_v + 1)
    throw Error(what + ": " + std::to_string(d.count_u) + " x " + std::to_string(d.count_v) +
                " control points are too few for degree " + std::to_string(d.degree_u) + " x " +
                std::to_string(d.degree_v) + "; each count must be >= degree + 1");
  const size_t n = size_t(d.count_u) * size_t(d.count_v);
  if (d.points.size() != n)
    throw Error(what + ": " + std::to_string(d.points.size()) + " control points given; expected count_u * count_v = " +
                std::to_string(n));
  if (!d.weights.empty() && d.weights.size() != n)
    throw Error(what + ": " + std::to_string(d.weights.size()) + " weights given for " + std::to_string(n) +
                " control points (the sizes must match, or weights be empty)");
  validateKnots(what, "knots_u", d.knots_u, d.degree_u, d.count_u);
  validateKnots(what, "knots_v", d.knots_v, d.degree_v, d.count_v);
  for (size_t k = 0; k < n; ++k)
    if (!isFinite(d.points[k]))
      throw Error(what + ": control point [" + std::to_string(k / size_t(d.count_v)) + "][" +
                  std::to_string(k % size_t(d.count_v)) + "] is not finite");
  if (d.weights.empty()) d.weights.assign(n, 1.0);
  for (size_t k = 0; k < n; ++k)
    if (!(d.weights[k] > 0) || !std::isfinite(d.weights[k]))
      throw Error(what + ": weight [" + std::to_string(k / size_t(d.count_v)) + "][" +
                  std::to_string(k % size_t(d.count_v)) + "] = " + num(d.weights[k]) +
                  "; weights must be finite and > 0");
}

ParamDomain NurbsSurface::domain() const {
  return {def_.knots_u[size_t(def_.degree_u)], def_.knots_u[size_t(def_.count_u)],
          def_.knots_v[size_t(def_.degree_v)], def_.knots_v[size_t(def_.count_v)]};
}

// Parameters outside the domain are clamped to it. The homogeneous sums are taken relative to the first
// control point of the active span (C = sum N w (P - P_ref) / sum N w), so near a pole, where many control
// points coincide, the small differences are computed without cancellation against the absolute position.
SurfaceDerivs NurbsSurface::evaluate(double u, double v) const {
  const NurbsDefinition& d = def_;
  const ParamDomain dom = domain();
  u = std::clamp(u, dom.u0, dom.u1);
  v = std::clamp(v, dom.v0, dom.v1);
  const int p = d.degree_u, q = d.degree_v;
  const int su = findSpan(d.knots_u, p, d.count_u, u);
  const int sv = findSpan(d.knots_v, q, d.count_v, v);
  double nu[3][kMaxDegree + 1], nv[3][kMaxDegree + 1];
  dersBasisFuns(su, u, p, d.knots_u, nu);
  dersBasisFuns(sv, v, q, d.knots_v, nv);

  const size_t cv = size_t(d.count_v);
  const size_t ref = size_t(su - p) * cv + size_t(sv - q);
  const Vec3 pref = d.points[ref];
  // Homogeneous sums: A_kl = d^(k+l)/du^k dv^l of sum N w (P - P_ref); W_kl likewise of sum N w.
  Vec3 A00(0), A10(0), A01(0), A20(0), A11(0), A02(0);
  double W00 = 0, W10 = 0, W01 = 0, W20 = 0, W11 = 0, W02 = 0;
  for (int i = 0; i <= p; ++i) {
    // Inner sums over v for row i: S_l = sum_j Nv^(l)_j w_ij (P_ij - P_ref), T_l = sum_j Nv^(l)_j w_ij.
    Vec3 S0(0), S1(0), S2(0);
    double T0 = 0, T1 = 0, T2 = 0;
    const size_t row = size_t(su - p + i) * cv + size_t(sv - q);
    for (int j = 0; j <= q; ++j) {
      const double w = d.weights[row + size_t(j)];
      const Vec3 pw = w * (d.points[row + size_t(j)] - pref);
      S0 += nv[0][j] * pw;
      S1 += nv[1][j] * pw;
      S2 += nv[2][j] * pw;
      T0 += nv[0][j] * w;
      T1 += nv[1][j] * w;
      T2 += nv[2][j] * w;
    }
    const double n0 = nu[0][i], n1 = nu[1][i], n2 = nu[2][i];
    A00 += n0 * S0; A10 += n1 * S0; A20 += n2 * S0;
    A01 += n0 * S1; A11 += n1 * S1; A02 += n0 * S2;
    W00 += n0 * T0; W10 += n1 * T0; W20 += n2 * T0;
    W01 += n0 * T1; W11 += n1 * T1; W02 += n0 * T2;
  }
  const double iw = 1.0 / W00;
  SurfaceDerivs r;
  const Vec3 c = A00 * iw;
  r.du = (A10 - W10 * c) * iw;
  r.dv = (A01 - W01 * c) * iw;
  r.duu = (A20 - 2.0 * W10 * r.du - W20 * c) * iw;
  r.duv = (A11 - W10 * r.dv - W01 * r.du - W11 * c) * iw;
  r.dvv = (A02 - 2.0 * W01 * r.dv - W02 * c) * iw;
  r.p = pref + c;
  return r;
}

SurfacePoint NurbsSurface::sample(double u, double v, bool with_curvature) const {
  return sampleWithDefaults(*this, u, v, evaluate(u, v), with_curvature);
}

std::string NurbsSurface::describe() const {
  std::ostringstream os;
  os << "NURBS " << def_.degree_u << "x" << def_.degree_v << ", " << def_.count_u << "x" << def_.count_v
     << " poles";
  const bool rational = std::any_of(def_.weights.begin(), def_.weights.end(),
                                    [&](double w) { return w != def_.weights[0]; });
  if (rational) os << ", rational";
  return os.str();
}

NurbsSurface makeSphereCap(Vec3 centre, double radius, double theta_max) {
  if (!(radius > 0) || !std::isfinite(radius))
    throw Error("sphere cap: radius must be finite and > 0, got " + num(radius));
  if (!(theta_max > 0) || !(theta_max <= kPi))
    throw Error("sphere cap: polar angle theta_max must be in (0, pi], got " + num(theta_max));
  if (!isFinite(centre)) throw Error("sphere cap: centre must be finite");
  // Meridian (u): polar angle 0..theta_max as a point (sin, cos) = (rho, z) on the unit circle, i.e. the
  // arc from angle pi/2 down to pi/2 - theta_max in the (rho, z) plane, traversed in reverse.
  const Arc mer = makeArc(0.5 * kPi - theta_max, 0.5 * kPi);
  const Arc par = makeArc(0.0, 2 * kPi);  // parallel (v): azimuth, a full turn
  NurbsDefinition d;
  d.degree_u = d.degree_v = 2;
  d.count_u = int(mer.points.size());
  d.count_v = int(par.points.size());
  d.knots_u = mer.knots;  // symmetric knot vectors: reversing the points keeps them valid
  d.knots_v = par.knots;
  for (int i = 0; i < d.count_u; ++i) {
    const size_t mi = mer.points.size() - 1 - size_t(i);
    const Vec2 m = snap(mer.points[mi]);  // (rho, z)
    for (int j = 0; j < d.count_v; ++j) {
      const Vec2 c = snap(par.points[size_t(j)]);
      // At the pole rho = 0 exactly, so the whole first row is the pole.
      d.points.push_back(centre + radius * Vec3(m.x * c.x, m.x * c.y, m.y));
      d.weights.push_back(mer.weights[mi] * par.weights[size_t(j)]);
    }
  }
  return NurbsSurface(std::move(d), "sphere cap");
}

NurbsSurface makeCylinderPatch(double radius, double angle, double height) {
  if (!(radius > 0) || !std::isfinite(radius))
    throw Error("cylinder patch: radius must be finite and > 0, got " + num(radius));
  if (!(angle > 0) || !(angle <= 2 * kPi))
    throw Error("cylinder patch: angle must be in (0, 2 pi], got " + num(angle));
  if (!(height > 0) || !std::isfinite(height))
    throw Error("cylinder patch: height must be finite and > 0, got " + num(height));
  // u: azimuth (du along e_phi), v: height (dv along +z); e_phi x e_z = e_r, outward.
  const Arc arc = makeArc(0.0, angle);
  NurbsDefinition d;
  d.degree_u = 2;
  d.degree_v = 1;
  d.count_u = int(arc.points.size());
  d.count_v = 2;
  d.knots_u = arc.knots;
  d.knots_v = {0, 0, 1, 1};
  for (int i = 0; i < d.count_u; ++i) {
    const Vec2 c = snap(arc.points[size_t(i)]);
    for (int j = 0; j < 2; ++j) {
      d.points.emplace_back(radius * c.x, radius * c.y, j * height);
      d.weights.push_back(arc.weights[size_t(i)]);
    }
  }
  return NurbsSurface(std::move(d), "cylinder patch");
}

NurbsSurface makeTorusPatch(double major_radius, double minor_radius) {
  if (!(major_radius > 0) || !std::isfinite(major_radius) || !(minor_radius > 0) || !std::isfinite(minor_radius))
    throw Error("torus patch: radii must be finite and > 0, got R = " + num(major_radius) + ", r = " +
                num(minor_radius));
  // u: toroidal angle phi in [0, pi/2] about z; v: poloidal angle psi in [0, pi/2] from the equator upwards.
  // Point ((R + r cos psi) cos phi, (R + r cos psi) sin phi, r sin psi); du x dv is the outward normal.
  const Arc tor = makeArc(0.0, 0.5 * kPi);
  const Arc pol = makeArc(0.0, 0.5 * kPi);
  NurbsDefinition d;
  d.degree_u = d.degree_v = 2;
  d.count_u = int(tor.points.size());
  d.count_v = int(pol.points.size());
  d.knots_u = tor.knots;
  d.knots_v = pol.knots;
  for (int i = 0; i < d.count_u; ++i) {
    const Vec2 c = snap(tor.points[size_t(i)]);
    for (int j = 0; j < d.count_v; ++j) {
      const Vec2 m = snap(pol.points[size_t(j)]);  // (cos psi, sin psi) control polygon
      const double rho = major_radius + minor_radius * m.x;
      d.points.emplace_back(rho * c.x, rho * c.y, minor_radius * m.y);
      d.weights.push_back(tor.weights[size_t(i)] * pol.weights[size_t(j)]);
    }
  }
  return NurbsSurface(std::move(d), "torus patch");
}

}  // namespace pvrr::cad
