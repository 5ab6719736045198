// Differential geometry from derivatives (normals, limits at poles, principal curvatures) and outlines
// (boundary radii, fromSquare, contains).
#include <gtest/gtest.h>

#include <cmath>

#include "pvrr/base/error.h"
#include "cad/outline.h"
#include "cad/surface.h"

namespace pvrr::cad {
namespace {

// Closed-form inputs of size ~1 go through a few dozen flops: roundoff is a few ulps.
constexpr double kRoundoff = 1e-13;
// Boundary points of outlines (the target).
constexpr double kOnOutline = 1e-12;

// Derivatives of the graph z = f(x, y) = 0.5 (x, y) H (x, y)^T at the origin under the sheared, scaled
// parametrisation (x, y) = J (u, v), J = [[1, 0.3], [0, 0.8]]. The principal axes of H are at angle `axis`
// with curvatures of the graph alpha (along axis) and beta; seen from the +z side (du × dv = +z) the surface
// bends towards the normal where alpha > 0, so the convention of surface.h gives k = -alpha, -beta.
SurfaceDerivs graphDerivs(double alpha, double beta, double axis) {
  const double c = std::cos(axis), s = std::sin(axis);
  // H = Rot diag(alpha, beta) Rot^T.
  const double hxx = alpha * c * c + beta * s * s, hxy = (alpha - beta) * c * s, hyy = alpha * s * s + beta * c * c;
  const double j11 = 1, j12 = 0.3, j21 = 0, j22 = 0.8;
  SurfaceDerivs d;
  d.p = Vec3(0);
  d.du = Vec3(j11, j21, 0);
  d.dv = Vec3(j12, j22, 0);
  auto h = [&](double a1, double a2, double b1, double b2) { return a1 * (hxx * b1 + hxy * b2) + a2 * (hxy * b1 + hyy * b2); };
  d.duu = Vec3(0, 0, h(j11, j21, j11, j21));
  d.duv = Vec3(0, 0, h(j11, j21, j12, j22));
  d.dvv = Vec3(0, 0, h(j12, j22, j12, j22));
  return d;
}

TEST(Surface, CurvatureOfASaddleUnderAShearedParametrisation) {
  const double alpha = 2.0, beta = -3.0, axis = radians(25);
  const SurfaceDerivs d = graphDerivs(alpha, beta, axis);
  const Vec3 n = normalFromDerivs(d);
  EXPECT_EQ(n, Vec3(0, 0, 1));
  const Curvature k = curvatureFromDerivs(d, n);
  EXPECT_NEAR(k.k1, 3.0, kRoundoff);  // -beta
  EXPECT_NEAR(k.k2, -2.0, kRoundoff);  // -alpha
  const Vec3 axis_a(std::cos(axis), std::sin(axis), 0), axis_b(-std::sin(axis), std::cos(axis), 0);
  EXPECT_NEAR(std::abs(glm::dot(k.dir1, axis_b)), 1.0, kRoundoff);
  EXPECT_NEAR(std::abs(glm::dot(k.dir2, axis_a)), 1.0, kRoundoff);
  EXPECT_NEAR(glm::dot(glm::cross(k.dir1, k.dir2), n), 1.0, kRoundoff);  // (dir1, dir2, n) right-handed
  EXPECT_NEAR(k.mean(), 0.5, kRoundoff);
  EXPECT_NEAR(k.gaussian(), -6.0, 10 * kRoundoff);
}

TEST(Surface, CurvatureSignFollowsTheNormal) {
  // A bowl z = (x^2 + y^2)/2 seen from +z is concave: k = -1; with the normal reversed it is convex: +1.
  const SurfaceDerivs d = graphDerivs(1.0, 1.0, 0.0);
  const Curvature up = curvatureFromDerivs(d, Vec3(0, 0, 1));
  const Curvature down = curvatureFromDerivs(d, Vec3(0, 0, -1));
  EXPECT_NEAR(up.k1, -1.0, kRoundoff);
  EXPECT_NEAR(up.k2, -1.0, kRoundoff);
  EXPECT_NEAR(down.k1, 1.0, kRoundoff);
  EXPECT_NEAR(down.k2, 1.0, kRoundoff);
}

// Sphere in polar coordinates, (u, v) = (theta, phi) on [theta0, theta1] x [0, 2 pi]: du × dv is outward; the
// poles theta = 0 and theta = pi have dv = 0.
class PolarSphere : public Surface {
 public:
  PolarSphere(double r, double t0, double t1) : r_(r), t0_(t0), t1_(t1) {}
  ParamDomain domain() const override { return {t0_, t1_, 0, 2 * kPi}; }
  SurfaceDerivs evaluate(double u, double v) const override {
    const double su = std::sin(u), cu = std::cos(u), sv = std::sin(v), cv = std::cos(v);
    SurfaceDerivs d;
    d.p = r_ * Vec3(su * cv, su * sv, cu);
    d.du = r_ * Vec3(cu * cv, cu * sv, -su);
    d.dv = r_ * Vec3(-su * sv, su * cv, 0);
    d.duu = -d.p;
    d.duv = r_ * Vec3(-cu * sv, cu * cv, 0);
    d.dvv = r_ * Vec3(-su * cv, -su * sv, 0);
    return d;
  }
  std::string describe() const override { return "polar sphere"; }

