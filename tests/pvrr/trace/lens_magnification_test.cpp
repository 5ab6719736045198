// Angular magnification of a distant target seen through a thin spherical lens (issue 6, "done when"): the
// reference tracer's rays against the paraxial thick-lens trace and against the thin-lens / lensmaker
// prediction, for a plus and a minus lens.
//
// Set-up: the eye at the origin looks along -z; the lens (eye-side vertex at distance d_v, centre thickness
// t, index n, surfaces R_front and R_back in pvrr's convention, cad/sag.h) faces it. An eye ray at angle a to
// the axis leaves the lens at angle b: a target at infinity subtending b is seen subtending a, so the angular
// magnification is M = tan a / tan b (a -> 0).
//
// Predictions and bounds (optics facts: /work/shared/notes/optics-facts.md):
// - Thin lens (lensmaker): P = (n - 1)(1/R_front - 1/R_back) (both radii in the convention above), and for an
//   object at infinity M_thin = 1 / (1 - d P), d the distance from the eye to the lens's middle plane
//   (d = d_v + t/2).
// - The exact paraxial value of the real, thick lens is M = 1 / (1 - d' P_eq) with the equivalent power
//   P_eq = P1 + P2 - (t/n) P1 P2 and d' the distance from the eye to the principal plane on the eye's side.
//   For a symmetric lens (P1 = P2 = P/2) that plane lies t/(2n) inside the eye-side vertex, so
//   |d' - d| = t/2 - t/(2n) = t (n - 1) / (2n) =: Dd, and |P_eq - P| = (t/n) P^2 / 4 =: DP. Hence
//     |M / M_thin - 1| = |d' P_eq - d P| / |1 - d' P_eq| <= e / (|1 - d P| - e),  e = |P| Dd + d DP + Dd DP:
//   the paraxial bound for the thin-lens prediction.
// - The traced rays are not paraxial: at field angle a the relative departure from the paraxial value is
//   third order (distortion), c a^2 with c of order (d |P|)^2 + 1 for these lenses; at a = 1 mrad, c a^2 <
//   1e-5, the bound between the tracer and the paraxial thick-lens trace (computed here by ABCD matrices).
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "cad/lens.h"
#include "pvrr/trace/tracer.h"
#include "support/test_scenes.h"

namespace pvrr {
namespace {

// Field angle of the traced rays: small enough that the third-order terms (c a^2) stay below kFieldRel.
constexpr double kFieldAngle_rad = 1e-3;
constexpr double kFieldRel = 1e-5;

struct LensCase {
  const char* name;
  double r_front, r_back, thickness, vertex_distance, n;
};

// Paraxial trace through the thick lens, from the eye: (height, angle) along the travel direction -z, with
// translation [[1, L], [0, 1]] and refraction [[1, 0], [-(n2 - n1)/(n2 Rs), n1/n2]]; Rs > 0 when the centre of
// curvature lies further along the travel, which is pvrr's R > 0 (centre at z_vertex - R). Returns
// M = a / b.
double paraxialMagnification(const LensCase& c) {
  double y = 0, u = 1.0;
  auto translate = [&](double l) { y += l * u; };
  auto refract = [&](double n1, double n2, double rs) { u = -(n2 - n1) / (n2 * rs) * y + n1 / n2 * u; };
  translate(c.vertex_distance);
  refract(1.0, c.n, c.r_front);
  translate(c.thickness);
  refract(c.n, 1.0, c.r_back);
  return 1.0 / u;
}

// The traced magnification: a ray from the eye at kFieldAngle_rad (in the xz or yz plane), its direction
// after the last refraction.
double tracedMagnification(const LensCase& c, bool vertical) {
  Scene s = test::roomScene(Vec3(0), Vec3(0, 0, -1));
  const double diameter = 0.02;
  const cad::Outline disc = cad::Outline::circle(diameter);
  Element e;
  e.name = c.name;
  e.type = ElementType::Lens;
  e.lens = cad::makeLens(cad::makeSphere(c.r_front, disc), cad::makeSphere(c.r_back, disc), disc, c.thickness, 0.0,
                         c.name);
  e.outline = disc;
  e.local_to_world = test::pose(Vec3(0, 0, -c.vertex_distance), Vec3(0, 0, 1));
  e.world_to_local = glm::inverse(e.local_to_world);
  e.dispersion = Dispersion::constant(c.n);
  s.elements.push_back(e);
  s.updateBounds();
  RayScene rays(s);
  Tracer tracer(rays, TraceOptions{});
  const double a = kFieldAngle_rad;
  const Vec3 d = vertical ? Vec3(0, std::sin(a), -std::cos(a)) : Vec3(std::sin(a), 0, -std::cos(a));
  std::vector<PathSegment> path;
  tracer.trace(Vec3(0), d, -1, &path);
  EXPECT_GE(path.size(), 3u);
  if (path.size() < 3) return 0;
  EXPECT_EQ(path[0].event, "refract");
  EXPECT_EQ(path[1].event, "refract");
  const Vec3 out = path[2].direction;
  const double tan_b = (vertical ? out.y : out.x) / -out.z;
  return std::tan(a) / tan_b;
}

void checkLens(const LensCase& c) {
  const double power = (c.n - 1) * (1 / c.r_front - 1 / c.r_back);
  const double d = c.vertex_distance + 0.5 * c.thickness;
  const double m_thin = 1 / (1 - d * power);
  const double dd = c.thickness * (c.n - 1) / (2 * c.n), dp = c.thickness / c.n * power * power / 4;
  const double e = std::abs(power) * dd + d * dp + dd * dp;
  const double thin_bound = e / (std::abs(1 - d * power) - e);

  const double m_parax = paraxialMagnification(c);
  EXPECT_LE(std::abs(m_parax / m_thin - 1), thin_bound) << c.name << ": paraxial thick lens vs thin lens";
  for (bool vertical : {false, true}) {
    const double m = tracedMagnification(c, vertical);
    EXPECT_NEAR(m / m_parax, 1.0, kFieldRel) << c.name << (vertical ? " (vertical)" : " (horizontal)");
    EXPECT_LE(std::abs(m / m_thin - 1), thin_bound + kFieldRel) << c.name;
    std::cout << "[ measured ] " << c.name << ": P = " << power << " D, M traced " << m << ", paraxial " << m_parax
              << ", thin lens " << m_thin << " (bound " << thin_bound << ")\n";
  }
}

TEST(LensMagnification, PlusLensMagnifiesAsTheLensmakerPredicts) {
  // +5 D equiconvex, n = 1.5: R = 2 (n - 1) / P = 0.2 m; 0.6 mm thick (edge 0.1 mm at 20 mm diameter), 0.1 m
  // from the eye: M_thin = 1 / (1 - 0.1003 * 5) ~ 2.0.
  checkLens({"plus lens", 0.2, -0.2, 0.0006, 0.1, 1.5});
}

TEST(LensMagnification, MinusLensMinifiesAsTheLensmakerPredicts) {
  // -5 D equiconcave: R_front = -0.2 (concave towards the eye), R_back = +0.2; 0.5 mm at the centre.
  checkLens({"minus lens", -0.2, 0.2, 0.0005, 0.1, 1.5});
}

}  // namespace
}  // namespace pvrr
