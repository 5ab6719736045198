// Analytic sag surfaces: plane, sphere, even asphere, toric and cylinder, with exact first and second sag
// derivatives in numerically stable forms (no R - sqrt(R^2 - r^2) cancellation).
#include "cad/sag.h"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

#include "pvrr/base/error.h"

namespace pvrr::cad {
namespace {

std::string num(double x) {
  std::ostringstream os;
  os << std::setprecision(6) << x;
  return os.str();
}

// 1/R with 0 and infinity meaning a plane; throws for NaN.
double curvatureOf(double radius, const std::string& what) {
  if (std::isnan(radius)) throw Error(what + ": radius is NaN");
  if (radius == 0 || std::isinf(radius)) return 0.0;
  return 1.0 / radius;
}

std::string radiusText(double c) { return c == 0 ? std::string("inf") : num(1.0 / c); }

[[noreturn]] void throwUndefined(const SagSurface& s, double x, double y, const std::string& why) {
  throw Error(s.describe() + ": sag undefined at (x, y) = (" + num(x) + ", " + num(y) + ") m (" + why + ")");
}

class PlaneSag final : public SagSurface {
 public:
  using SagSurface::SagSurface;
  SagDerivs sag(double, double) const override { return {}; }
  std::shared_ptr<const SagSurface> withVertex(double z) const override {
    return std::make_shared<PlaneSag>(outline(), z);
  }
  std::string describe() const override { return "plane"; }
  bool sphereCurvature(double* c) const override {
    *c = 0;
    return true;
  }
};

// Z = f(r^2) with f(rho) = c rho / (1 + sqrt(1 - K rho)) + sum_i a_i rho^(i+2), K = (1 + k) c^2.
// With s = sqrt(1 - K rho): f' = c / (2 s) + sum a_i (i+2) rho^(i+1), f'' = c K / (4 s^3) + sum a_i (i+2)(i+1)
// rho^i (from c rho / (1 + s) = c (1 - s) / K). Then Z_x = 2 x f', Z_xx = 2 f' + 4 x^2 f'', Z_xy = 4 x y f''.
class ConicSag final : public SagSurface {
 public:
  ConicSag(Outline o, double z_vertex, double c, double conic, std::vector<double> a, bool is_sphere)
      : SagSurface(o, z_vertex), c_(c), k_(conic), a_(std::move(a)), sphere_(is_sphere),
        K_((1 + conic) * c * c) {}

  bool defined(double x, double y) const override { return 1 - K_ * (x * x + y * y) > 0; }

  SagDerivs sag(double x, double y) const override {
    const double rho = x * x + y * y;
    const double arg = 1 - K_ * rho;
    if (!(arg > 0)) throwUndefined(*this, x, y, sphere_ ? "r >= |R|" : "1 - (1 + k) c^2 r^2 <= 0");
    const double s = std::sqrt(arg);
    double f = c_ * rho / (1 + s), f1 = c_ / (2 * s), f2 = c_ * K_ / (4 * s * s * s);
    if (!a_.empty()) {
      // Horner in rho for sum a_i rho^(i+2) and its derivatives.
      double p0 = 0, p1 = 0, p2 = 0;
      for (size_t i = a_.size(); i-- > 0;) {
        const double e = double(i) + 2;
        p0 = p0 * rho + a_[i];
        p1 = p1 * rho + a_[i] * e;
        p2 = p2 * rho + a_[i] * e * (e - 1);
      }
      f += p0 * rho * rho;
      f1 += p1 * rho;
      f2 += p2;
    }
    SagDerivs d;
    d.z = f;
    d.zx = 2 * x * f1;
    d.zy = 2 * y * f1;
    d.zxx = 2 * f1 + 4 * x * x * f2;
    d.zxy = 4 * x * y * f2;
    d.zyy = 2 * f1 + 4 * y * y * f2;
    return d;
  }

  std::shared_ptr<const SagSurface> withVertex(double z) const override {
    return std::make_shared<ConicSag>(outline(), z, c_, k_, a_, sphere_);
  }

  bool sphereCurvature(double* c) const override {
    if (k_ != 0 || std::any_of(a_.begin(), a_.end(), [](double x) { return x != 0; })) return false;
    *c = c_;
    return true;
  }

  std::string describe() const override {
    std::ostringstream os;
    if (c_ == 0 && a_.empty()) return "plane";
    os << (sphere_ ? "sphere" : "asphere") << " R=" << radiusText(c_) << " m";
    if (!sphere_) {
      os << " k=" << num(k_);
      for (size_t i = 0; i < a_.size(); ++i)
        if (a_[i] != 0) os << " A" << (2 * i + 4) << "=" << num(a_[i]);
    }
    return os.str();
  }

