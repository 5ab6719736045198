// Deterministic generators for the shipped models (see cad/model_generator.h). The fits use plain
// least squares (Eigen, Householder QR) on fixed sample grids, so the same build writes the same bytes.
#include "cad/model_generator.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>

#include "cad/cad_import.h"
#include "pvrr/base/atomic_file.h"
#include "pvrr/base/error.h"

namespace pvrr::cad {
namespace {

// Samples per millimetre-ish for the fits: dense enough to pin every pole (>> poles per span).
constexpr int kFitSamplesU = 85, kFitSamplesV = 65;

// Values and first derivatives of all B-spline basis functions of degree p at t (Cox-de Boor), for a
// clamped knot vector; t in [knots[p], knots[n]].
void basis(const std::vector<double>& knots, int p, double t, std::vector<double>& N, std::vector<double>& dN) {
  const int n = int(knots.size()) - p - 1;
  // Span index with knots[s] <= t < knots[s+1], the last non-empty span at the right end.
  int s = p;
  while (s < n - 1 && t >= knots[std::size_t(s) + 1]) ++s;
  // Degree-0 .. p triangle over all functions (small sizes, clarity over speed).
  std::vector<double> prev(std::size_t(n + p), 0.0);
  prev[std::size_t(s)] = 1.0;
  std::vector<double> lower;
  for (int d = 1; d <= p; ++d) {
    std::vector<double> cur(std::size_t(n + p - d), 0.0);
    for (int i = 0; i < n + p - d; ++i) {
      double v = 0;
      const double a = knots[std::size_t(i + d)] - knots[std::size_t(i)];
      const double b = knots[std::size_t(i + d + 1)] - knots[std::size_t(i + 1)];
      if (a > 0) v += (t - knots[std::size_t(i)]) / a * prev[std::size_t(i)];
      if (b > 0) v += (knots[std::size_t(i + d + 1)] - t) / b * prev[std::size_t(i + 1)];
      cur[std::size_t(i)] = v;
    }
    if (d == p) lower = prev;
    prev = std::move(cur);
  }
  N.assign(prev.begin(), prev.begin() + n);
  dN.assign(std::size_t(n), 0.0);
  for (int i = 0; i < n; ++i) {
    const double a = knots[std::size_t(i + p)] - knots[std::size_t(i)];
    const double b = knots[std::size_t(i + p + 1)] - knots[std::size_t(i + 1)];
    if (a > 0) dN[std::size_t(i)] += p / a * lower[std::size_t(i)];
    if (b > 0) dN[std::size_t(i)] -= p / b * lower[std::size_t(i + 1)];
  }
}

std::vector<double> greville(const std::vector<double>& knots, int p) {
  const int n = int(knots.size()) - p - 1;
  std::vector<double> g(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    double s = 0;
    for (int k = 1; k <= p; ++k) s += knots[std::size_t(i + k)];
    g[std::size_t(i)] = s / p;
  }
  return g;
}

// Bicubic z(x, y) graph: poles at the Greville abscissae (so x(u) = u, y(v) = v), z by least squares to
// `design` on a grid over the knot range; then the tangent plane at the origin is subtracted from the z
// poles (exact: a linear function's poles are its values at the Greville abscissae).
GeneratedSurface fitGraph(const std::vector<double>& ku, const std::vector<double>& kv,
                          const std::function<double(double, double)>& design, const Outline& trim) {
  constexpr int p = 3;
  const int nu = int(ku.size()) - p - 1, nv = int(kv.size()) - p - 1;
  const double u0 = ku.front(), u1 = ku.back(), v0 = kv.front(), v1 = kv.back();
  Eigen::MatrixXd A(kFitSamplesU * kFitSamplesV, nu * nv);
  Eigen::VectorXd b(kFitSamplesU * kFitSamplesV);
  std::vector<double> Nu, dNu, Nv, dNv;
  for (int a = 0; a < kFitSamplesU; ++a)
    for (int c = 0; c < kFitSamplesV; ++c) {
      const double x = u0 + (u1 - u0) * a / (kFitSamplesU - 1), y = v0 + (v1 - v0) * c / (kFitSamplesV - 1);
      basis(ku, p, x, Nu, dNu);
      basis(kv, p, y, Nv, dNv);
      const int row = a * kFitSamplesV + c;
      for (int i = 0; i < nu; ++i)
        for (int j = 0; j < nv; ++j) A(row, i * nv + j) = Nu[std::size_t(i)] * Nv[std::size_t(j)];
      b(row) = design(x, y);
    }
  const Eigen::VectorXd z = A.householderQr().solve(b);

  auto eval = [&](double x, double y, double& f, double& fx, double& fy) {
    basis(ku, p, x, Nu, dNu);
    basis(kv, p, y, Nv, dNv);
    f = fx = fy = 0;
    for (int i = 0; i < nu; ++i)
      for (int j = 0; j < nv; ++j) {
        const double zij = z(i * nv + j);
        f += Nu[std::size_t(i)] * Nv[std::size_t(j)] * zij;
        fx += dNu[std::size_t(i)] * Nv[std::size_t(j)] * zij;
        fy += Nu[std::size_t(i)] * dNv[std::size_t(j)] * zij;
      }
  };
  double f0, fx0, fy0;
  eval(0, 0, f0, fx0, fy0);

  NurbsDefinition d;
  d.degree_u = d.degree_v = p;
  d.count_u = nu;
  d.count_v = nv;
  d.knots_u = ku;
  d.knots_v = kv;
  const std::vector<double> gu = greville(ku, p), gv = greville(kv, p);
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      const double x = gu[std::size_t(i)], y = gv[std::size_t(j)];
      d.points.emplace_back(x, y, z(i * nv + j) - (f0 + fx0 * x + fy0 * y));
    }

