// Mirror surface maps (pvrr/impostor/surface_map.h): bilinear samples of the maps (the CPU twin of the shader's
// `bilinear`) lie on the exact surface, with its derivatives and normal, across NURBS (car mirror),
// subdivision (saddle) and sag (concave) surfaces; the outline mask covers the outline. The shader's
// parameter-to-texture mapping (u_sm) is not checked here: its Gauss-Newton steps read position and normal
// through the same mapping, so an offset would move both together (the GL tests check what it sees).
#include <gtest/gtest.h>

#include <cstdio>
#include <random>

#include "pvrr/base/error.h"
#include "cad/sag.h"
#include "pvrr/impostor/surface_map.h"
#include "support/scenes.h"

namespace pvrr {
namespace {

TEST(SurfaceMap, SamplesLieOnTheExactSurface) {
  // Bilinear interpolation between samples h apart errs by at most h^2/8 (|S_uu| + |S_vv|) in position, and
  // likewise in the normal on a smooth surface: measured 4-7e-8 m, and normals 3e-8 rad (sphere) and 8e-7
  // rad (subdivision). The car mirror's NURBS changes its curvature across knot lines, where the normal's
  // interpolation error is first order, h times the jump: 7e-5 rad measured (a reflection 0.5' off at
  // worst; the impostor's median on the car mirror is 0.009').
  struct Case {
    const char* scene;
    double position_tol_m, normal_tol_rad;
  };
  for (const Case& c : {Case{"car-mirror", 2e-7, 2e-4}, Case{"saddle-mirror", 2e-7, 1e-5}, Case{"concave-mirror", 2e-7, 1e-6}}) {
    const Scene s = test::shippedScene(c.scene);
    const cad::Surface& surf = *s.elements[0].surface;
    const Element& el = s.elements[0];
    const SurfaceMap m = buildSurfaceMap(surf, 512, el.has_outline ? &el.outline : nullptr);
    const cad::ParamDomain d = surf.domain();
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> uu(d.u0, d.u1), vv(d.v0, d.v1);
    double worst_p = 0, worst_n = 0, worst_d = 0, scale_d = 0;
    for (int k = 0; k < 3000; ++k) {
      const double u = uu(rng), v = vv(rng);
      const cad::SurfaceDerivs exact = surf.evaluate(u, v);
      const SurfaceMapSample got = sampleSurfaceMap(m, u, v);
      worst_p = std::max(worst_p, glm::length(got.position - exact.p));
      worst_n = std::max(worst_n, angleBetween(got.normal, surf.normal(u, v)));
      // Stored with respect to the normalised parameters.
      const Vec3 du = exact.du * (d.u1 - d.u0), dv = exact.dv * (d.v1 - d.v0);
      worst_d = std::max(worst_d, std::max(glm::length(got.du - du), glm::length(got.dv - dv)));
      scale_d = std::max(scale_d, std::max(glm::length(du), glm::length(dv)));
    }
    std::printf("[ measured ] %s: position %.3g m, normal %.3g rad, derivatives %.3g of %.3g\n", c.scene, worst_p,
                worst_n, worst_d, scale_d);
    EXPECT_LE(worst_p, c.position_tol_m) << c.scene;
    EXPECT_LE(worst_n, c.normal_tol_rad) << c.scene;
    // The derivatives only steer the shader's Gauss-Newton steps: a few per cent would do; they are far better.
    EXPECT_LE(worst_d, 0.01 * scale_d) << c.scene;
    // The mask: where the four samples around (u, v) are all inside the outline the map says inside, where all
    // are outside it says outside. (Between, the shader's 0.5 threshold places the rim to half a sample.)
    if (el.has_outline) {
      int wrong = 0, checked = 0;
      const double su = (d.u1 - d.u0) / 511, sv = (d.v1 - d.v0) / 511;
      for (int k = 0; k < 3000; ++k) {
        const double u = uu(rng), v = vv(rng);
        const double a0 = d.u0 + su * std::floor((u - d.u0) / su), b0 = d.v0 + sv * std::floor((v - d.v0) / sv);
        int in = 0;
        for (const Vec2 q : {Vec2(a0, b0), Vec2(a0 + su, b0), Vec2(a0, b0 + sv), Vec2(a0 + su, b0 + sv)})
          in += el.outline.contains(q);
        if (in != 0 && in != 4) continue;
        ++checked;
        wrong += (sampleSurfaceMap(m, u, v).inside >= 0.5) != (in == 4);
      }
      EXPECT_GT(checked, 2000) << c.scene;
      EXPECT_EQ(wrong, 0) << c.scene;
    }
  }
}

// A sphere mirror (radius 0.12 m) whose circular outline (0.2 m across) has its box's corners beyond the
// radius, where the sag is undefined: those samples are taken from points moved towards the centre, marked
// outside the outline, and the map builds.
TEST(SurfaceMap, SamplesWhereTheSurfaceIsUndefinedMoveInwards) {
  const cad::Outline disc = cad::Outline::circle(0.2);
  const cad::SagSurfacePtr sphere = cad::makeSphere(0.12, disc);
  const SurfaceMap m = buildSurfaceMap(*sphere, 64, &disc);
  EXPECT_GT(m.moved_samples, 0);
  EXPECT_LT(m.moved_samples, 64 * 64 / 4);
  // The corner sample (u0, v0) was moved, and lies outside the outline.
  EXPECT_EQ(m.position[3], 0.0f);
  for (float x : m.position) EXPECT_TRUE(std::isfinite(x));
  // The centre is evaluated where it lies, inside (to the interpolation between samples 3.2 mm apart:
  // h^2/8 (2/R) = 2.1e-5 m).
  const SurfaceMapSample c = sampleSurfaceMap(m, 0.0, 0.0);
  EXPECT_NEAR(c.position.z, sphere->evaluate(0, 0).p.z, 3e-5);
  EXPECT_GE(c.inside, 0.5);
}

TEST(SurfaceMap, RejectsBadSizes) {
  const Scene s = test::shippedScene("concave-mirror");
  EXPECT_THROW(buildSurfaceMap(*s.elements[0].surface, 1), Error);
  EXPECT_THROW(buildSurfaceMap(*s.elements[0].surface, 5000), Error);
}

}  // namespace
}  // namespace pvrr