 private:
  double c_, k_;
  std::vector<double> a_;
  bool sphere_;
  double K_;
};

// Exact torus, in the frame (x', y') rotated by the axis angle: the b-section Zb(y') = cb y'^2 / (1 + sqrt(1
// - cb^2 y'^2)) (a circle of radius Rb) is revolved about the line parallel to y' at distance Ra behind the
// vertex, so the x'-section through the vertex is a circle of radius Ra. With w = 1 - ca Zb and
// q = sqrt(w^2 - ca^2 x'^2):
//   Z = Zb + ca x'^2 / (w + q)            (= Ra - sign(Ra) sqrt((Ra - Zb)^2 - x'^2), without cancellation)
//   Z_x' = ca x' / q,  Z_y' = Zb' w / q,
//   Z_x'x' = ca w^2 / q^3,  Z_x'y' = ca^2 x' w Zb' / q^3,  Z_y'y' = Zb'' w / q + ca^3 x'^2 Zb'^2 / q^3,
// with Zb' = cb y' / sb, Zb'' = cb / sb^3, sb = sqrt(1 - cb^2 y'^2). ca = 0 is a cylinder with its axis
// along x'; then Z = Zb.
class ToricSag final : public SagSurface {
 public:
  ToricSag(Outline o, double z_vertex, double ca, double cb, double axis_rad, bool is_cylinder)
      : SagSurface(o, z_vertex), ca_(ca), cb_(cb), axis_(axis_rad), cos_(std::cos(axis_rad)),
        sin_(std::sin(axis_rad)), cylinder_(is_cylinder) {}

  bool defined(double x, double y) const override {
    const double xr = cos_ * x + sin_ * y, yr = -sin_ * x + cos_ * y;
    const double sb2 = 1 - cb_ * cb_ * yr * yr;
    if (!(sb2 > 0)) return false;
    const double zb = cb_ * yr * yr / (1 + std::sqrt(sb2));
    const double w = 1 - ca_ * zb;
    return w > 0 && w * w - ca_ * ca_ * xr * xr > 0;
  }

  SagDerivs sag(double x, double y) const override {
    const double xr = cos_ * x + sin_ * y, yr = -sin_ * x + cos_ * y;
    const double sb2 = 1 - cb_ * cb_ * yr * yr;
    if (!(sb2 > 0)) throwUndefined(*this, x, y, "|y'| >= |Rb| across the axis");
    const double sb = std::sqrt(sb2);
    const double zb = cb_ * yr * yr / (1 + sb);
    const double zb1 = cb_ * yr / sb, zb2 = cb_ / (sb2 * sb);
    const double w = 1 - ca_ * zb;
    const double q2 = w * w - ca_ * ca_ * xr * xr;
    if (!(w > 0) || !(q2 > 0)) throwUndefined(*this, x, y, "outside the torus along the axis direction");
    const double q = std::sqrt(q2), q3 = q2 * q;
    const double z = zb + ca_ * xr * xr / (w + q);
    const double zx = ca_ * xr / q, zy = zb1 * w / q;
    const double hxx = ca_ * w * w / q3;
    const double hxy = ca_ * ca_ * xr * w * zb1 / q3;
    const double hyy = zb2 * w / q + ca_ * ca_ * ca_ * xr * xr * zb1 * zb1 / q3;
    // Back to (x, y): gradient g = J^T g', Hessian H = J^T H' J with J = d(x', y')/d(x, y) = [[c, s], [-s, c]].
    const double c = cos_, s = sin_;
    SagDerivs d;
    d.z = z;
    d.zx = c * zx - s * zy;
    d.zy = s * zx + c * zy;
    d.zxx = c * c * hxx - 2 * c * s * hxy + s * s * hyy;
    d.zxy = c * s * hxx + (c * c - s * s) * hxy - c * s * hyy;
    d.zyy = s * s * hxx + 2 * c * s * hxy + c * c * hyy;
    return d;
  }

  std::shared_ptr<const SagSurface> withVertex(double z) const override {
    return std::make_shared<ToricSag>(outline(), z, ca_, cb_, axis_, cylinder_);
  }

