// Outlines: rounded rectangles, ellipses, circles and star-shaped polygons, with exact boundary radii and the
// square-to-region map used by grid tessellation.
#include "cad/outline.h"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

#include "pvrr/base/error.h"

namespace pvrr::cad {
namespace {

bool finite2(Vec2 v) { return std::isfinite(v.x) && std::isfinite(v.y); }

std::string fmt(double x) {
  std::ostringstream os;
  os << std::setprecision(6) << x;
  return os.str();
}

double cross2(Vec2 a, Vec2 b) { return a.x * b.y - a.y * b.x; }

// Distance from a point (y0, y1) outside the ellipse with semi-axes e0 >= e1 > 0, in the first quadrant, to
// the ellipse. D. Eberly, "Distance from a Point to an Ellipse, an Ellipsoid, or a Hyperellipsoid"
// (Geometric Tools, 2013), bisection on the Lagrange multiplier.
double distanceToEllipse(double e0, double e1, double y0, double y1) {
  if (y1 > 0) {
    if (y0 > 0) {
      const double z0 = y0 / e0, z1 = y1 / e1;
      const double g = z0 * z0 + z1 * z1 - 1;
      if (g == 0) return 0;
      const double r0 = (e0 / e1) * (e0 / e1);
      const double n0 = r0 * z0;
      double s0 = z1 - 1, s1 = g < 0 ? 0 : std::hypot(n0, z1) - 1, s = 0;
      for (int i = 0; i < 200; ++i) {
        s = 0.5 * (s0 + s1);
        if (s == s0 || s == s1) break;
        const double a = n0 / (s + r0), b = z1 / (s + 1);
        const double f = a * a + b * b - 1;
        if (f > 0) s0 = s; else if (f < 0) s1 = s; else break;
      }
      const double x0 = r0 * y0 / (s + r0), x1 = y1 / (s + 1);
      return std::hypot(x0 - y0, x1 - y1);
    }
    return std::abs(y1 - e1);
  }
  const double numer0 = e0 * y0, denom0 = e0 * e0 - e1 * e1;
  if (numer0 < denom0) {
    const double xde0 = numer0 / denom0;
    const double x0 = e0 * xde0, x1 = e1 * std::sqrt(std::max(0.0, 1 - xde0 * xde0));
    return std::hypot(x0 - y0, x1);
  }
  return std::abs(y0 - e0);
}

double distanceToSegment(Vec2 p, Vec2 a, Vec2 b) {
  const Vec2 ab = b - a;
  const double l2 = glm::dot(ab, ab);
  const double t = l2 > 0 ? std::clamp(glm::dot(p - a, ab) / l2, 0.0, 1.0) : 0.0;
  return glm::length(p - (a + t * ab));
}

}  // namespace

Outline Outline::rectangle(double width, double height, double corner_radius, Vec2 centre) {
  if (!(width > 0) || !(height > 0) || !std::isfinite(width) || !std::isfinite(height))
    throw Error("rectangle outline: width and height must be finite and > 0, got " + fmt(width) + " x " +
                fmt(height));
  if (!(corner_radius >= 0) || corner_radius > 0.5 * std::min(width, height) * (1 + 1e-12))
    throw Error("rectangle outline " + fmt(width) + " x " + fmt(height) +
                ": corner radius must be in [0, min(width, height)/2], got " + fmt(corner_radius));
  if (!finite2(centre)) throw Error("rectangle outline: centre must be finite");
  Outline o;
  o.shape_ = Shape::Rectangle;
  o.width_ = width;
  o.height_ = height;
  o.corner_radius_ = std::min(corner_radius, 0.5 * std::min(width, height));
  o.centre_ = centre;
  o.lo_ = centre - 0.5 * Vec2(width, height);
  o.hi_ = centre + 0.5 * Vec2(width, height);
  return o;
}

Outline Outline::ellipse(double width, double height, Vec2 centre) {
  if (!(width > 0) || !(height > 0) || !std::isfinite(width) || !std::isfinite(height))
    throw Error("ellipse outline: width and height must be finite and > 0, got " + fmt(width) + " x " +
                fmt(height));
  if (!finite2(centre)) throw Error("ellipse outline: centre must be finite");
  Outline o;
  o.shape_ = Shape::Ellipse;
  o.width_ = width;
  o.height_ = height;
  o.centre_ = centre;
  o.lo_ = centre - 0.5 * Vec2(width, height);
  o.hi_ = centre + 0.5 * Vec2(width, height);
  return o;
}

Outline Outline::circle(double diameter, Vec2 centre) {
  if (!(diameter > 0) || !std::isfinite(diameter))
    throw Error("circle outline: diameter must be finite and > 0, got " + fmt(diameter));
  if (!finite2(centre)) throw Error("circle outline: centre must be finite");
  Outline o;
  o.shape_ = Shape::Circle;
  o.width_ = o.height_ = diameter;
  o.centre_ = centre;
  o.lo_ = centre - Vec2(0.5 * diameter);
  o.hi_ = centre + Vec2(0.5 * diameter);
  return o;
}

// The loop is stored counter-clockwise, rotated so that the angles about the centre increase from the first
// point; the check that each edge subtends a positive angle and the angles add up to one turn is the
// definition of "star-shaped about the centre" (the centre lies strictly inside the kernel).
Outline Outline::polygon(std::vector<Vec2> loop, Vec2 centre) {
  const size_t n = loop.size();
  if (n < 3) throw Error("polygon outline: needs at least 3 points, got " + std::to_string(n));
  if (!finite2(centre)) throw Error("polygon outline: centre must be finite");
  for (size_t i = 0; i < n; ++i)
    if (!finite2(loop[i])) throw Error("polygon outline: point " + std::to_string(i) + " is not finite");
  double area2 = 0;
  for (size_t i = 0; i < n; ++i) area2 += cross2(loop[i] - centre, loop[(i + 1) % n] - centre);
  if (area2 < 0) std::reverse(loop.begin(), loop.end());
  double turn = 0;
  for (size_t i = 0; i < n; ++i) {
    const Vec2 a = loop[i] - centre, b = loop[(i + 1) % n] - centre;
    const double cr = cross2(a, b);
    if (!(cr > 0))
      throw Error("polygon outline: not star-shaped about the centre (" + fmt(centre.x) + ", " + fmt(centre.y) +
                  "): edge from point " + std::to_string(i) + " does not turn counter-clockwise about it");
    turn += std::atan2(cr, glm::dot(a, b));
  }
  if (std::abs(turn - 2 * kPi) > 1e-6)
    throw Error("polygon outline: the loop winds " + fmt(turn / (2 * kPi)) +
                " times about the centre; expected once (a simple loop star-shaped about the centre)");
  std::vector<double> ang(n);
  for (size_t i = 0; i < n; ++i) ang[i] = std::atan2(loop[i].y - centre.y, loop[i].x - centre.x);
  const size_t first = size_t(std::min_element(ang.begin(), ang.end()) - ang.begin());
  std::rotate(loop.begin(), loop.begin() + long(first), loop.end());
  std::rotate(ang.begin(), ang.begin() + long(first), ang.end());
  for (size_t i = 1; i < n; ++i)
    while (ang[i] < ang[i - 1]) ang[i] += 2 * kPi;

  Outline o;
  o.shape_ = Shape::Polygon;
  o.centre_ = centre;
  o.lo_ = o.hi_ = loop[0];
  for (const Vec2& p : loop) {
    o.lo_ = glm::min(o.lo_, p);
    o.hi_ = glm::max(o.hi_, p);
  }
  o.width_ = o.hi_.x - o.lo_.x;
  o.height_ = o.hi_.y - o.lo_.y;
  o.loop_ = std::move(loop);
  o.loop_angles_ = std::move(ang);
  return o;
}

Vec2 Outline::boundsMin() const { return lo_; }
Vec2 Outline::boundsMax() const { return hi_; }

double Outline::boundaryRadius(double theta) const {
  const double c = std::cos(theta), s = std::sin(theta);
  switch (shape_) {
    case Shape::Circle:
      return 0.5 * width_;
    case Shape::Ellipse: {
      const double a = 0.5 * width_, b = 0.5 * height_;
      return 1.0 / std::hypot(c / a, s / b);
    }
    case Shape::Rectangle: {
      // By symmetry, work in the first quadrant with d = (|c|, |s|).
      const double dx = std::abs(c), dy = std::abs(s);
      const double hw = 0.5 * width_, hh = 0.5 * height_, r = corner_radius_;
      const double tx = dx > 0 ? hw / dx : kInf, ty = dy > 0 ? hh / dy : kInf;
      if (tx <= ty) {  // the ray leaves the box through the side x = hw
        if (tx * dy <= hh - r) return tx;
      } else if (ty * dx <= hw - r) {  // through the side y = hh
        return ty;
      }
      // Corner arc about C = (hw - r, hh - r): the larger root of |t d - C| = r. With b = d·C and the part of C
      // perpendicular to d, t = b + sqrt(r^2 - |C_perp|^2) (no cancellation: b >= 0 in this quadrant).
      const Vec2 d(dx, dy), cc(hw - r, hh - r);
      const double b = glm::dot(d, cc);
      const Vec2 perp = cc - b * d;
      return b + std::sqrt(std::max(0.0, r * r - glm::dot(perp, perp)));
    }
    case Shape::Polygon: {
      const size_t n = loop_.size();
      const double a0 = loop_angles_[0];
      double t = theta;
      t = a0 + std::fmod(t - a0, 2 * kPi);
      if (t < a0) t += 2 * kPi;
      // Edge k spans [ang[k], ang[k+1]) with ang[n] = ang[0] + 2 pi.
      const size_t k = size_t(std::upper_bound(loop_angles_.begin(), loop_angles_.end(), t) -
                              loop_angles_.begin()) - 1;
      const Vec2 p0 = loop_[k] - centre_, p1 = loop_[(k + 1) % n] - centre_;
      const Vec2 e = p1 - p0, d(c, s);
      const double den = cross2(d, e);
      if (!(den > 0)) return glm::length(p0);
      return cross2(p0, e) / den;
    }
  }
  return 0;
}

bool Outline::contains(Vec2 p, double tol) const {
  const Vec2 q = p - centre_;
  switch (shape_) {
    case Shape::Circle:
      return glm::length(q) <= 0.5 * width_ + tol;
    case Shape::Ellipse: {
      const double a = 0.5 * width_, b = 0.5 * height_;
      const double x = std::abs(q.x), y = std::abs(q.y);
      if ((x / a) * (x / a) + (y / b) * (y / b) <= 1) return true;
      if (tol <= 0) return false;
      return (a >= b ? distanceToEllipse(a, b, x, y) : distanceToEllipse(b, a, y, x)) <= tol;
    }
    case Shape::Rectangle: {
      // Signed distance of a rounded box (exact).
      const double r = corner_radius_;
      const Vec2 e = glm::abs(q) - (0.5 * Vec2(width_, height_) - Vec2(r));
      const double outside = glm::length(glm::max(e, Vec2(0)));
      const double inside = std::min(std::max(e.x, e.y), 0.0);
      return outside + inside - r <= tol;
    }
    case Shape::Polygon: {
      if (glm::length(q) <= boundaryRadius(std::atan2(q.y, q.x))) return true;
      if (tol <= 0) return false;
      for (size_t i = 0; i < loop_.size(); ++i)
        if (distanceToSegment(p, loop_[i], loop_[(i + 1) % loop_.size()]) <= tol) return true;
      return false;
    }
  }
  return false;
}

// The square [-1,1]^2 is first mapped linearly onto the bounding box (each half-axis to the box's extent on
// that side of the centre), then scaled radially about the centre so that the box's boundary lands on the
// outline: p = centre + dir * boundaryRadius(theta) * max(|s.x|, |s.y|). For a circle this is exactly the
// square's radial scaling; for a sharp rectangle it is the identity onto the box, so corners are grid
// vertices; an ellipse or rounded rectangle keeps the grid spread along its long side.
Vec2 Outline::fromSquare(Vec2 s) const {
  const double m = std::max(std::abs(s.x), std::abs(s.y));
  if (m == 0) return centre_;
  const Vec2 q(s.x * (s.x >= 0 ? hi_.x - centre_.x : centre_.x - lo_.x),
               s.y * (s.y >= 0 ? hi_.y - centre_.y : centre_.y - lo_.y));
  const double len = glm::length(q);
  return centre_ + q * (m * boundaryRadius(std::atan2(q.y, q.x)) / len);
}

std::string Outline::describe() const {
  std::ostringstream os;
  os << std::setprecision(6);
  switch (shape_) {
    case Shape::Rectangle:
      os << "rectangle " << width_ << " x " << height_;
      if (corner_radius_ > 0) os << ", corner radius " << corner_radius_;
      break;
    case Shape::Ellipse:
      os << "ellipse " << width_ << " x " << height_;
      break;
    case Shape::Circle:
      os << "circle diameter " << width_;
      break;
    case Shape::Polygon:
      os << "polygon of " << loop_.size() << " points, " << width_ << " x " << height_;
      break;
  }
  if (centre_ != Vec2(0)) os << " about (" << centre_.x << ", " << centre_.y << ")";
  return os.str();
}

}  // namespace pvrr::cad