  // Fit quality over the trimmed region (after the tangent-plane shift, against the design).
  double sum2 = 0, worst = 0;
  int count = 0;
  for (int a = 0; a <= 100; ++a)
    for (int c = 0; c <= 100; ++c) {
      const double x = u0 + (u1 - u0) * a / 100, y = v0 + (v1 - v0) * c / 100;
      if (!trim.contains(Vec2(x, y))) continue;
      double f, fx, fy;
      eval(x, y, f, fx, fy);
      const double e = (f - (f0 + fx0 * x + fy0 * y)) - design(x, y);
      sum2 += e * e;
      worst = std::max(worst, std::abs(e));
      ++count;
    }
  return GeneratedSurface{NurbsSurface(std::move(d), "generated surface"), trim,
                          count ? std::sqrt(sum2 / count) : 0.0, worst};
}

std::vector<double> clamped(double a, double b, const std::vector<double>& interior) {
  std::vector<double> k(4, a);
  k.insert(k.end(), interior.begin(), interior.end());
  k.insert(k.end(), 4, b);
  return k;
}

// Sag of a sphere of radius r with its vertex at the origin, bending away from +z.
double sphereZ(double r, double x, double y) { return -(r - std::sqrt(r * r - x * x - y * y)); }

}  // namespace

double CarMirrorDesign::z(double x_mm, double y_mm) {
  const double band_start = 0.5 * width_mm - band_width_mm;
  double z = sphereZ(main_radius_mm, x_mm, y_mm);
  if (x_mm > band_start) {
    const double t = x_mm - band_start;
    z -= 0.5 * (1 / band_radius_mm - 1 / main_radius_mm) * t * t;
  }
  return z;
}

GeneratedSurface carMirrorSurface() {
  using D = CarMirrorDesign;
  // 5 mm margin beyond the glass so the trim sits inside the surface.
  const double hu = 0.5 * D::width_mm + 5, hv = 0.5 * D::height_mm + 5;
  const double band_start = 0.5 * D::width_mm - D::band_width_mm;
  const std::vector<double> ku = clamped(-hu, hu, {band_start, band_start});  // 6 poles
  const std::vector<double> kv = clamped(-hv, hv, {0.0});                     // 5 poles
  return fitGraph(ku, kv, &CarMirrorDesign::z, Outline::rectangle(D::width_mm, D::height_mm, D::corner_radius_mm));
}

void writeCarMirrorStep(const std::string& path) {
  const GeneratedSurface g = carMirrorSurface();
  writeStep(path, g.surface, g.trim, "mm");
}

double LensFrontDesign::z(double x_mm, double y_mm) { return sphereZ(radius_mm, x_mm, y_mm); }

GeneratedSurface lensFrontSurface() {
  using D = LensFrontDesign;
  const double h = 0.5 * D::diameter_mm + 2;
  std::vector<double> interior;
  for (int k = 1; k <= 4; ++k) interior.push_back(-h + 2 * h * k / 5);  // 5 equal spans, 8 poles
  const std::vector<double> k = clamped(-h, h, interior);
  return fitGraph(k, k, &LensFrontDesign::z, Outline::circle(D::diameter_mm));
}

void writeLensIges(const std::string& path) {
  const GeneratedSurface g = lensFrontSurface();
  writeIges(path, g.surface, g.trim, "mm");
}

