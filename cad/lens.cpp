// Lens solids: validation that both sags exist over the outline and that the surfaces do not meet inside it;
// NURBS surfaces as sag graphs (makeNurbsSag).
#include "cad/lens.h"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <limits>
#include <sstream>
#include <vector>

#include "pvrr/base/error.h"

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

// ---- NURBS surfaces as sag graphs ----

// Samples per direction of the (u, v) -> (x, y) table: the affine guess is fitted to it and the nearest
// sample restarts Newton when the affine guess fails (strongly non-affine parametrisations).
constexpr int kGraphTable = 33;

// What every copy of one NURBS sag shares (withVertex makes copies).
struct NurbsGraph {
  std::shared_ptr<const NurbsSurface> surface;
  std::optional<Outline> trim;
  double trim_tol = 0;
  std::string what;
  ParamDomain dom;
  double scale = 1;     // largest |x|, |y| over the table (metres): the scale of the inversion's rounding
  double z_axis = 0;    // z of the surface over the local origin
  Vec2 uv_axis{0};
  // Affine guess (u, v) ~ A (x, y) + b, least squares over the table.
  double a[2][3] = {{0, 0, 0}, {0, 0, 0}};
  std::vector<Vec2> table_uv, table_xy;  // regular samples only (see singular())
  double min_nz = 0;    // cos(max slope)

  // det d(x, y)/d(u, v).
  static double jacobian(const SurfaceDerivs& d) { return d.du.x * d.dv.y - d.dv.x * d.du.y; }

  Vec2 clampUv(Vec2 uv) const {
    return Vec2(std::clamp(uv.x, dom.u0, dom.u1), std::clamp(uv.y, dom.v0, dom.v1));
  }

  // Newton on (x(u, v), y(u, v)) = (x, y) from `start`, clamped to the domain. 1: converged; 0: stopped at
  // the domain boundary (the point is not over the surface); -1: failed (singular or not converging).
  int newton(double x, double y, Vec2 start, Vec2& uv, SurfaceDerivs& d) const {
    const double eps = std::numeric_limits<double>::epsilon();
    const double tol = 8 * eps * scale, accept = 256 * eps * scale;
    uv = clampUv(start);
    double r_len = kInf;
    for (int it = 0; it < 40; ++it) {
      d = surface->evaluate(uv.x, uv.y);
      const double rx = d.p.x - x, ry = d.p.y - y;
      r_len = std::hypot(rx, ry);
      if (!std::isfinite(r_len)) return -1;
      if (r_len <= tol) return 1;
      const double det = jacobian(d);
      if (!std::isfinite(det) || det == 0) return -1;
      const Vec2 next = clampUv(uv + Vec2((-d.dv.y * rx + d.dv.x * ry) / det, (d.du.y * rx - d.du.x * ry) / det));
      if (next == uv) return r_len <= accept ? 1 : 0;  // stalled: at rounding, or pinned at the boundary
      uv = next;
    }
    d = surface->evaluate(uv.x, uv.y);
    r_len = std::hypot(d.p.x - x, d.p.y - y);
    if (r_len <= accept) return 1;
    const bool on_edge = uv.x == dom.u0 || uv.x == dom.u1 || uv.y == dom.v0 || uv.y == dom.v1;
    return on_edge ? 0 : -1;
  }

  // (u, v) over (x, y) and the derivatives there; false when (x, y) is beyond the surface, with `uv` then
  // the boundary point the inversion stopped at.
  bool invert(double x, double y, Vec2& uv, SurfaceDerivs& d) const {
    const Vec2 guess(a[0][0] * x + a[0][1] * y + a[0][2], a[1][0] * x + a[1][1] * y + a[1][2]);
    const int first = newton(x, y, guess, uv, d);
    if (first == 1) return true;
    size_t best = 0;
    double best_d2 = kInf;
    for (size_t k = 0; k < table_xy.size(); ++k) {
      const double dx = table_xy[k].x - x, dy = table_xy[k].y - y, d2 = dx * dx + dy * dy;
      if (d2 < best_d2) {
        best_d2 = d2;
        best = k;
      }
    }
    Vec2 uv2;
    SurfaceDerivs d2;
    const int second = newton(x, y, table_uv[best], uv2, d2);
    if (second == 1 || first == -1) {
      uv = uv2;
      d = d2;
    }
    return second == 1;
  }

