// NURBS evaluation against an independent Cox-de Boor evaluator and finite differences, the exact rational
// sphere/cylinder/torus patches against their closed forms, and the validation messages.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include "pvrr/base/error.h"
#include "cad/nurbs.h"

namespace pvrr::cad {
namespace {

// Positions of the exact patches: a few ulps of the radius from roundoff in the rational sums (the issue's
// target is 1e-12 relative).
constexpr double kPositionRel = 1e-12;
// Normals against the radial direction (the target).
constexpr double kNormalAngleRad = 1e-9;
// Principal curvatures, relative (the target).
constexpr double kCurvatureRel = 1e-9;
// Principal directions: |cos| of the angle to the expected direction must be within this of 1.
constexpr double kDirectionCos = 1e-9;

// Plain Cox-de Boor recursion, written independently of the library (no spans, no derivative tables).
double coxDeBoor(const std::vector<double>& U, int i, int p, double t, double t_end) {
  if (p == 0) {
    if (t == t_end) return (U[size_t(i)] < t_end && U[size_t(i + 1)] == t_end) ? 1.0 : 0.0;
    return (U[size_t(i)] <= t && t < U[size_t(i + 1)]) ? 1.0 : 0.0;
  }
  double r = 0;
  const double d1 = U[size_t(i + p)] - U[size_t(i)], d2 = U[size_t(i + p + 1)] - U[size_t(i + 1)];
  if (d1 > 0) r += (t - U[size_t(i)]) / d1 * coxDeBoor(U, i, p - 1, t, t_end);
  if (d2 > 0) r += (U[size_t(i + p + 1)] - t) / d2 * coxDeBoor(U, i + 1, p - 1, t, t_end);
  return r;
}

Vec3 referencePoint(const NurbsDefinition& d, double u, double v) {
  const double ue = d.knots_u[size_t(d.count_u)], ve = d.knots_v[size_t(d.count_v)];
  Vec3 num(0);
  double den = 0;
  for (int i = 0; i < d.count_u; ++i)
    for (int j = 0; j < d.count_v; ++j) {
      const size_t k = size_t(i * d.count_v + j);
      const double w = (d.weights.empty() ? 1.0 : d.weights[k]) * coxDeBoor(d.knots_u, i, d.degree_u, u, ue) *
                       coxDeBoor(d.knots_v, j, d.degree_v, v, ve);
      num += w * d.points[k];
      den += w;
    }
  return num / den;
}

// A general surface: degree 3 x 2, non-uniform knots with a double interior knot in u, varied weights.
NurbsDefinition generalDefinition() {
  NurbsDefinition d;
  d.degree_u = 3;
  d.degree_v = 2;
  d.count_u = 6;
  d.count_v = 5;
  d.knots_u = {0, 0, 0, 0, 0.3, 0.3, 1.1, 1.1, 1.1, 1.1};
  d.knots_v = {-1, -1, -1, -0.2, 0.1, 2, 2, 2};
  for (int i = 0; i < d.count_u; ++i)
    for (int j = 0; j < d.count_v; ++j) {
      d.points.emplace_back(0.2 * i + 0.03 * j * j, 0.25 * j - 0.02 * i, 0.1 * std::sin(1.3 * i + 0.7 * j));
      d.weights.push_back(0.6 + 0.35 * std::cos(0.9 * i - 1.7 * j) * std::cos(0.9 * i - 1.7 * j) + 0.1 * j);
    }
  return d;
}

TEST(Nurbs, PositionsMatchIndependentCoxDeBoor) {
  // Both evaluators are exact rational sums; they differ by roundoff on coordinates of size ~1.
  constexpr double kAbs = 1e-14;
  const NurbsDefinition def = generalDefinition();
  const NurbsSurface s(def);
  const ParamDomain dom = s.domain();
  EXPECT_EQ(dom.u0, 0);
  EXPECT_EQ(dom.u1, 1.1);
  EXPECT_EQ(dom.v0, -1);
  EXPECT_EQ(dom.v1, 2);
  for (double a : {0.0, 0.13, 0.3 / 1.1, 0.5, 0.77, 1.0})
    for (double b : {0.0, 0.2, 0.8 / 3, 0.5, 1.0}) {
      const double u = dom.u0 + a * (dom.u1 - dom.u0), v = dom.v0 + b * (dom.v1 - dom.v0);
      const Vec3 p = s.evaluate(u, v).p, q = referencePoint(def, u, v);
      EXPECT_NEAR(p.x, q.x, kAbs) << u << " " << v;
      EXPECT_NEAR(p.y, q.y, kAbs) << u << " " << v;
      EXPECT_NEAR(p.z, q.z, kAbs) << u << " " << v;
    }
}

TEST(Nurbs, DerivativesMatchFiniteDifferences) {
  // Central differences of the independent evaluator with step h have error ~h^2 |p'''| + eps/h; with
  // h = 1e-5 that is ~1e-9 for first and (for differences of the library's first derivatives) second order.
  constexpr double kH = 1e-5;
  constexpr double kTol = 2e-8;
  const NurbsDefinition def = generalDefinition();
  const NurbsSurface s(def);
  for (double u : {0.1, 0.45, 0.9})
    for (double v : {-0.7, 0.0, 1.5}) {
      const SurfaceDerivs d = s.evaluate(u, v);
      const Vec3 du = (referencePoint(def, u + kH, v) - referencePoint(def, u - kH, v)) / (2 * kH);
      const Vec3 dv = (referencePoint(def, u, v + kH) - referencePoint(def, u, v - kH)) / (2 * kH);
      const Vec3 duu = (s.evaluate(u + kH, v).du - s.evaluate(u - kH, v).du) / (2 * kH);
      const Vec3 duv = (s.evaluate(u, v + kH).du - s.evaluate(u, v - kH).du) / (2 * kH);
      const Vec3 dvv = (s.evaluate(u, v + kH).dv - s.evaluate(u, v - kH).dv) / (2 * kH);
      for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(d.du[c], du[c], kTol);
        EXPECT_NEAR(d.dv[c], dv[c], kTol);
        EXPECT_NEAR(d.duu[c], duu[c], kTol * 10);
        EXPECT_NEAR(d.duv[c], duv[c], kTol * 10);
        EXPECT_NEAR(d.dvv[c], dvv[c], kTol * 10);
      }
    }
}

void expectAlong(const Vec3& dir, const Vec3& expected, const char* what) {
  EXPECT_NEAR(std::abs(glm::dot(glm::normalize(dir), glm::normalize(expected))), 1.0, kDirectionCos) << what;
}

class SphereCap : public ::testing::TestWithParam<double> {};

TEST_P(SphereCap, OnSphereRadialNormalsUnitCurvature) {
  const double R = GetParam();
  const Vec3 centre(0.3, -0.2, 0.5);
  const double theta_max = radians(40);
  const NurbsSurface s = makeSphereCap(centre, R, theta_max);
  const ParamDomain dom = s.domain();
  // Parameters near the pole (u = 0) down to 1e-12 of the domain, the pole itself, and the rest.
  const std::vector<double> us = {0.0, 1e-12, 1e-9, 1e-6, 1e-3, 0.1, 0.37, 0.5, 0.81, 1.0};
  const std::vector<double> vs = {0.0, 0.07, 0.25, 0.33, 0.5, 0.61, 0.9, 1.0};
  for (double a : us)
    for (double b : vs) {
      const double u = dom.u0 + a * (dom.u1 - dom.u0), v = dom.v0 + b * (dom.v1 - dom.v0);
      const Vec3 p = s.evaluate(u, v).p;
      EXPECT_NEAR(glm::length(p - centre), R, kPositionRel * R) << "u=" << u << " v=" << v;
      // At the pole the radial direction is +z exactly.
      const Vec3 radial = a == 0 ? Vec3(0, 0, 1) : glm::normalize(p - centre);
      EXPECT_LE(angleBetween(s.normal(u, v), radial), kNormalAngleRad) << "u=" << u << " v=" << v;
      const Curvature k = s.curvature(u, v);
      EXPECT_NEAR(k.k1 * R, 1.0, kCurvatureRel) << "u=" << u << " v=" << v;
      EXPECT_NEAR(k.k2 * R, 1.0, kCurvatureRel) << "u=" << u << " v=" << v;
    }
  // The u = 1 edge is the parallel at theta_max.
  const Vec3 edge = s.evaluate(dom.u1, 0.3).p - centre;
  EXPECT_NEAR(std::acos(edge.z / R), theta_max, 1e-12);
  EXPECT_EQ(s.evaluate(0, 0.3).p, centre + Vec3(0, 0, R));
}

INSTANTIATE_TEST_SUITE_P(Radii, SphereCap, ::testing::Values(1.2, 1e3));

TEST(Nurbs, CylinderPatchRadiusNormalsAndCurvature) {
  const double r = 0.7, angle = radians(80), h = 0.3;
  const NurbsSurface s = makeCylinderPatch(r, angle, h);
  for (double u : {0.0, 0.21, 0.5, 0.93, 1.0})
    for (double v : {0.0, 0.4, 1.0}) {
      const Vec3 p = s.evaluate(u, v).p;
      const Vec3 radial = glm::normalize(Vec3(p.x, p.y, 0));
      EXPECT_NEAR(std::hypot(p.x, p.y), r, kPositionRel * r);
      EXPECT_NEAR(p.z, v * h, kPositionRel * h);
      const double phi = std::atan2(p.y, p.x);
      EXPECT_GE(phi, -1e-15);
      EXPECT_LE(phi, angle + 1e-15);
      EXPECT_LE(angleBetween(s.normal(u, v), radial), kNormalAngleRad);
      const Curvature k = s.curvature(u, v);
      EXPECT_NEAR(k.k1 * r, 1.0, kCurvatureRel);
      EXPECT_NEAR(k.k2 * r, 0.0, kCurvatureRel);
      expectAlong(k.dir1, Vec3(-p.y, p.x, 0), "cylinder dir1 (around)");
      expectAlong(k.dir2, Vec3(0, 0, 1), "cylinder dir2 (axis)");
    }
  EXPECT_NEAR(std::atan2(s.evaluate(1, 0).p.y, s.evaluate(1, 0).p.x), angle, 1e-14);
}

TEST(Nurbs, TorusPatchOnTorusWithPrincipalCurvatures) {
  const double R = 2.0, r = 0.5;
  const NurbsSurface s = makeTorusPatch(R, r);
  for (double u : {0.0, 0.3, 0.5, 0.8, 1.0})
    for (double v : {0.0, 0.1, 0.5, 0.77, 1.0}) {
      const Vec3 p = s.evaluate(u, v).p;
      const double rho = std::hypot(p.x, p.y);
      const Vec3 e_rho = Vec3(p.x, p.y, 0) / rho, e_phi(-e_rho.y, e_rho.x, 0);
      const Vec3 tube_centre = R * e_rho;
      EXPECT_NEAR(glm::length(p - tube_centre), r, kPositionRel * R);
      EXPECT_LE(angleBetween(s.normal(u, v), p - tube_centre), kNormalAngleRad);
      const double psi = std::atan2(p.z, rho - R);  // poloidal angle, the phi
      const Curvature k = s.curvature(u, v);
      EXPECT_NEAR(k.k1 * r, 1.0, kCurvatureRel);
      const double k_tor = std::cos(psi) / (R + r * std::cos(psi));
      EXPECT_NEAR(k.k2, k_tor, kCurvatureRel / r);
      expectAlong(k.dir1, -std::sin(psi) * e_rho + Vec3(0, 0, std::cos(psi)), "torus dir1 (poloidal)");
      expectAlong(k.dir2, e_phi, "torus dir2 (toroidal)");
    }
}

void expectError(NurbsDefinition d, const std::string& needle) {
  try {
    NurbsSurface s(std::move(d), "part.step face 3");
    FAIL() << "no error; expected one mentioning \"" << needle << "\"";
  } catch (const Error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("part.step face 3"), std::string::npos) << msg;
    EXPECT_NE(msg.find(needle), std::string::npos) << msg;
  }
}