namespace {

// The progressive design's corridor coordinate t, the smooth step S = s(t) and G (cad/model_generator.h).
struct Corridor {
  double t, s, g;
};
Corridor corridorAt(double y_mm) {
  using D = ProgressiveBackDesign;
  const double l = D::corridor_length_mm;
  const double t = (D::corridor_top_mm - y_mm) / l;
  if (t <= 0) return {t, 0.0, 0.0};
  if (t >= 1) {
    // G(1) = L^2 / 7, G'(1) = L^2 / 2 (per unit t), G'' = L^2 beyond.
    const double e = t - 1;
    return {t, 1.0, l * l * (1.0 / 7 + 0.5 * e + 0.5 * e * e)};
  }
  const double t3 = t * t * t, t5 = t3 * t * t;
  return {t, t3 * (10 + t * (-15 + 6 * t)), l * l * t5 * (0.5 + t * (-0.5 + t / 7))};
}

}  // namespace

double ProgressiveBackDesign::z(double x_mm, double y_mm) {
  const double c = 1 / base_radius_mm, r2 = x_mm * x_mm + y_mm * y_mm;
  const double kappa = -add_d / (n_d - 1) * 1e-3;  // per mm
  const Corridor k = corridorAt(y_mm);
  const double sag = c * r2 / (1 + std::sqrt(1 - c * c * r2)) + kappa * (k.g + 0.5 * k.s * x_mm * x_mm);
  return -sag;
}

double ProgressiveBackDesign::addAt(double y_mm) { return add_d * corridorAt(y_mm).s; }

GeneratedSurface progressiveBackSurface() {
  using D = ProgressiveBackDesign;
  const double hu = 0.5 * D::blank_width_mm, hv = 0.5 * D::blank_height_mm;
  std::vector<double> iu;
  for (int k = 1; k < 8; ++k) iu.push_back(-hu + 2 * hu * k / 8);  // 8 equal spans: 11 poles
  const double top = D::corridor_top_mm, bottom = D::corridor_top_mm - D::corridor_length_mm;
  // 16 spans (19 poles): 8 of 1.5 mm along the corridor (the smooth step's fit error falls as h^4, its
  // curvature error as h^2), knots at both of its ends.
  std::vector<double> iv = {-19, -15.5};
  for (int k = 0; k <= 8; ++k) iv.push_back(bottom + (top - bottom) * k / 8);
  for (double y : {3.5, 8.0, 13.0, 18.0}) iv.push_back(y);
  return fitGraph(clamped(-hu, hu, iu), clamped(-hv, hv, iv), &ProgressiveBackDesign::z,
                  Outline::ellipse(D::lens_width_mm, D::lens_height_mm));
}

void writeProgressiveBackIges(const std::string& path) {
  const GeneratedSurface g = progressiveBackSurface();
  writeIges(path, g.surface, std::nullopt, "mm");
}

double FreeformCageDesign::z(double x_mm, double y_mm) {
  return x_mm * x_mm / (2 * radius_x_mm) - y_mm * y_mm / (2 * radius_y_mm);
}

void writeFreeformCageObj(const std::string& path) {
  using D = FreeformCageDesign;
  std::ostringstream os;
  os << "# pvrr freeform mirror: Catmull-Clark cage, " << D::nx << " x " << D::ny << " vertices\n"
     << "# units: mm\n"
     << "# design: z = x^2/(2*" << D::radius_x_mm << ") - y^2/(2*" << D::radius_y_mm << ") over "
     << D::width_mm << " x " << D::height_mm << " mm; faces wound counter-clockwise seen from +z (normal +z)\n"
     << "# written by pvrr::cad::writeFreeformCageObj\n";
  os.precision(17);
  for (int j = 0; j < D::ny; ++j)
    for (int i = 0; i < D::nx; ++i) {
      const double x = -0.5 * D::width_mm + D::width_mm * i / (D::nx - 1);
      const double y = -0.5 * D::height_mm + D::height_mm * j / (D::ny - 1);
      os << "v " << x << ' ' << y << ' ' << D::z(x, y) << '\n';
    }
  for (int j = 0; j + 1 < D::ny; ++j)
    for (int i = 0; i + 1 < D::nx; ++i) {
      const int a = 1 + i + D::nx * j;  // OBJ indices are 1-based
      os << "f " << a << ' ' << a + 1 << ' ' << a + 1 + D::nx << ' ' << a + D::nx << '\n';
    }
  writeFileAtomic(path, os.str(), MissingFolder::Fail);
}

}  // namespace pvrr::cad