  // Whether d(x, y)/d(u, v) is singular at d: a collapsed edge or a pole of the parametrisation (the apex
  // of a spherical cap built from arcs, say), where the graph is smooth but graph() would divide by zero.
  static bool singular(const SurfaceDerivs& d) {
    return !(std::abs(jacobian(d)) > 1e-9 * glm::length(Vec2(d.du)) * glm::length(Vec2(d.dv)));
  }

  // Graph z(x, y) = z of the surface and its derivatives, from the derivatives at the (u, v) over (x, y):
  // with J = d(x, y)/d(u, v) and a_i = J^-1 e_i, z_i = grad z . a_i and, differentiating F(u(x)) = x twice,
  // z_ij = Q_z(a_i, a_j) - grad z . J^-1 Q_xy(a_i, a_j), Q(a, b) = P_uu a0 b0 + P_uv (a0 b1 + a1 b0) + P_vv a1 b1.
  static SagDerivs graph(const SurfaceDerivs& d) {
    const double det = jacobian(d);
    const Vec2 a1(d.dv.y / det, -d.du.y / det), a2(-d.dv.x / det, d.du.x / det);
    const Vec2 gz(d.du.z, d.dv.z);
    auto q = [&](Vec2 p, Vec2 r) { return d.duu * (p.x * r.x) + d.duv * (p.x * r.y + p.y * r.x) + d.dvv * (p.y * r.y); };
    auto second = [&](Vec2 p, Vec2 r) {
      const Vec3 qq = q(p, r);
      // J^-1 (qx, qy) = qx a1 + qy a2.
      const Vec2 duv = qq.x * a1 + qq.y * a2;
      return qq.z - glm::dot(gz, duv);
    };
    SagDerivs g;
    g.z = d.p.z;
    g.zx = glm::dot(gz, a1);
    g.zy = glm::dot(gz, a2);
    g.zxx = second(a1, a1);
    g.zxy = second(a1, a2);
    g.zyy = second(a2, a2);
    return g;
  }
};

class NurbsSag final : public SagSurface {
 public:
  NurbsSag(std::shared_ptr<const NurbsGraph> g, const Outline& outline, double z_vertex)
      : SagSurface(outline, z_vertex), g_(std::move(g)) {}

  bool defined(double x, double y) const override {
    Vec2 uv;
    SurfaceDerivs d;
    if (!g_->invert(x, y, uv, d)) return false;
    if (g_->trim && !g_->trim->contains(uv, g_->trim_tol)) return false;
    const Vec3 c = glm::cross(d.du, d.dv);
    return std::abs(c.z) >= g_->min_nz * glm::length(c);
  }

  // Sag Z = z_axis - z(x, y) (cad/sag.h: the point is (x, y, z_vertex - Z)); beyond the surface, its
  // second-order Taylor expansion at the boundary point.
  SagDerivs sag(double x, double y) const override {
    Vec2 uv;
    SurfaceDerivs d;
    const bool over = g_->invert(x, y, uv, d);
    SagDerivs z = NurbsGraph::singular(d) ? nearSingular(x, y, d) : NurbsGraph::graph(d);
    if (!over) {
      const double dx = x - d.p.x, dy = y - d.p.y;
      z.z += z.zx * dx + z.zy * dy + 0.5 * (z.zxx * dx * dx + 2 * z.zxy * dx * dy + z.zyy * dy * dy);
      z.zx += z.zxx * dx + z.zxy * dy;
      z.zy += z.zxy * dx + z.zyy * dy;
    }
    return SagDerivs{g_->z_axis - z.z, -z.zx, -z.zy, -z.zxx, -z.zxy, -z.zyy};
  }

  std::shared_ptr<const SagSurface> withVertex(double z_vertex) const override {
    return std::make_shared<NurbsSag>(g_, outline(), z_vertex);
  }

  std::string describe() const override {
    const Vec3 lo = g_->surface->evaluate(g_->dom.u0, g_->dom.v0).p, hi = g_->surface->evaluate(g_->dom.u1, g_->dom.v1).p;
    return g_->surface->describe() + " from " + g_->what + " (spanning (" + num(lo.x) + ", " + num(lo.y) +
           ") to (" + num(hi.x) + ", " + num(hi.y) + ") m" + (g_->trim ? ", trimmed)" : ")");
  }