  std::string describe() const override {
    std::ostringstream os;
    if (cylinder_)
      os << "cylinder R=" << radiusText(cb_) << " m, axis " << num(degrees(axis_)) << " deg";
    else
      os << "toric Ra=" << radiusText(ca_) << " m, Rb=" << radiusText(cb_) << " m, axis " << num(degrees(axis_))
         << " deg";
    return os.str();
  }

 private:
  double ca_, cb_, axis_, cos_, sin_;
  bool cylinder_;
};

void checkVertex(double z_vertex, const std::string& what) {
  if (!std::isfinite(z_vertex)) throw Error(what + ": z_vertex must be finite, got " + num(z_vertex));
}

}  // namespace

ParamDomain SagSurface::domain() const {
  const Vec2 lo = outline_.boundsMin(), hi = outline_.boundsMax();
  return {lo.x, hi.x, lo.y, hi.y};
}

SurfaceDerivs SagSurface::evaluate(double u, double v) const {
  const SagDerivs s = sag(u, v);
  SurfaceDerivs d;
  d.p = Vec3(u, v, z_vertex_ - s.z);
  d.du = Vec3(1, 0, -s.zx);
  d.dv = Vec3(0, 1, -s.zy);
  d.duu = Vec3(0, 0, -s.zxx);
  d.duv = Vec3(0, 0, -s.zxy);
  d.dvv = Vec3(0, 0, -s.zyy);
  return d;
}

// du × dv = (Z_x, Z_y, 1).
Vec3 SagSurface::normal(double u, double v) const {
  const SagDerivs s = sag(u, v);
  return glm::normalize(Vec3(s.zx, s.zy, 1.0));
}

Curvature SagSurface::curvature(double u, double v) const {
  return curvatureFromDerivs(evaluate(u, v), normal(u, v));
}

SurfacePoint SagSurface::sample(double u, double v, bool with_curvature) const {
  const SagDerivs s = sag(u, v);
  SurfacePoint r;
  r.p = Vec3(u, v, z_vertex_ - s.z);
  r.n = glm::normalize(Vec3(s.zx, s.zy, 1.0));
  if (with_curvature) {
    SurfaceDerivs d;
    d.p = r.p;
    d.du = Vec3(1, 0, -s.zx);
    d.dv = Vec3(0, 1, -s.zy);
    d.duu = Vec3(0, 0, -s.zxx);
    d.duv = Vec3(0, 0, -s.zxy);
    d.dvv = Vec3(0, 0, -s.zyy);
    r.k = curvatureFromDerivs(d, r.n);
  }
  return r;
}

SagSurfacePtr makePlane(Outline outline, double z_vertex) {
  checkVertex(z_vertex, "plane");
  return std::make_shared<PlaneSag>(outline, z_vertex);
}

SagSurfacePtr makeSphere(double radius, Outline outline, double z_vertex) {
  checkVertex(z_vertex, "sphere");
  return std::make_shared<ConicSag>(outline, z_vertex, curvatureOf(radius, "sphere"), 0.0, std::vector<double>{},
                                    true);
}

SagSurfacePtr makeAsphere(double radius, double conic, std::vector<double> coefficients, Outline outline,
                          double z_vertex) {
  checkVertex(z_vertex, "asphere");
  if (!std::isfinite(conic)) throw Error("asphere: conic constant must be finite, got " + num(conic));
  for (size_t i = 0; i < coefficients.size(); ++i)
    if (!std::isfinite(coefficients[i]))
      throw Error("asphere: coefficient A" + std::to_string(2 * i + 4) + " must be finite");
  return std::make_shared<ConicSag>(outline, z_vertex, curvatureOf(radius, "asphere"), conic,
                                    std::move(coefficients), false);
}

SagSurfacePtr makeToric(double radius_a, double radius_b, double axis_rad, Outline outline, double z_vertex) {
  checkVertex(z_vertex, "toric");
  if (!std::isfinite(axis_rad)) throw Error("toric: axis angle must be finite");
  return std::make_shared<ToricSag>(outline, z_vertex, curvatureOf(radius_a, "toric radius_a"),
                                    curvatureOf(radius_b, "toric radius_b"), axis_rad, false);
}

SagSurfacePtr makeCylinder(double radius, double axis_rad, Outline outline, double z_vertex) {
  checkVertex(z_vertex, "cylinder");
  if (!std::isfinite(axis_rad)) throw Error("cylinder: axis angle must be finite");
  return std::make_shared<ToricSag>(outline, z_vertex, 0.0, curvatureOf(radius, "cylinder"), axis_rad, true);
}

}  // namespace pvrr::cad
