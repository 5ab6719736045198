// An independent as-worn calculation for the lens map tests: written apart from pvrr/analysis/lensmap.cpp and
// sharing none of its code (no RayScene, no optics.h). Its own ray/sag intersection (Newton on the sag
// function of cad/sag.h, the surfaces' definition), its own vector Snell, and a different way to the wavefront:
// the optical path lengths of a 7 x 7 grid of rays from a distant object, whose equal-path surface (the
// wavefront) is fitted by a quartic polynomial on the plane tangent to the vertex sphere; its second
// derivatives are the vergence matrix. (The product differentiates ray directions by ray positions instead.)
// Object at infinity only.
#pragma once
#include <Eigen/Dense>

#include <cmath>
#include <optional>

#include "cad/lens.h"
#include "pvrr/base/math.h"

namespace pvrr::test {

struct WornReading {
  double vxx = 0, vxy = 0, vyy = 0;  // vergence matrix in the eye's frame (e_x right, e_y up), dioptres
  double prism_h = 0, prism_v = 0;   // prism dioptres, base right / up positive
  double sphere() const { return 0.5 * (vxx + vyy) + std::hypot(0.5 * (vxx - vyy), vxy); }
  double cylinder() const { return -2 * std::hypot(0.5 * (vxx - vyy), vxy); }
  double mean() const { return 0.5 * (vxx + vyy); }
};

class WornReference {
 public:
  // `lens` in its local frame (+z towards the eye); `n` the index; rotation centre r behind the eye-side vertex.
  WornReference(const cad::LensSolid& lens, double n, double r) : lens_(lens), n_(n), r_(r) {}

  std::optional<WornReading> at(double gaze_x_deg, double gaze_y_deg) const {
    const double a = gaze_x_deg * kPi / 180, b = gaze_y_deg * kPi / 180;
    // Fick: turn right about the vertical, then up about the turned horizontal axis.
    const Vec3 g(std::cos(b) * std::sin(a), std::sin(b), -std::cos(b) * std::cos(a));
    const Vec3 ex(std::cos(a), 0, std::sin(a));
    const Vec3 ey = glm::cross(-g, ex);  // up: the eye looks along g, right-handed (right, up, back)
    const Vec3 c(0, 0, r_);
    // Chief ray: eye side out to the object.
    Vec3 p = c, d = g;
    if (!cross(*lens_.front, p, d, 1.0, n_) || !cross(*lens_.back, p, d, n_, 1.0)) return std::nullopt;
    const Vec3 out = d, back_point = p;
    WornReading w;
    w.prism_h = 100 * glm::dot(out, ex) / glm::dot(out, g);
    w.prism_v = 100 * glm::dot(out, ey) / glm::dot(out, g);
    // A plane wave from the object: rays along -out through a grid on a plane normal to it.
    const Vec3 e1 = glm::normalize(glm::cross(out, Vec3(0, 1, 0)));
    const Vec3 e2 = glm::cross(e1, out);
    const Vec3 origin = back_point + 0.05 * out;
    const Vec3 vs = c + r_ * g;  // the vertex sphere's point on the chief ray; the plane T is normal to g there
    constexpr int kGrid = 7;
    constexpr double kRadius_m = 3e-4;
    struct Sample {
      Vec3 x, d;
      double opl;
    };
    std::vector<Sample> samples;
    double opl_chief = 0;
    for (int i = 0; i < kGrid; ++i)
      for (int j = 0; j < kGrid; ++j) {
        const double u = kRadius_m * (2.0 * i / (kGrid - 1) - 1), v = kRadius_m * (2.0 * j / (kGrid - 1) - 1);
        Vec3 q = origin + u * e1 + v * e2, dir = -out;
        double opl = 0;
        const Vec3 q0 = q;
        if (!cross(*lens_.back, q, dir, 1.0, n_)) return std::nullopt;
        opl += glm::length(q - q0);
        const Vec3 q1 = q;
        if (!cross(*lens_.front, q, dir, n_, 1.0)) return std::nullopt;
        opl += n_ * glm::length(q - q1);
        const double t = glm::dot(vs - q, g) / glm::dot(dir, g);  // to the plane T (may be negative: virtual)
        const Vec3 x = q + t * dir;
        opl += t;
        samples.push_back({x, dir, opl});
        if (i == kGrid / 2 && j == kGrid / 2) opl_chief = opl;
      }
    // The equal-path surface through the chief ray's point, in (e_x, e_y, propagation -g) about vs.
    Eigen::MatrixXd m(samples.size(), 15);
    Eigen::VectorXd z(samples.size());
    for (size_t k = 0; k < samples.size(); ++k) {
      const Vec3 wp = samples[k].x + (opl_chief - samples[k].opl) * samples[k].d - vs;
      const double x = glm::dot(wp, ex) / kRadius_m, y = glm::dot(wp, ey) / kRadius_m;
      z(Eigen::Index(k)) = glm::dot(wp, -g);
      int col = 0;
      for (int deg = 0; deg <= 4; ++deg)
        for (int py = 0; py <= deg; ++py) m(Eigen::Index(k), col++) = std::pow(x, deg - py) * std::pow(y, py);
    }
    const Eigen::VectorXd coef = m.colPivHouseholderQr().solve(z);
    // Columns 3, 4, 5: x^2, x y, y^2 (in units of kRadius_m).
    const double s = 1.0 / (kRadius_m * kRadius_m);
    w.vxx = 2 * coef(3) * s;
    w.vxy = coef(4) * s;
    w.vyy = 2 * coef(5) * s;
    return w;
  }

 private:
  // Moves the ray (p, d) to its hit on sag surface s and refracts it from index n1 into n2. False: no hit
  // within the outline, no convergence, or total internal reflection.
  static bool cross(const cad::SagSurface& s, Vec3& p, Vec3& d, double n1, double n2) {
    double t = (s.zVertex() - p.z) / d.z;
    bool converged = false;
    for (int it = 0; it < 50 && !converged; ++it) {
      const Vec3 x = p + t * d;
      const cad::SagDerivs z = s.sag(x.x, x.y);
      const double f = x.z - (s.zVertex() - z.z);
      const double df = d.z + z.zx * d.x + z.zy * d.y;
      const double step = f / df;
      t -= step;
      converged = std::abs(step) < 1e-15;
    }
    if (!converged) return false;
    p = p + t * d;
    if (!s.outline().contains(Vec2(p.x, p.y), 0)) return false;
    const cad::SagDerivs z = s.sag(p.x, p.y);
    Vec3 nrm = glm::normalize(Vec3(z.zx, z.zy, 1));
    if (glm::dot(nrm, d) > 0) nrm = -nrm;
    const double eta = n1 / n2, ci = -glm::dot(d, nrm);
    const double k = 1 - eta * eta * (1 - ci * ci);
    if (k < 0) return false;
    d = glm::normalize(eta * d + (eta * ci - std::sqrt(k)) * nrm);
    return true;
  }

  const cad::LensSolid& lens_;
  double n_, r_;
};

}  // namespace pvrr::test
