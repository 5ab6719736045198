// Sag surfaces against sag formulas written out independently here (naive forms, long double where they
// cancel), finite differences of those formulas, the exact torus geometry and principal curvatures.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include "pvrr/base/error.h"
#include "cad/sag.h"

namespace pvrr::cad {
namespace {

// Sags of size <= 1e-2 m computed two ways agree to ~1e-17 m; 1e-15 m allows for long-double cancellation
// in the naive references.
constexpr double kSagAbs = 1e-15;
// Five-point central differences of the reference sag with step kH: truncation ~kH^4 |Z^(5)| / 30 and
// roundoff ~eps |Z| / kH, both below 1e-10 for the radii here (down to 0.04 m).
constexpr double kH = 1e-4;
constexpr double kSlopeAbs = 1e-9;
// Second derivatives by the same differences of the library's slopes, relative to the Hessian's size.
constexpr double kHessianRel = 1e-8;

double diff5(const std::function<double(double)>& f, double x) {
  return (-f(x + 2 * kH) + 8 * f(x + kH) - 8 * f(x - kH) + f(x - 2 * kH)) / (12 * kH);
}
// Curvatures and directions of size ~1/R from a few dozen flops.
constexpr double kCurvRel = 1e-12;

// Naive sphere sag, R - sign(R) sqrt(R^2 - r^2), in long double to tame the cancellation.
double sphereSagRef(double R, double x, double y) {
  const long double r2 = (long double)x * x + (long double)y * y;
  const long double Rl = R;
  return double(Rl - (R > 0 ? 1 : -1) * std::sqrt(Rl * Rl - r2));
}

double asphereSagRef(double R, double k, const std::vector<double>& a, double x, double y) {
  const long double r2 = (long double)x * x + (long double)y * y, c = 1.0L / R;
  long double z = c * r2 / (1 + std::sqrt(1 - (1 + k) * c * c * r2));
  long double rp = r2 * r2;
  for (double ai : a) {
    z += ai * rp;
    rp *= r2;
  }
  return double(z);
}

const Outline kDisc = Outline::circle(0.06);

void expectDerivsMatch(const SagSurface& s, const std::function<double(double, double)>& ref, double x, double y,
                       double sag_abs = kSagAbs) {
  const SagDerivs d = s.sag(x, y);
  EXPECT_NEAR(d.z, ref(x, y), sag_abs) << s.describe() << " at " << x << ", " << y;
  EXPECT_NEAR(d.zx, diff5([&](double t) { return ref(t, y); }, x), kSlopeAbs);
  EXPECT_NEAR(d.zy, diff5([&](double t) { return ref(x, t); }, y), kSlopeAbs);
  const double scale = std::abs(d.zxx) + std::abs(d.zyy) + std::abs(d.zxy);
  EXPECT_NEAR(d.zxx, diff5([&](double t) { return s.sag(t, y).zx; }, x), kHessianRel * scale);
  EXPECT_NEAR(d.zxy, diff5([&](double t) { return s.sag(x, t).zx; }, y), kHessianRel * scale);
  EXPECT_NEAR(d.zxy, diff5([&](double t) { return s.sag(t, y).zy; }, x), kHessianRel * scale);
  EXPECT_NEAR(d.zyy, diff5([&](double t) { return s.sag(x, t).zy; }, y), kHessianRel * scale);
}

TEST(Sag, SphereMatchesNaiveSagAndIsASphere) {
  for (double R : {1.2, -0.5, 0.06}) {
    const double zv = 0.003;
    const SagSurfacePtr s = makeSphere(R, kDisc, zv);
    const Vec3 centre(0, 0, zv - R);  // header: the centre of curvature is at z_vertex - R
    for (double x : {0.0, 0.011, -0.02, 0.029})
      for (double y : {0.0, -0.013, 0.02}) {
        // Steep parts (r > 0.6 |R|) are left out: the differences' truncation error grows there.
        if (std::hypot(x, y) > 0.6 * std::abs(R)) continue;
        expectDerivsMatch(*s, [&](double a, double b) { return sphereSagRef(R, a, b); }, x, y);
        const Vec3 p = s->evaluate(x, y).p;
        EXPECT_NEAR(glm::length(p - centre), std::abs(R), 1e-15 + 1e-15 * std::abs(R));
        // The normal is (p - centre)/R: outward for R > 0, towards the centre (still +z-ish) for R < 0.
        EXPECT_LE(angleBetween(s->normal(x, y), (p - centre) / R), 1e-14);
        const Curvature k = s->curvature(x, y);
        EXPECT_NEAR(k.k1 * R, 1.0, kCurvRel);
        EXPECT_NEAR(k.k2 * R, 1.0, kCurvRel);
      }
  }
}

TEST(Sag, AsphereMatchesItsFormula) {
  const double R = 0.35, k = -1.7;
  const std::vector<double> a = {2.5, -40.0, 900.0};  // A4 [m^-3], A6 [m^-5], A8 [m^-7]
  const SagSurfacePtr s = makeAsphere(R, k, a, kDisc, 0.0);
  for (double x : {0.0, 0.007, -0.018, 0.027})
    for (double y : {0.0, 0.012, -0.021})
      expectDerivsMatch(*s, [&](double u, double v) { return asphereSagRef(R, k, a, u, v); }, x, y);
  EXPECT_EQ(s->describe(), "asphere R=0.35 m k=-1.7 A4=2.5 A6=-40 A8=900");
  // At the vertex the curvature is that of the base sphere.
  const Curvature kv = s->curvature(0, 0);
  EXPECT_NEAR(kv.k1 * R, 1.0, kCurvRel);
  EXPECT_NEAR(kv.k2 * R, 1.0, kCurvRel);
}

TEST(Sag, EvaluateAndNormalAreConsistent) {
  const SagSurfacePtr s = makeAsphere(-0.8, 0.3, {1.0}, kDisc, -0.01);
  for (double x : {0.0, 0.02})
    for (double y : {-0.01, 0.025}) {
      const SurfaceDerivs d = s->evaluate(x, y);
      const SagDerivs z = s->sag(x, y);
      EXPECT_EQ(d.p, Vec3(x, y, -0.01 - z.z));
      EXPECT_EQ(d.du, Vec3(1, 0, -z.zx));
      EXPECT_EQ(d.dv, Vec3(0, 1, -z.zy));
      EXPECT_EQ(d.duu, Vec3(0, 0, -z.zxx));
      EXPECT_EQ(d.duv, Vec3(0, 0, -z.zxy));
      EXPECT_EQ(d.dvv, Vec3(0, 0, -z.zyy));
      EXPECT_LE(angleBetween(s->normal(x, y), glm::cross(d.du, d.dv)), 1e-15);
    }
  const ParamDomain dom = s->domain();
  EXPECT_EQ(dom.u0, -0.03);
  EXPECT_EQ(dom.u1, 0.03);
}

TEST(Sag, SampleIsBitIdenticalToSeparateCalls) {
  const SagSurfacePtr s = makeToric(0.4, -0.3, 0.2, kDisc, 0.01);
  for (double x : {0.0, -0.02})
    for (double y : {0.0, 0.015}) {
      const SurfacePoint p = s->sample(x, y, true);
      const Curvature k = s->curvature(x, y);
      EXPECT_EQ(p.p, s->evaluate(x, y).p);
      EXPECT_EQ(p.n, s->normal(x, y));
      EXPECT_EQ(p.k.k1, k.k1);
      EXPECT_EQ(p.k.k2, k.k2);
      EXPECT_EQ(p.k.dir2, k.dir2);
    }
}

TEST(Sag, ToricIsAnExactTorusWithPrincipalRadiiAtTheAxis) {
  struct Case { double ra, rb, axis_deg; };
  for (const Case c : {Case{0.5, 0.2, 30.0}, Case{0.2, 0.5, -70.0}, Case{-0.6, 0.25, 110.0}, Case{0.3, -0.9, 5.0}}) {
    const double axis = radians(c.axis_deg);
    const SagSurfacePtr s = makeToric(c.ra, c.rb, axis, kDisc, 0.0);
    const Vec3 ea(std::cos(axis), std::sin(axis), 0), eb(-std::sin(axis), std::cos(axis), 0);
    const Curvature k = s->curvature(0, 0);
    const double ka = 1 / c.ra, kb = 1 / c.rb;
    EXPECT_NEAR(k.k1, std::max(ka, kb), kCurvRel * std::max(std::abs(ka), std::abs(kb)));
    EXPECT_NEAR(k.k2, std::min(ka, kb), kCurvRel * std::max(std::abs(ka), std::abs(kb)));
    EXPECT_NEAR(std::abs(glm::dot(ka > kb ? k.dir1 : k.dir2, ea)), 1.0, kCurvRel);
    EXPECT_NEAR(std::abs(glm::dot(ka > kb ? k.dir2 : k.dir1, eb)), 1.0, kCurvRel);
    // Exact torus: the b-circle Zb(y') = Rb - sign(Rb) sqrt(Rb^2 - y'^2) revolved about the line parallel to
    // y' at sag Ra: every point's distance from that line is |Ra - Zb(y')|.
    for (double x : {0.0, 0.013, -0.027})
      for (double y : {0.0, 0.019, -0.024}) {
        const double xr = x * ea.x + y * ea.y, yr = x * eb.x + y * eb.y;
        const double zb = sphereSagRef(c.rb, 0.0, yr);
        const double z = s->sag(x, y).z;
        EXPECT_NEAR(std::hypot(xr, c.ra - z), std::abs(c.ra - zb), 1e-14) << c.ra << " " << c.rb;
        // Sections: along the axis through the vertex a circle of radius Ra; across it one of radius Rb.
        if (yr == 0) {
          EXPECT_NEAR(z, sphereSagRef(c.ra, xr, 0.0), kSagAbs);
        }
        const auto ref = [&](double u, double v) {
          const double ur = u * ea.x + v * ea.y, vr = u * eb.x + v * eb.y;
          const double zb2 = sphereSagRef(c.rb, 0.0, vr);
          const double d = c.ra - zb2;
          return c.ra - (c.ra > 0 ? 1 : -1) * std::sqrt(d * d - ur * ur);
        };
        expectDerivsMatch(*s, ref, x, y, 1e-14);
      }
  }
}

TEST(Sag, CylinderIsFlatAlongItsAxis) {
  const double R = 0.25, axis = radians(40);
  const SagSurfacePtr s = makeCylinder(R, axis, kDisc);
  const Vec2 ea(std::cos(axis), std::sin(axis)), eb(-std::sin(axis), std::cos(axis));
  for (double t : {-0.02, 0.0, 0.015})
    for (double a : {-0.02, 0.0, 0.01}) {
      const Vec2 p = t * eb + a * ea;
      EXPECT_NEAR(s->sag(p.x, p.y).z, sphereSagRef(R, t, 0), kSagAbs);
      const Curvature k = s->curvature(p.x, p.y);
      EXPECT_NEAR(k.k1 * R, 1.0, kCurvRel);
      EXPECT_NEAR(k.k2, 0.0, kCurvRel / R);
      EXPECT_NEAR(std::abs(glm::dot(k.dir2, Vec3(ea, 0))), 1.0, kCurvRel);
    }
  EXPECT_EQ(s->describe(), "cylinder R=0.25 m, axis 40 deg");
}

TEST(Sag, PlaneAndInfiniteRadius) {
  const SagSurfacePtr p = makePlane(kDisc, 0.5);
  EXPECT_EQ(p->evaluate(0.01, -0.02).p, Vec3(0.01, -0.02, 0.5));
  EXPECT_EQ(p->normal(0.01, 0.02), Vec3(0, 0, 1));
  const SagSurfacePtr s = makeSphere(kInf, kDisc);
  EXPECT_EQ(s->sag(0.02, 0.01).z, 0.0);
  EXPECT_EQ(makeSphere(0, kDisc)->sag(0.02, 0.01).z, 0.0);
  EXPECT_THROW(makeSphere(std::nan(""), kDisc), Error);
  EXPECT_THROW(makeSphere(1, kDisc, kInf), Error);
}

TEST(Sag, UndefinedSagThrowsNamingSurfaceAndPoint) {
  const SagSurfacePtr s = makeSphere(-0.02, kDisc);
  EXPECT_TRUE(s->defined(0.019, 0.0));
  EXPECT_FALSE(s->defined(0.021, 0.0));
  EXPECT_FALSE(s->defined(0.02, 0.0));
  try {
    s->sag(0.015, 0.015);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("sphere R=-0.02 m"), std::string::npos) << msg;
    EXPECT_NE(msg.find("(0.015, 0.015)"), std::string::npos) << msg;
  }
  const SagSurfacePtr t = makeToric(0.5, 0.01, 0.0, kDisc);
  EXPECT_FALSE(t->defined(0.0, 0.011));
  EXPECT_THROW(t->sag(0.0, 0.011), Error);
  EXPECT_FALSE(makeAsphere(0.1, 3.0, {}, kDisc)->defined(0.06, 0));  // (1 + k) c^2 r^2 = 1.44
}

TEST(Sag, WithVertexShiftsOnlyZ) {
  const SagSurfacePtr s = makeToric(0.5, 0.2, 0.3, kDisc, 0.0);
  const SagSurfacePtr t = s->withVertex(-0.004);
  EXPECT_EQ(t->zVertex(), -0.004);
  EXPECT_EQ(t->describe(), s->describe());
  const Vec3 a = s->evaluate(0.01, 0.02).p, b = t->evaluate(0.01, 0.02).p;
  EXPECT_EQ(a.x, b.x);
  EXPECT_EQ(b.z, -0.004 - s->sag(0.01, 0.02).z);
  EXPECT_EQ(makeSphere(1.2, kDisc)->withVertex(1)->describe(), "sphere R=1.2 m");
}

// sphereCurvature: spheres and planes only (pvrr refinement meets them in closed form), kept by withVertex; the
// closed form c (x^2 + y^2 + Z^2) = 2 Z holds at the sag's points.
TEST(Sag, SphereCurvatureOnlyForSpheresAndPlanes) {
  double c = -1;
  ASSERT_TRUE(makeSphere(-0.5, kDisc)->withVertex(-0.002)->sphereCurvature(&c));
  EXPECT_EQ(c, -2.0);
  ASSERT_TRUE(makePlane(kDisc)->sphereCurvature(&c));
  EXPECT_EQ(c, 0.0);
  EXPECT_TRUE(makeAsphere(0.5, 0.0, {}, kDisc)->sphereCurvature(&c));  // conic 0, no terms: a sphere
  EXPECT_FALSE(makeAsphere(0.5, -0.5, {}, kDisc)->sphereCurvature(&c));
  EXPECT_FALSE(makeAsphere(0.5, 0.0, {1e-3}, kDisc)->sphereCurvature(&c));
  EXPECT_FALSE(makeToric(0.5, 0.7, 0.0, kDisc)->sphereCurvature(&c));
  const SagSurfacePtr s = makeSphere(0.3, kDisc);
  ASSERT_TRUE(s->sphereCurvature(&c));
  const double x = 0.02, y = -0.01, Z = s->sag(x, y).z;
  EXPECT_NEAR(c * (x * x + y * y + Z * Z), 2 * Z, 1e-15);
}

}  // namespace
}  // namespace pvrr::cad