 private:
  double r_, t0_, t1_;
};

TEST(Surface, NormalAtAPoleIsTheLimitFromInside) {
  // North pole at u = u0 (approached with u increasing) and south pole at u = u1 (approached decreasing):
  // both outward.
  const PolarSphere north(1.5, 0.0, 1.0), south(1.5, 2.0, kPi);
  for (double v : {0.0, 0.4, 2.0, 5.0}) {
    EXPECT_LE(angleBetween(north.normal(0.0, v), Vec3(0, 0, 1)), kRoundoff);
    EXPECT_LE(angleBetween(south.normal(kPi, v), Vec3(0, 0, -1)), kRoundoff);
  }
  // The bare function takes the sign of the step; from the other side the limit flips.
  const SurfaceDerivs d = north.evaluate(0.0, 0.7);
  EXPECT_LE(angleBetween(normalFromDerivs(d), Vec3(0, 0, 1)), kRoundoff);
  EXPECT_LE(angleBetween(normalFromDerivs(d, -1, 1), Vec3(0, 0, -1)), kRoundoff);
}

TEST(Surface, NormalAtACollapsedVEdge) {
  // Swap the roles of u and v: (u, v) = (phi, theta), so du vanishes at theta = 0 and du × dv is inward.
  const PolarSphere s(2.0, 0.0, 1.0);
  SurfaceDerivs d = s.evaluate(0.0, 1.1);
  std::swap(d.du, d.dv);
  std::swap(d.duu, d.dvv);
  EXPECT_LE(angleBetween(normalFromDerivs(d), Vec3(0, 0, -1)), kRoundoff);
  // Nearby, off the pole, the plain cross product agrees in orientation.
  SurfaceDerivs e = s.evaluate(1e-3, 1.1);
  std::swap(e.du, e.dv);
  EXPECT_LT(glm::normalize(glm::cross(e.du, e.dv)).z, -0.99);
}

TEST(Surface, ApexNormalFromSecondOrder) {
  // p(u, v) = (u^2, v^2, u v): at the origin du = dv = 0, duu = (2,0,0), dvv = (0,2,0), duv = (0,0,1).
  SurfaceDerivs d{};  // value-initialised: glm vectors are not zeroed by default construction
  d.duu = Vec3(2, 0, 0);
  d.dvv = Vec3(0, 2, 0);
  d.duv = Vec3(0, 0, 1);
  // (duu + duv) × (duv + dvv) = (2,0,1) × (0,2,1) = (-2, -2, 4).
  EXPECT_LE(angleBetween(normalFromDerivs(d), Vec3(-2, -2, 4)), kRoundoff);
  EXPECT_EQ(normalFromDerivs(SurfaceDerivs{}), Vec3(0));
}

TEST(Surface, CurvatureAtAndNearAPoleIsFinite) {
  const double r = 1.5;
  const PolarSphere s(r, 0.0, 1.0);
  for (double u : {0.0, 1e-12, 1e-7, 1e-3})
    for (double v : {0.0, 1.0, 3.0}) {
      const Curvature k = s.curvature(u, v);
      EXPECT_NEAR(k.k1 * r, 1.0, 1e-9) << u;
      EXPECT_NEAR(k.k2 * r, 1.0, 1e-9) << u;
    }
}

// Independent boundary tests: the residual of each shape's implicit equation at a point.
double roundedRectResidual(Vec2 p, double w, double h, double r) {
  const double x = std::abs(p.x), y = std::abs(p.y), hw = 0.5 * w, hh = 0.5 * h;
  if (x > hw - r && y > hh - r) return std::hypot(x - (hw - r), y - (hh - r)) - r;
  return std::max(x - hw, y - hh);
}

TEST(Outline, BoundaryRadiusLiesOnEachShape) {
  const Outline rr = Outline::rectangle(0.12, 0.05, 0.01);
  const Outline sharp = Outline::rectangle(0.12, 0.05);
  const Outline el = Outline::ellipse(0.12, 0.05);
  const Outline ci = Outline::circle(0.07);
  for (int k = 0; k < 720; ++k) {
    const double t = -kPi + 2 * kPi * k / 720 + 1e-3;
    const Vec2 d(std::cos(t), std::sin(t));
    EXPECT_NEAR(roundedRectResidual(rr.boundaryRadius(t) * d, 0.12, 0.05, 0.01), 0.0, kOnOutline * 0.12) << t;
    EXPECT_NEAR(roundedRectResidual(sharp.boundaryRadius(t) * d, 0.12, 0.05, 0.0), 0.0, kOnOutline * 0.12) << t;
    const Vec2 e = el.boundaryRadius(t) * d;
    EXPECT_NEAR(std::pow(e.x / 0.06, 2) + std::pow(e.y / 0.025, 2), 1.0, kOnOutline) << t;
    EXPECT_DOUBLE_EQ(ci.boundaryRadius(t), 0.035);
  }
  // The rounded corner's midpoint along the diagonal of the corner circle centre.
  const double cx = 0.05, cy = 0.015;
  const double t = std::atan2(cy, cx);
  EXPECT_NEAR(rr.boundaryRadius(t), std::hypot(cx, cy) + 0.01, kOnOutline);
}

TEST(Outline, FromSquareBoundaryLandsOnTheOutline) {
  const Vec2 c(0.01, -0.02);
  const Outline rr = Outline::rectangle(0.12, 0.05, 0.01, c);
  const Outline el = Outline::ellipse(0.12, 0.05, c);
  const Outline ci = Outline::circle(0.07, c);
  const Outline sharp = Outline::rectangle(0.12, 0.05, 0, c);
  for (int k = 0; k <= 200; ++k) {
    const double t = -1 + 2.0 * k / 200;
    for (Vec2 s : {Vec2(t, -1), Vec2(1, t), Vec2(-t, 1), Vec2(-1, t)}) {
      EXPECT_NEAR(roundedRectResidual(rr.fromSquare(s) - c, 0.12, 0.05, 0.01), 0.0, kOnOutline * 0.12);
      const Vec2 e = el.fromSquare(s) - c;
      EXPECT_NEAR(std::pow(e.x / 0.06, 2) + std::pow(e.y / 0.025, 2), 1.0, kOnOutline);
      EXPECT_NEAR(glm::length(ci.fromSquare(s) - c), 0.035, kOnOutline * 0.07);
      EXPECT_NEAR(roundedRectResidual(sharp.fromSquare(s) - c, 0.12, 0.05, 0.0), 0.0, kOnOutline * 0.12);
    }
  }
  // Sharp corners are images of the square's corners; the centre maps to the centre; interior stays inside.
  EXPECT_NEAR(sharp.fromSquare(Vec2(1, 1)).x, c.x + 0.06, kOnOutline);
  EXPECT_NEAR(sharp.fromSquare(Vec2(1, 1)).y, c.y + 0.025, kOnOutline);
  EXPECT_EQ(rr.fromSquare(Vec2(0)), c);
  for (double a : {-0.99, -0.5, 0.0, 0.3, 0.98})
    for (double b : {-0.97, -0.1, 0.2, 0.99}) {
      EXPECT_TRUE(rr.contains(rr.fromSquare(Vec2(a, b))));
      EXPECT_TRUE(el.contains(el.fromSquare(Vec2(a, b))));
    }
}

TEST(Outline, PolygonIsStarShapedAndExact) {
  // A pentagon-like trim loop given clockwise (it is reoriented) about a centre off the origin.
  const std::vector<Vec2> loop = {{0.2, 0.9}, {0.9, 0.6}, {0.8, 0.1}, {0.3, 0.05}, {0.1, 0.4}};
  const Vec2 c(0.45, 0.45);
  const Outline p = Outline::polygon(loop, c);
  EXPECT_EQ(p.loop().size(), 5u);
  EXPECT_EQ(p.boundsMin(), Vec2(0.1, 0.05));
  EXPECT_EQ(p.boundsMax(), Vec2(0.9, 0.9));
  auto onLoop = [&](Vec2 q) {
    double best = kInf;
    for (size_t i = 0; i < loop.size(); ++i) {
      const Vec2 a = loop[i], b = loop[(i + 1) % loop.size()];
      const double t = std::clamp(glm::dot(q - a, b - a) / glm::dot(b - a, b - a), 0.0, 1.0);
      best = std::min(best, glm::length(q - (a + t * (b - a))));
    }
    return best;
  };
  for (int k = 0; k < 360; ++k) {
    const double t = 2 * kPi * k / 360 - 3;
    EXPECT_LE(onLoop(c + p.boundaryRadius(t) * Vec2(std::cos(t), std::sin(t))), kOnOutline);
  }
  for (int k = 0; k <= 50; ++k) {
    const double t = -1 + 2.0 * k / 50;
    for (Vec2 s : {Vec2(t, -1), Vec2(1, t), Vec2(-t, 1), Vec2(-1, t)}) EXPECT_LE(onLoop(p.fromSquare(s)), kOnOutline);
  }
  EXPECT_TRUE(p.contains(c));
  EXPECT_FALSE(p.contains(Vec2(0.95, 0.95)));
  EXPECT_TRUE(p.contains(Vec2(0.2, 0.9 + 1e-4), 2e-4));
  // Not star-shaped about a centre outside the loop.
  EXPECT_THROW(Outline::polygon(loop, Vec2(2, 2)), Error);
  EXPECT_THROW(Outline::polygon({{0, 0}, {1, 0}}, Vec2(0.5, 0.1)), Error);
}

TEST(Outline, ContainsWithTolerance) {
  const Outline rr = Outline::rectangle(2, 1, 0.2);
  EXPECT_TRUE(rr.contains(Vec2(0.9, 0.4)));
  EXPECT_TRUE(rr.contains(Vec2(0.999, 0.0)));
  // Just outside the rounded corner along its diagonal: distance 0.01 outside.
  const Vec2 corner_centre(0.8, 0.3), dir = glm::normalize(Vec2(1, 1));
  const Vec2 q = corner_centre + (0.2 + 0.01) * dir;
  EXPECT_FALSE(rr.contains(q));
  EXPECT_FALSE(rr.contains(q, 0.009));
  EXPECT_TRUE(rr.contains(q, 0.011));
  // The sharp box corner is outside a rounded rectangle.
  EXPECT_FALSE(rr.contains(Vec2(0.999, 0.499)));
  const Outline el = Outline::ellipse(4, 2);
  // (2.1, 0) is 0.1 from the ellipse's vertex (2, 0).
  EXPECT_FALSE(el.contains(Vec2(2.1, 0), 0.099));
  EXPECT_TRUE(el.contains(Vec2(2.1, 0), 0.101));
  EXPECT_FALSE(el.contains(Vec2(0, 1.05), 0.049));
  EXPECT_TRUE(el.contains(Vec2(0, 1.05), 0.051));
  const Outline ci = Outline::circle(2);
  EXPECT_TRUE(ci.contains(Vec2(0.6, 0.8)));
  EXPECT_FALSE(ci.contains(Vec2(0.61, 0.8)));
}

TEST(Outline, InvalidShapesAndDescribe) {
  EXPECT_THROW(Outline::rectangle(0, 1), Error);
  EXPECT_THROW(Outline::rectangle(1, 1, 0.6), Error);
  EXPECT_THROW(Outline::ellipse(1, -1), Error);
  EXPECT_THROW(Outline::circle(std::nan("")), Error);
  EXPECT_EQ(Outline::rectangle(0.1, 0.05, 0.005).describe(), "rectangle 0.1 x 0.05, corner radius 0.005");
  EXPECT_EQ(Outline::circle(0.07).describe(), "circle diameter 0.07");
  EXPECT_EQ(Outline::ellipse(0.1, 0.05, Vec2(0.01, 0)).describe(), "ellipse 0.1 x 0.05 about (0.01, 0)");
}

}  // namespace
}  // namespace pvrr::cad
