#include "pvrr/analysis/lensmap.h"

#include <tbb/parallel_for.h>

#include <chrono>
#include <cmath>

#include "pvrr/base/error.h"
#include "pvrr/optics/material.h"
#include "pvrr/optics/optics.h"

namespace pvrr {

namespace {

// Where the object-side rays of an infinite object's bundle start, back along the chief ray from its point on
// the object-side surface: beyond any spectacle lens's sag, so that the first hit is that surface.
constexpr double kBundleStart_m = 0.05;
// The focimeter's search for zero prism: Newton steps on the gaze with a central-difference Jacobian.
constexpr int kFocimeterIterations = 20;
constexpr double kFocimeterStep_rad = 1e-4;   // the Jacobian's half step
constexpr double kFocimeterTolerance = 1e-9;  // prism dioptres: far below any reading's 0.01
// Half step (in tangent) of the straight-ahead derivative J0 of the object's tangent by the gaze's: its
// truncation error (~1e-6 relative) is far below the 0.01 % distortion is printed to.
constexpr double kDistortionStep = 1e-3;
// gazeForObject: Newton steps with a central-difference Jacobian (half step kInverseStep in tangent).
constexpr int kInverseIterations = 30;
constexpr double kInverseStep = 1e-6;
constexpr double kInverseTolerance = 1e-12;

struct EyeFrame {
  Vec3 g, ex, ey;
};

EyeFrame eyeFrame(double gx_rad, double gy_rad) {
  const double cx = std::cos(gx_rad), sx = std::sin(gx_rad), cy = std::cos(gy_rad), sy = std::sin(gy_rad);
  return {Vec3(cy * sx, sy, -cy * cx), Vec3(cx, 0, sx), Vec3(-sy * sx, cy, sy * cx)};
}

// Tangents (x, y) / (-z) of a lens-frame direction.
Vec2 tangents(const Vec3& d) { return Vec2(d.x, d.y) / (-d.z); }

}  // namespace

SphCylAxis sphCylAxis(double vxx, double vxy, double vyy) {
  const double mean = 0.5 * (vxx + vyy);
  const double half = std::hypot(0.5 * (vxx - vyy), vxy);
  SphCylAxis r;
  r.sphere_d = mean + half;
  r.cylinder_d = -2 * half;
  // The sphere's eigenvector, counter-clockwise from the eye's right as the wearer sees it; TABO = 180 - phi.
  const double phi_deg = half > 0 ? degrees(0.5 * std::atan2(2 * vxy, vxx - vyy)) : 0.0;
  double axis = std::fmod(180.0 - phi_deg, 180.0);
  if (axis < 0) axis += 180.0;
  r.axis_deg = axis;
  return r;
}

Lensmap::Lensmap(const RayScene& rays, int element, LensmapOptions options)
    : rays_(rays),
      el_(element >= 0 && size_t(element) < rays.scene().elements.size()
              ? rays.scene().elements[size_t(element)]
              : throw Error("lensmap: no element " + std::to_string(element))),
      element_(element),
      options_(options) {
  if (el_.type != ElementType::Lens) throw Error("lensmap: element \"" + el_.name + "\" is not a lens");
  if (!(options_.rotation_centre_m > 0)) throw Error("lensmap: the rotation centre must lie behind the lens");
  if (!(options_.object_distance_m > options_.rotation_centre_m))
    throw Error("lensmap: the object distance must exceed the rotation centre's distance from the lens");
  n_d_ = el_.dispersion.index(kLineD_nm);
  centre_local_ = Vec3(0, 0, options_.rotation_centre_m);
  Vec2 a, b, c, d;
  const double e = kDistortionStep;
  have_j0_ = objectTangents(Vec2(0), t_obj0_) && objectTangents(Vec2(e, 0), a) && objectTangents(Vec2(-e, 0), b) &&
             objectTangents(Vec2(0, e), c) && objectTangents(Vec2(0, -e), d);
  j0x_ = (a - b) / (2 * e);
  j0y_ = (c - d) / (2 * e);
}

bool Lensmap::objectTangents(const Vec2& t_gaze, Vec2& t_obj) const {
  const double gx = std::atan(t_gaze.x), gy = std::atan(t_gaze.y * std::cos(gx));
  const Chief c = chief(eyeFrame(gx, gy).g, kLineD_nm);
  if (!c.ok) return false;
  t_obj = tangents(objectDirection(c));
  return true;
}

Vec2 Lensmap::paraxialObject(const Vec2& t_gaze) const {
  if (!have_j0_) return Vec2(std::nan(""));
  return t_obj0_ + j0x_ * t_gaze.x + j0y_ * t_gaze.y;
}

std::optional<Vec2> Lensmap::gazeForObject(const Vec2& t_obj) const {
  if (!have_j0_) return std::nullopt;
  const double det0 = j0x_.x * j0y_.y - j0y_.x * j0x_.y;
  if (!(std::abs(det0) > 0)) return std::nullopt;
  const Vec2 r0 = t_obj - t_obj0_;
  Vec2 t((j0y_.y * r0.x - j0y_.x * r0.y) / det0, (-j0x_.y * r0.x + j0x_.x * r0.y) / det0);
  for (int it = 0; it < kInverseIterations; ++it) {
    Vec2 f, a, b, c, d;
    if (!objectTangents(t, f)) return std::nullopt;
    f -= t_obj;
    if (glm::length(f) < kInverseTolerance) return t;
    const double e = kInverseStep;
    if (!objectTangents(t + Vec2(e, 0), a) || !objectTangents(t - Vec2(e, 0), b) ||
        !objectTangents(t + Vec2(0, e), c) || !objectTangents(t - Vec2(0, e), d))
      return std::nullopt;
    const Vec2 jx = (a - b) / (2 * e), jy = (c - d) / (2 * e);
    const double det = jx.x * jy.y - jy.x * jx.y;
    if (!(std::abs(det) > 0)) return std::nullopt;
    t -= Vec2((jy.y * f.x - jy.x * f.y) / det, (-jx.y * f.x + jx.x * f.y) / det);
  }
  return std::nullopt;
}

Lensmap::Chief Lensmap::chief(const Vec3& g, double wavelength_nm) const {
  Chief c;
  const double n = el_.dispersion.index(wavelength_nm);
  const Vec3 o = el_.toWorldPoint(centre_local_), d = glm::normalize(el_.toWorldDir(g));
  const RayHit h0 = rays_.intersectElementSurface(element_, 0, o, d);
  if (!h0.hit()) {
    c.reason = "miss";
    return c;
  }
  const Refraction r0 = refract(d, h0.normal, 1.0, n);
  const RayHit h1 = rays_.intersectElementSurface(element_, 1, h0.point, r0.direction);
  if (!h1.hit()) {
    c.reason = "miss";
    return c;
  }
  const Refraction r1 = refract(r0.direction, h1.normal, n, 1.0);
  if (r1.tir) {
    c.reason = "tir";
    return c;
  }
  c.ok = true;
  c.front = el_.toLocalPoint(h0.point);
  c.back = el_.toLocalPoint(h1.point);
  c.out = glm::normalize(el_.toLocalDir(r1.direction));
  return c;
}

Vec3 Lensmap::objectDirection(const Chief& c) const {
  if (!std::isfinite(options_.object_distance_m)) return c.out;
  const Vec3 w = c.back - centre_local_;
  const double b = glm::dot(w, c.out);
  const double s = -b + std::sqrt(b * b - (glm::dot(w, w) - options_.object_distance_m * options_.object_distance_m));
  return glm::normalize(w + s * c.out);
}

bool Lensmap::bundle(const Chief& c, const Vec3& g, const Vec3& ex, const Vec3& ey, const Vec3& at, double v[4],
                     std::string& reason) const {
  const double n = n_d_;
  const double delta = options_.bundle_offset_m;
  Vec3 e1 = ex - glm::dot(ex, c.out) * c.out;
  e1 = glm::normalize(e1);
  const Vec3 e2 = glm::cross(c.out, e1);
  const bool near = std::isfinite(options_.object_distance_m);
  Vec3 q(0);
  if (near) {
    const Vec3 w = c.back - centre_local_;
    const double b = glm::dot(w, c.out);
    const double s = -b + std::sqrt(b * b - (glm::dot(w, w) - options_.object_distance_m * options_.object_distance_m));
    q = c.back + s * c.out;
  }
  // h (position on the plane through `at` normal to g) and s (slope) of each of the 4 rays.
  Vec2 h[4], s[4];
  const int di[4] = {1, -1, 0, 0}, dj[4] = {0, 0, 1, -1};
  for (int k = 0; k < 4; ++k) {
    const Vec3 target = c.back + delta * (double(di[k]) * e1 + double(dj[k]) * e2);
    Vec3 o, d;
    if (near) {
      o = q;
      d = glm::normalize(target - q);
    } else {
      o = target + kBundleStart_m * c.out;
      d = -c.out;
    }
    const Vec3 ow = el_.toWorldPoint(o), dw = glm::normalize(el_.toWorldDir(d));
    const RayHit h1 = rays_.intersectElementSurface(element_, 1, ow, dw);
    if (!h1.hit()) {
      reason = "miss";
      return false;
    }
    const Refraction r1 = refract(dw, h1.normal, 1.0, n);
    const RayHit h0 = rays_.intersectElementSurface(element_, 0, h1.point, r1.direction);
    if (!h0.hit()) {
      reason = "miss";
      return false;
    }
    const Refraction r0 = refract(r1.direction, h0.normal, n, 1.0);
    if (r0.tir) {
      reason = "tir";
      return false;
    }
    const Vec3 p = el_.toLocalPoint(h0.point), dir = glm::normalize(el_.toLocalDir(r0.direction));
    const double t = glm::dot(at - p, g) / glm::dot(dir, g);
    const Vec3 x = p + t * dir - at;
    h[k] = Vec2(glm::dot(x, ex), glm::dot(x, ey));
    s[k] = Vec2(glm::dot(dir, ex), glm::dot(dir, ey)) / glm::dot(dir, -g);
  }
  // Columns: derivatives by the two offsets (the common factor 1 / (2 delta) cancels in V = -Js Jh^-1).
  const Vec2 h1 = h[0] - h[1], h2 = h[2] - h[3], s1 = s[0] - s[1], s2 = s[2] - s[3];
  const double det = h1.x * h2.y - h2.x * h1.y;
  if (!(std::abs(det) > 0)) {
    reason = "degenerate bundle";
    return false;
  }
  // Jh^-1 = [h2.y, -h2.x; -h1.y, h1.x] / det; V = -[s1 s2] Jh^-1.
  v[0] = -(s1.x * h2.y - s2.x * h1.y) / det;   // Vxx
  v[1] = -(-s1.x * h2.x + s2.x * h1.x) / det;  // Vxy
  v[2] = -(s1.y * h2.y - s2.y * h1.y) / det;   // Vyx
  v[3] = -(-s1.y * h2.x + s2.y * h1.x) / det;  // Vyy
  return true;
}

LensmapPoint Lensmap::evaluate(double gaze_x_deg, double gaze_y_deg, const LensmapPoint* rx) const {
  LensmapPoint p;
  p.gaze_x_deg = gaze_x_deg;
  p.gaze_y_deg = gaze_y_deg;
  const EyeFrame f = eyeFrame(radians(gaze_x_deg), radians(gaze_y_deg));
  const Chief c = chief(f.g, kLineD_nm);
  if (!c.ok) {
    p.reason = c.reason;
    return p;
  }
  double v[4];
  const Vec3 at = centre_local_ + options_.rotation_centre_m * f.g;
  if (!bundle(c, f.g, f.ex, f.ey, at, v, p.reason)) return p;
  const Chief cf = chief(f.g, kLineF_nm), cc = chief(f.g, kLineC_nm);
  if (!cf.ok || !cc.ok) {
    p.reason = !cf.ok ? cf.reason : cc.reason;
    return p;
  }
  p.valid = true;
  p.lens_x_mm = 1e3 * c.front.x;
  p.lens_y_mm = 1e3 * c.front.y;
  const double v_object = std::isfinite(options_.object_distance_m)
                              ? -1.0 / (options_.object_distance_m - options_.rotation_centre_m)
                              : 0.0;
  p.asymmetry_d = std::abs(v[1] - v[2]);
  p.vxx = v[0] - v_object;
  p.vxy = 0.5 * (v[1] + v[2]);
  p.vyy = v[3] - v_object;
  const SphCylAxis sca = sphCylAxis(p.vxx, p.vxy, p.vyy);
  p.sphere_d = sca.sphere_d;
  p.cylinder_d = sca.cylinder_d;
  p.axis_deg = sca.axis_deg;
  p.mean_power_d = sca.sphere_d + 0.5 * sca.cylinder_d;
  // Tangential direction: the lens axis (+z) projected onto the eye's frame, pointing away from the axis.
  Vec2 t(-glm::dot(Vec3(0, 0, 1), f.ex), -glm::dot(Vec3(0, 0, 1), f.ey));
  t = glm::length(t) > 1e-12 ? glm::normalize(t) : Vec2(1, 0);
  p.tangential_d = t.x * t.x * p.vxx + 2 * t.x * t.y * p.vxy + t.y * t.y * p.vyy;
  p.sagittal_d = t.y * t.y * p.vxx - 2 * t.x * t.y * p.vxy + t.x * t.x * p.vyy;
  if (rx) {
    const SphCylAxis d = sphCylAxis(p.vxx - rx->vxx, p.vxy - rx->vxy, p.vyy - rx->vyy);
    p.power_error_d = d.sphere_d + 0.5 * d.cylinder_d;
    p.unwanted_cylinder_d = -d.cylinder_d;
    // Prentice: -100 V0 d, d the decentration on the eye-side surface (m), V0 the prescription's matrix.
    p.prentice_h = -100 * (rx->vxx * c.front.x + rx->vxy * c.front.y);
    p.prentice_v = -100 * (rx->vxy * c.front.x + rx->vyy * c.front.y);
  }
  const double oz = glm::dot(c.out, f.g);
  p.prism_h = 100 * glm::dot(c.out, f.ex) / oz;
  p.prism_v = 100 * glm::dot(c.out, f.ey) / oz;
  const Vec3 od = objectDirection(c);
  p.object_x_deg = degrees(std::atan2(od.x, -od.z));
  p.object_y_deg = degrees(std::atan2(od.y, std::hypot(od.x, od.z)));
  p.lateral_colour_arcmin = arcminutes(angleBetween(cf.out, cc.out));
  const Vec2 tg = Vec2(f.g.x, f.g.y) / (-f.g.z);
  // The paraxial image of this object: J0^-1 (t_obj - t_obj0).
  const Vec2 r = tangents(od) - t_obj0_;
  const double det = j0x_.x * j0y_.y - j0y_.x * j0x_.y;
  const Vec2 paraxial = Vec2(j0y_.y * r.x - j0y_.x * r.y, -j0x_.y * r.x + j0x_.x * r.y) / det;
  p.distortion_pct = !have_j0_ || !(std::abs(det) > 0) ? std::nan("")
                     : glm::length(tg) < 1e-12         ? 0.0
                                                       : 100 * (glm::length(tg) / glm::length(paraxial) - 1);
  return p;
}

LensmapResult::Focimeter Lensmap::focimeter() const {
  // The focimeter measures with a parallel beam: an object at infinity, whatever the map's object distance.
  if (std::isfinite(options_.object_distance_m)) {
    LensmapOptions o = options_;
    o.object_distance_m = kInf;
    return Lensmap(rays_, element_, o).focimeter();
  }
  LensmapResult::Focimeter r;
  auto prism = [&](double gx, double gy, Vec2& out) {
    const EyeFrame f = eyeFrame(gx, gy);
    const Chief c = chief(f.g, kLineD_nm);
    if (!c.ok) return false;
    const double oz = glm::dot(c.out, f.g);
    out = Vec2(glm::dot(c.out, f.ex), glm::dot(c.out, f.ey)) * (100 / oz);
    return true;
  };
  double gx = 0, gy = 0;
  Vec2 p0;
  for (int it = 0;; ++it) {
    if (!prism(gx, gy, p0)) {
      r.reason = "the search left the lens";
      return r;
    }
    r.iterations = it;
    r.residual_prism = glm::length(p0);
    if (r.residual_prism < kFocimeterTolerance) break;
    if (it == kFocimeterIterations) {
      r.reason = "no convergence to zero prism in " + std::to_string(kFocimeterIterations) + " steps";
      return r;
    }
    Vec2 a, b, c, d;
    const double e = kFocimeterStep_rad;
    if (!prism(gx + e, gy, a) || !prism(gx - e, gy, b) || !prism(gx, gy + e, c) || !prism(gx, gy - e, d)) {
      r.reason = "the search left the lens";
      return r;
    }
    const Vec2 jx = (a - b) / (2 * e), jy = (c - d) / (2 * e);
    const double det = jx.x * jy.y - jy.x * jx.y;
    if (!(std::abs(det) > 0)) {
      r.reason = "prism does not change with gaze";
      return r;
    }
    gx -= (jy.y * p0.x - jy.x * p0.y) / det;
    gy -= (-jx.y * p0.x + jx.x * p0.y) / det;
  }
  const EyeFrame f = eyeFrame(gx, gy);
  const Chief c = chief(f.g, kLineD_nm);
  double v[4];
  std::string why;
  if (!bundle(c, f.g, f.ex, f.ey, c.front, v, why)) {
    r.reason = why;
    return r;
  }
  const SphCylAxis s = sphCylAxis(v[0], 0.5 * (v[1] + v[2]), v[3]);
  r.found = true;
  r.gaze_x_deg = degrees(gx);
  r.gaze_y_deg = degrees(gy);
  r.lens_x_mm = 1e3 * c.front.x;
  r.lens_y_mm = 1e3 * c.front.y;
  r.sphere_d = s.sphere_d;
  r.cylinder_d = s.cylinder_d;
  r.axis_deg = s.axis_deg;
  return r;
}

LensmapResult::Progressive Lensmap::progressive(const LensmapPoint& rx) const {
  LensmapResult::Progressive pr;
  pr.far_gaze_y_deg = rx.gaze_y_deg;
  pr.far_lens_y_mm = rx.lens_y_mm;
  pr.far_mean_d = rx.mean_power_d;
  // Down the meridian from straight ahead, while the rays pass.
  std::vector<LensmapPoint> down;
  for (double gy = 0; gy >= -options_.gaze_max_deg - 1e-9; gy -= kProgressiveStep_deg) {
    LensmapPoint p = evaluate(0, gy, &rx);
    if (!p.valid) break;
    down.push_back(p);
  }
  double add = 0;
  for (const LensmapPoint& p : down) add = std::max(add, p.mean_power_d - rx.mean_power_d);
  if (add < kProgressiveMinAdd_d) return pr;
  pr.detected = true;
  pr.add_d = add;
  // The first gaze reaching `share` of the add, interpolated between samples.
  auto reach = [&](double share, double& gy, double& lens_y) {
    const double target = rx.mean_power_d + share * add;
    for (size_t i = 1; i < down.size(); ++i)
      if (down[i].mean_power_d >= target) {
        const LensmapPoint &a = down[i - 1], &b = down[i];
        const double t = (target - a.mean_power_d) / (b.mean_power_d - a.mean_power_d);
        gy = a.gaze_y_deg + t * (b.gaze_y_deg - a.gaze_y_deg);
        lens_y = a.lens_y_mm + t * (b.lens_y_mm - a.lens_y_mm);
        return;
      }
  };
  double lens_y85 = 0, gy85 = 0, lens_y50 = 0;
  reach(0.95, pr.near_gaze_y_deg, pr.near_lens_y_mm);
  pr.near_mean_d = evaluate(0, pr.near_gaze_y_deg, &rx).mean_power_d;
  reach(0.85, gy85, lens_y85);
  pr.corridor_length_mm = pr.far_lens_y_mm - lens_y85;
  reach(0.5, pr.corridor_mid_gaze_y_deg, lens_y50);
  // Across the corridor at its middle: bisect each side for the unwanted cylinder's 0.5 D.
  auto edge = [&](double sign) {
    auto cyl = [&](double gx) {
      const LensmapPoint p = evaluate(gx, pr.corridor_mid_gaze_y_deg, &rx);
      return p.valid ? p.unwanted_cylinder_d - kCorridorCylinder_d : kInf;
    };
    double inner = 0, outer = 0;
    if (cyl(0) >= 0) return std::nan("");
    for (outer = kProgressiveStep_deg; outer <= options_.gaze_max_deg; outer += kProgressiveStep_deg) {
      if (cyl(sign * outer) >= 0) break;
      inner = outer;
    }
    if (outer > options_.gaze_max_deg) return std::nan("");
    for (int it = 0; it < 40; ++it) {
      const double mid = 0.5 * (inner + outer);
      (cyl(sign * mid) < 0 ? inner : outer) = mid;
    }
    return evaluate(sign * inner, pr.corridor_mid_gaze_y_deg, &rx).lens_x_mm;
  };
  pr.corridor_width_mm = edge(1) - edge(-1);
  return pr;
}

LensmapResult Lensmap::run() const {
  const auto t0 = std::chrono::steady_clock::now();
  LensmapResult r;
  r.element = el_.name;
  r.options = options_;
  r.n_d = n_d_;
  r.abbe = el_.dispersion.abbe();
  r.centre = evaluate(0, 0);
  if (!r.centre.valid)
    throw Error("lensmap: element \"" + el_.name + "\": the straight-ahead gaze does not pass the lens (" +
                r.centre.reason + ")");
  const int n = options_.grid;
  r.points.resize(size_t(n) * size_t(n));
  tbb::parallel_for(0, n * n, [&](int i) {
    const int ix = i % n, iy = i / n;
    const double gx = n > 1 ? -options_.gaze_max_deg + 2 * options_.gaze_max_deg * ix / (n - 1) : 0.0;
    const double gy = n > 1 ? -options_.gaze_max_deg + 2 * options_.gaze_max_deg * iy / (n - 1) : 0.0;
    r.points[size_t(i)] = evaluate(gx, gy, &r.centre);
  });
  for (const LensmapPoint& p : r.points)
    if (!p.valid) {
      ++r.empty;
      (p.reason == "tir" ? r.empty_tir : r.empty_miss)++;
    }
  r.focimeter = focimeter();
  r.progressive = progressive(r.centre);
  r.elapsed_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

}  // namespace pvrr
