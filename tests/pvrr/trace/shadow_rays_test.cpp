// The reference's shadow rays against closed-form shadow outlines: a sphere's shadow under a directional
// light is the ellipse of its projection, a square's under a point light is the square scaled by similar
// triangles; mirrors block, lenses pass (1 - R0)^2.
#include <gtest/gtest.h>

#include "pvrr/trace/shading.h"
#include "pvrr/trace/shadow_rays.h"
#include "pvrr/trace/tracer.h"
#include "support/shadow_scenes.h"

namespace pvrr {
namespace {

// The scene's sphere is a 48 x 24 mesh: its silhouette lies within r (1 - cos(pi / 24)) ~ 0.9 % of r inside
// the exact sphere's. Ground points within 2 % of the outline (in normalised radius) are left out.
constexpr double kSphereBand = 0.02;
// The quad is exact; its shadow's edge is found to float precision of the Embree candidates (~1e-7 m over
// metres): 0.1 % of the half side is far beyond that.
constexpr double kQuadBand = 1e-3;

// Ground points on a regular grid over [-extent, extent]^2.
template <class F>
void forGroundGrid(double extent, int n, F f) {
  for (int i = 0; i < n; ++i)
    for (int k = 0; k < n; ++k) f(Vec3(-extent + 2 * extent * (i + 0.5) / n, 0, -extent + 2 * extent * (k + 0.5) / n));
}

TEST(ShadowRays, SphereUnderADirectionalLightShadowsItsProjectedEllipse) {
  for (const Vec3 dir : {Vec3(0, -1, 0), Vec3(0.5, -1, 0.2), Vec3(-0.8, -1, -0.3)}) {
    const Vec3 d = glm::normalize(dir);
    Scene s = test::shadowScene("sphere", R"({"type": "directional", "direction": [)" + std::to_string(dir.x) + ", " +
                                              std::to_string(dir.y) + ", " + std::to_string(dir.z) + "]}");
    RayScene rays(s);
    ShadowRays shadows(rays);
    const Light& light = s.lights[0];
    ASSERT_TRUE(light.shadows);  // on unless the scene says otherwise
    int inside = 0, checked = 0;
    forGroundGrid(1.2, 120, [&](const Vec3& g) {
      const double r = test::sphereShadowRadius(d, g);
      if (std::abs(r - 1) < kSphereBand) return;
      ++checked;
      inside += r < 1;
      EXPECT_EQ(shadows.transmittance(light, g).x, r < 1 ? 0.0 : 1.0) << "at " << g.x << ", " << g.z;
    });
    EXPECT_GT(inside, 200);  // the shadow is sampled (a disc of r = 0.2 m: ~300 points), not missed
    EXPECT_GT(checked, 10000);
  }
}

TEST(ShadowRays, SquareUnderAPointLightShadowsItsScaledSquare) {
  for (const Vec3 l : {Vec3(0, 2, 0), Vec3(0.3, 2.5, -0.2), Vec3(-0.1, 1.5, 0.25)}) {
    Scene s = test::shadowScene("quad", R"({"type": "point", "position": [)" + std::to_string(l.x) + ", " +
                                            std::to_string(l.y) + ", " + std::to_string(l.z) + "]}");
    RayScene rays(s);
    ShadowRays shadows(rays);
    int inside = 0;
    forGroundGrid(1.6, 160, [&](const Vec3& g) {
      const double r = test::quadShadowRadius(l, g);
      if (std::abs(r - 1) < kQuadBand) return;
      inside += r < 1;
      EXPECT_EQ(shadows.transmittance(s.lights[0], g).x, r < 1 ? 0.0 : 1.0) << "at " << g.x << ", " << g.z;
    });
    EXPECT_GT(inside, 1000);
  }
}

TEST(ShadowRays, ShadowsOffLetEveryLightThrough) {
  Scene s = test::shadowScene("quad", R"({"type": "point", "position": [0, 2, 0], "shadows": false})");
  RayScene rays(s);
  EXPECT_FALSE(s.lights[0].shadows);
  EXPECT_EQ(ShadowRays(rays).transmittance(s.lights[0], Vec3(0, 0, 0)), Vec3(1.0));
}

// A mirror blocks light from either side; a lens passes (1 - R0)^2 at its index.
TEST(ShadowRays, MirrorsBlockAndLensesTransmitByFresnel) {
  const std::string light = R"({"type": "directional", "direction": [0, -1, 0]})";
  const std::string mirror = R"({"name": "m", "type": "mirror", "pose": {"position": [1.0, 1.5, 1.0],
      "normal": [0, -1, 0], "up": [0, 0, 1]}, "outline": {"shape": "circle", "diameter": 0.3},
      "surface": {"type": "plane"}, "material": {"reflectance": 0.9}})";
  const std::string lens = R"({"name": "l", "type": "lens", "pose": {"position": [-1.0, 1.5, 1.0],
      "normal": [0, 1, 0], "up": [0, 0, -1]}, "outline": {"shape": "circle", "diameter": 0.3},
      "front": {"type": "sphere", "radius": 1.0}, "back": {"type": "sphere", "radius": -1.0},
      "centre_thickness": 0.03, "material": {"n_d": 1.5, "V_d": 60, "dispersion": false}})";
  Scene s = test::shadowScene("quad", light, mirror + ", " + lens);
  RayScene rays(s);
  ShadowRays shadows(rays);
  const double r0 = (0.5 / 2.5) * (0.5 / 2.5);  // normal incidence at n = 1.5
  EXPECT_NEAR(lensShadowTransmittance(s.elements[1]), (1 - r0) * (1 - r0), 1e-12);
  EXPECT_EQ(shadows.transmittance(s.lights[0], Vec3(1.0, 0, 1.0)), Vec3(0.0));  // under the mirror (its back)
  EXPECT_EQ(shadows.transmittance(s.lights[0], Vec3(1.0, 0, 1.3)), Vec3(1.0));  // beside it
  EXPECT_NEAR(shadows.transmittance(s.lights[0], Vec3(-1.0, 0, 1.0)).x, (1 - r0) * (1 - r0), 1e-12);  // the lens
  // The mirror's front faces down: light from below is blocked as well.
  Light up = s.lights[0];
  up.direction = Vec3(0, 1, 0);
  EXPECT_EQ(shadows.transmittance(up, Vec3(1.0, 3, 1.0)), Vec3(0.0));
}