TEST(Nurbs, InvalidDefinitionsNameTheProblem) {
  const NurbsDefinition good = generalDefinition();
  EXPECT_NO_THROW(NurbsSurface{good});
  {
    NurbsDefinition d = good;
    d.degree_v = 0;
    expectError(d, "degree must be >= 1");
  }
  {
    NurbsDefinition d = good;
    d.degree_u = 16;
    expectError(d, "supported maximum 15");
  }
  {
    NurbsDefinition d = good;
    d.count_u = 3;  // degree 3 needs 4
    d.points.resize(15);
    d.weights.resize(15);
    d.knots_u = {0, 0, 0, 0, 1, 1, 1};
    expectError(d, "too few");
  }
  {
    NurbsDefinition d = good;
    d.knots_u.pop_back();
    expectError(d, "knots_u has 9 values; expected count + degree + 1 = 10");
  }
  {
    NurbsDefinition d = good;
    d.knots_v[4] = -0.5;  // after -0.2
    expectError(d, "knots_v decrease at index 4");
  }
  {
    NurbsDefinition d = good;
    d.knots_v = {-1, -1, -1, 0.1, 0.1, 0.1, 0.1, 2};  // interior multiplicity 4 > degree + 1 = 3
    expectError(d, "multiplicity 4");
  }
  {
    NurbsDefinition d = good;
    d.weights[7] = 0;
    expectError(d, "weight [1][2] = 0");
  }
  {
    NurbsDefinition d = good;
    d.weights[3] = -1;
    expectError(d, "weights must be finite and > 0");
  }
  {
    NurbsDefinition d = good;
    d.points[12].y = std::nan("");
    expectError(d, "control point [2][2] is not finite");
  }
  {
    NurbsDefinition d = good;
    d.knots_u[5] = kInf;
    expectError(d, "knots_u[5] is not finite");
  }
  {
    NurbsDefinition d = good;
    d.weights[4] = std::nan("");
    expectError(d, "weights must be finite");
  }
  {
    NurbsDefinition d = good;
    d.weights.pop_back();
    expectError(d, "29 weights given for 30 control points");
  }
  {
    NurbsDefinition d = good;
    d.points.pop_back();
    expectError(d, "29 control points given; expected count_u * count_v = 30");
  }
}