 private:
  // The graph's derivatives at a singular point of the parametrisation, whose z is d.p.z: the mean of the
  // derivatives at the four points h away along x and y, which is the value at the centre to O(h^2)
  // (h = 1e-6 of the surface's extent: ~1e-12 relative for a smooth surface). Throws when those are
  // singular too (a degenerate line, not a point).
  SagDerivs nearSingular(double x, double y, const SurfaceDerivs& d) const {
    const double h = 1e-6 * std::max(g_->scale, 1e-9);
    SagDerivs m{};
    const double offsets[4][2] = {{h, 0}, {-h, 0}, {0, h}, {0, -h}};
    for (const auto& o : offsets) {
      Vec2 uv;
      SurfaceDerivs dn;
      g_->invert(x + o[0], y + o[1], uv, dn);
      if (NurbsGraph::singular(dn))
        throw Error(g_->what + ": the surface's parametrisation is degenerate along a line through (" + num(x) +
                    ", " + num(y) + ") m: no slope there");
      const SagDerivs gn = NurbsGraph::graph(dn);
      m.zx += 0.25 * (gn.zx - gn.zxx * o[0] - gn.zxy * o[1]);
      m.zy += 0.25 * (gn.zy - gn.zxy * o[0] - gn.zyy * o[1]);
      m.zxx += 0.25 * gn.zxx;
      m.zxy += 0.25 * gn.zxy;
      m.zyy += 0.25 * gn.zyy;
    }
    m.z = d.p.z;
    return m;
  }

  std::shared_ptr<const NurbsGraph> g_;
};

}  // namespace

SagSurfacePtr makeNurbsSag(std::shared_ptr<const NurbsSurface> surface, const Outline& outline,
                           std::optional<Outline> trim_uv, double trim_tolerance_uv, const std::string& what,
                           double z_vertex) {
  if (!surface) throw Error(what + ": no surface");
  auto g = std::make_shared<NurbsGraph>();
  g->surface = std::move(surface);
  g->trim = std::move(trim_uv);
  g->trim_tol = trim_tolerance_uv;
  g->what = what;
  g->dom = g->surface->domain();
  g->min_nz = std::cos(radians(kNurbsSagMaxSlope_deg));
  // The table, and the affine guess fitted to it by least squares (3 x 3 normal equations per coordinate).
  Mat3 ata(0.0);
  Vec3 atu(0.0), atv(0.0);
  double scale = 0;
  for (int i = 0; i < kGraphTable; ++i)
    for (int j = 0; j < kGraphTable; ++j) {
      const Vec2 uv(g->dom.u0 + (g->dom.u1 - g->dom.u0) * i / (kGraphTable - 1),
                    g->dom.v0 + (g->dom.v1 - g->dom.v0) * j / (kGraphTable - 1));
      const SurfaceDerivs sd = g->surface->evaluate(uv.x, uv.y);
      const Vec3 p = sd.p;
      if (!isFinite(p)) throw Error(what + ": the surface is not finite at (u, v) = (" + num(uv.x) + ", " + num(uv.y) + ")");
      // Newton cannot start at a singular point of (u, v) -> (x, y) (a pole of the parametrisation).
      if (NurbsGraph::singular(sd)) continue;
      g->table_uv.push_back(uv);
      g->table_xy.emplace_back(p.x, p.y);
      scale = std::max({scale, std::abs(p.x), std::abs(p.y)});
      const Vec3 row(p.x, p.y, 1.0);
      ata += glm::outerProduct(row, row);
      atu += uv.x * row;
      atv += uv.y * row;
    }
  g->scale = std::max(scale, 1e-300);
  if (std::abs(glm::determinant(ata)) > 0) {
    const Mat3 inv = glm::inverse(ata);
    const Vec3 cu = inv * atu, cv = inv * atv;
    for (int k = 0; k < 3; ++k) {
      g->a[0][k] = cu[k];
      g->a[1][k] = cv[k];
    }
  }
  SurfaceDerivs d;
  if (!g->invert(0, 0, g->uv_axis, d))
    throw Error(what + ": the surface (" + g->surface->describe() + ") does not lie over the lens axis (x, y) = (0, 0)"
                " of the lens frame; its x and y must be the lens's local x and y, in the file's unit");
  g->z_axis = d.p.z;
  return std::make_shared<NurbsSag>(std::move(g), outline, z_vertex);
}

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
