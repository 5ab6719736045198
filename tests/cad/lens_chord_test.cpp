// The straight chord through a lens's glass (cad/lens_chord.h) against closed forms: a plane slab's t / cos,
// a biconvex lens's sphere intersections from either face, and the edge where a chord leaves the outline.
#include <gtest/gtest.h>

#include <cmath>

#include "cad/lens_chord.h"

namespace pvrr::cad {
namespace {

// Newton stops within 1e-12 m of the other surface; along an oblique line that is a little more in length.
constexpr double kChord_m = 1e-11;
// The edge is found by bisection to ~1e-17 of the chord, the closed form is exact.
constexpr double kEdge_m = 1e-12;

// The nearest positive s where p + s e meets the sphere of radius R whose vertex is at z_vertex, on the
// sag's own cap (cad/sag.h: the centre at z_vertex - R).
double sphereHit(double R, double z_vertex, const Vec3& p, const Vec3& e) {
  const Vec3 c(0, 0, z_vertex - R);
  const double b = glm::dot(e, p - c), cc = glm::dot(p - c, p - c) - R * R;
  const double root = std::sqrt(b * b - cc);
  for (double s : {-b - root, -b + root})
    if (s > 1e-9 && ((p + s * e).z - c.z) * R > 0) return s;
  return std::nan("");
}

TEST(LensChord, PlaneSlabIsThicknessOverCosine) {
  const Outline disc = Outline::circle(0.06);
  const double t = 0.004;
  const LensSolid slab = makeLens(makePlane(disc), makePlane(disc), disc, t, 0, "slab");
  for (double deg : {0.0, 20.0, 45.0, 70.0}) {
    const double a = radians(deg);
    const Vec3 d(std::sin(a), 0, -std::cos(a));
    const auto front = chordInside(slab, 0, Vec3(0.001, 0.002, 0), d);
    ASSERT_TRUE(front.has_value()) << deg;
    EXPECT_NEAR(front->length_m, t / std::cos(a), kChord_m) << deg;
    EXPECT_FALSE(front->through_edge);
    // From the back, with d given in the other sense: the same chord.
    const auto back = chordInside(slab, 1, Vec3(-0.003, 0.001, -t), d);
    ASSERT_TRUE(back.has_value()) << deg;
    EXPECT_NEAR(back->length_m, t / std::cos(a), kChord_m) << deg;
  }
  // Along the surface: no chord.
  EXPECT_FALSE(chordInside(slab, 0, Vec3(0, 0, 0), Vec3(1, 0, 0)).has_value());
}

TEST(LensChord, BiconvexLensMatchesTheSpheres) {
  const Outline disc = Outline::circle(0.04);
  const double R = 0.1;
  const LensSolid lens = makeLens(makeSphere(R, disc), makeSphere(-R, disc), disc, 0.005, 0, "biconvex");
  const double t = lens.centre_thickness;
  for (const Vec2 xy : {Vec2(0, 0), Vec2(0.008, -0.004), Vec2(-0.012, 0.01)})
    for (const Vec3 dir : {Vec3(0, 0, -1), glm::normalize(Vec3(0.3, -0.1, -1)), glm::normalize(Vec3(-0.2, 0.4, -1))}) {
      const double zf = -(R - std::sqrt(R * R - glm::dot(xy, xy)));
      const Vec3 p(xy, zf);
      const auto c = chordInside(lens, 0, p, dir);
      ASSERT_TRUE(c.has_value());
      EXPECT_FALSE(c->through_edge);
      EXPECT_NEAR(c->length_m, sphereHit(-R, -t, p, dir), kChord_m) << xy.x << " " << xy.y;
      // Back again from where it left: the same length.
      const Vec3 q = p + c->length_m * dir;
      const auto back = chordInside(lens, 1, q, -dir);
      ASSERT_TRUE(back.has_value());
      EXPECT_NEAR(back->length_m, c->length_m, kChord_m);
    }
  // Along the axis, the chord is the thickness at the point.
  const auto axial = chordInside(lens, 0, Vec3(0.01, 0, -(R - std::sqrt(R * R - 1e-4))), Vec3(0, 0, 1));
  ASSERT_TRUE(axial.has_value());
  EXPECT_NEAR(axial->length_m, lens.thicknessAt(0.01, 0), kChord_m);
}

TEST(LensChord, LeavesThroughTheEdgeNearTheRim) {
  const Outline disc = Outline::circle(0.04);
  const double t = 0.01;
  const LensSolid slab = makeLens(makePlane(disc), makePlane(disc), disc, t, 0, "slab");
  // 1 mm inside the rim, 45 degrees outwards: the back plane is 10 mm further along x, the rim 1 mm.
  const Vec3 p(0.019, 0, 0), d = glm::normalize(Vec3(1, 0, -1));
  const auto c = chordInside(slab, 0, p, d);
  ASSERT_TRUE(c.has_value());
  EXPECT_TRUE(c->through_edge);
  EXPECT_NEAR(c->length_m, 0.001 * std::sqrt(2.0), kEdge_m);
}

}  // namespace
}  // namespace pvrr::cad