// With the caustic light added (TraceOptions::caustics), a lens blocks a light with caustics on fully, as the
// raster shadow maps do; a light with caustics off still passes (1 - R0)^2, and mirrors block either way.
TEST(ShadowRays, LensesBlockCausticLightsWhenTheCausticIsAdded) {
  const std::string lens = R"({"name": "l", "type": "lens", "pose": {"position": [-1.0, 1.5, 1.0],
      "normal": [0, 1, 0], "up": [0, 0, -1]}, "outline": {"shape": "circle", "diameter": 0.3},
      "front": {"type": "sphere", "radius": 1.0}, "back": {"type": "sphere", "radius": -1.0},
      "centre_thickness": 0.03, "material": {"n_d": 1.5, "V_d": 60, "dispersion": false}})";
  Scene s = test::shadowScene("quad", R"({"type": "directional", "direction": [0, -1, 0], "caustics": true})", lens);
  RayScene rays(s);
  const double r0 = (0.5 / 2.5) * (0.5 / 2.5);
  const Vec3 under(-1.0, 0, 1.0), beside(-1.0, 0, 1.3);
  Light on = s.lights[0], off = s.lights[0];
  ASSERT_TRUE(on.caustics);
  off.caustics = false;
  const ShadowRays plain(rays), blocking(rays, true);
  EXPECT_NEAR(plain.transmittance(on, under).x, (1 - r0) * (1 - r0), 1e-12);
  EXPECT_EQ(blocking.transmittance(on, under), Vec3(0.0));
  EXPECT_EQ(blocking.transmittance(on, beside), Vec3(1.0));
  EXPECT_EQ(blocking.transmittance(off, under), plain.transmittance(off, under));
}

// The tracer shades a shadowed ground point with the ambient light only, a lit one with both lights.
TEST(ShadowRays, TracerShadesShadowedPointsWithAmbientOnly) {
  Scene s = test::shadowScene("sphere", R"({"type": "directional", "direction": [0, -1, 0], "intensity": 0.8})");
  RayScene rays(s);
  Tracer tracer(rays, TraceOptions{});
  const Vec3 top(0, 5, 0);
  const Vec3 under = Vec3(test::kSphereCentre.x, 0, test::kSphereCentre.z) + Vec3(0.05, 0, 0);
  const Vec3 lit(0.8, 0, 0.8);
  // Rays from below the ground plane would miss; aim from a point beside the sphere.
  const Vec3 from(-1.0, 0.3, 1.5);
  const TraceResult rs = tracer.trace(from, glm::normalize(under - from), 0);
  const TraceResult rl = tracer.trace(top, glm::normalize(lit - top), 0);
  ASSERT_LT(glm::length(rs.seen - under), 1e-9);
  ASSERT_LT(glm::length(rl.seen - lit), 1e-9);
  EXPECT_NEAR(rs.color.x, 0.7 * 0.2, 1e-12);
  EXPECT_NEAR(rl.color.x, 0.7 * (0.2 + 0.8), 1e-12);
}

}  // namespace
}  // namespace pvrr