TEST(Nurbs, ZeroLengthDomainIsRejected) {
  // Degree 1 with 2 control points: knots {a, b, c, d}; domain [k1, k2]. Equal k1 = k2 (multiplicity 2 =
  // degree + 1, allowed) leaves an empty domain.
  NurbsDefinition d;
  d.degree_u = d.degree_v = 1;
  d.count_u = d.count_v = 2;
  d.knots_u = {0, 1, 1, 2};
  d.knots_v = {0, 0, 1, 1};
  d.points = {Vec3(0, 0, 0), Vec3(0, 1, 0), Vec3(1, 0, 0), Vec3(1, 1, 0)};
  expectError(d, "zero-length domain");
}

TEST(Nurbs, SampleIsBitIdenticalToSeparateCalls) {
  const NurbsSurface cap = makeSphereCap(Vec3(1, 2, 3), 1.2, radians(40));
  const NurbsSurface general(generalDefinition());
  for (const NurbsSurface* s : {&cap, &general}) {
    const ParamDomain dom = s->domain();
    for (double a : {0.0, 1e-7, 0.3, 1.0})
      for (double b : {0.0, 0.45, 1.0}) {
        const double u = dom.u0 + a * (dom.u1 - dom.u0), v = dom.v0 + b * (dom.v1 - dom.v0);
        const SurfacePoint p = s->sample(u, v, true);
        const Curvature k = s->curvature(u, v);
        EXPECT_EQ(p.p, s->evaluate(u, v).p);
        EXPECT_EQ(p.n, s->normal(u, v));
        EXPECT_EQ(p.k.k1, k.k1);
        EXPECT_EQ(p.k.k2, k.k2);
        EXPECT_EQ(p.k.dir1, k.dir1);
      }
  }
}

TEST(Nurbs, DescribeNamesDegreesAndPoles) {
  EXPECT_EQ(NurbsSurface(generalDefinition()).describe(), "NURBS 3x2, 6x5 poles, rational");
  EXPECT_EQ(makeCylinderPatch(1, 1, 1).describe(), "NURBS 2x1, 3x2 poles, rational");
}

TEST(Nurbs, ExactPatchArgumentsAreValidated) {
  EXPECT_THROW(makeSphereCap(Vec3(0), -1, 0.5), Error);
  EXPECT_THROW(makeSphereCap(Vec3(0), 1, 0), Error);
  EXPECT_THROW(makeSphereCap(Vec3(0), 1, 4), Error);
  EXPECT_THROW(makeCylinderPatch(1, 0, 1), Error);
  EXPECT_THROW(makeCylinderPatch(1, 1, 0), Error);
  EXPECT_THROW(makeTorusPatch(0, 1), Error);
}

}  // namespace
}  // namespace pvrr::cad
