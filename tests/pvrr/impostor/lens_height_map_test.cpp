// Refractor height maps (pvrr/impostor/lens_height_map.h): the bilinear samples the GPU takes lie on the exact sag
// surfaces to the interpolation error of a smooth surface, with outward normals, over the whole outline.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "pvrr/base/error.h"
#include "pvrr/impostor/lens_height_map.h"
#include "support/scenes.h"

namespace pvrr {
namespace {

// Bilinear interpolation of a smooth height on a grid of spacing h errs by at most h^2/8 (|z_xx| + |z_yy|).
// With 512 texels over a 55-60 mm box (h ~ 0.11 mm) and curvatures up to 50 m^-1 (radii down to 20 mm):
// 1.4e-7 m. Measured: spectacle lens 4.5e-8 m (radius 70.9 mm), progressive 8.5e-8 m, reading lens 1.6e-8 m.
constexpr double kHeightTol_m = 1.5e-7;
// The normals: a smooth surface interpolates them to ~h^2 (2e-7 rad measured on the spectacle lens), but the
// progressive lens's NURBS back surface changes its curvature across knot lines, where the error is first
// order, h times the jump: 4.4e-5 rad measured. 1e-4 rad turns an exit ray by at most (n - 1) 1e-4 rad = 0.17'.
constexpr double kNormalTol_rad = 1e-4;

TEST(LensHeightMap, SamplesLieOnTheExactSurfacesWithOutwardNormals) {
  for (const char* name : {"spectacle-lens", "progressive-lens", "reading-lens"}) {
    const Scene s = test::shippedScene(name);
    const Element& lens = s.elements[0];
    ASSERT_EQ(lens.type, ElementType::Lens) << name;
    const LensHeightMap m = buildLensHeightMap(lens, 512);
    // Square texels, 512 along the longer side, covering the outline with its margin.
    EXPECT_EQ(std::max(m.nx, m.ny), 512) << name;
    EXPECT_NEAR(m.dx, m.dy, 1e-3 * m.dx) << name;
    const Vec2 lo = lens.lens.outline.boundsMin(), hi = lens.lens.outline.boundsMax();
    EXPECT_LE(m.x0, lo.x - 0.04 * (hi.x - lo.x)) << name;
    EXPECT_GE(m.x0 + m.nx * m.dx, hi.x + 0.04 * (hi.x - lo.x)) << name;
    EXPECT_LE(m.y0, lo.y - 0.04 * (hi.y - lo.y)) << name;
    EXPECT_GE(m.y0 + m.ny * m.dy, hi.y + 0.04 * (hi.y - lo.y)) << name;
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> ux(lo.x, hi.x), uy(lo.y, hi.y);
    int checked = 0;
    double worst_z = 0, worst_n = 0;
    while (checked < 2000) {
      const double x = ux(rng), y = uy(rng);
      if (!lens.lens.outline.contains(Vec2(x, y))) continue;
      ++checked;
      for (const bool back : {false, true}) {
        const cad::SagSurface& surf = back ? *lens.lens.back : *lens.lens.front;
        const cad::SurfacePoint exact = surf.sample(x, y, false);
        const Vec4 got = sampleHeightMap(m, back, x, y);
        worst_z = std::max(worst_z, std::abs(got.x - exact.p.z));
        // Outward: the front faces +z (the eye), the back -z.
        const Vec3 outward = back ? -exact.n : exact.n;
        worst_n = std::max(worst_n, angleBetween(Vec3(got.y, got.z, got.w), outward));
        EXPECT_EQ(got.w > 0, !back) << name;
      }
    }
    EXPECT_LE(worst_z, kHeightTol_m) << name;
    EXPECT_LE(worst_n, kNormalTol_rad) << name;
    // The outline mask and the glass: at every texel inside the outline the front lies above the back; the
    // mask covers the outline's share of the box (an ellipse or circle: pi/4 of its own box, which is the
    // map's box less the 5 % margins), to a texel row's worth.
    size_t inside = 0;
    double thinnest = kInf;
    for (size_t k = 0; k < m.inside.size(); ++k) {
      if (m.inside[k] == 0.0f) continue;
      ++inside;
      thinnest = std::min(thinnest, double(m.front[4 * k]) - double(m.back[4 * k]));
    }
    EXPECT_GT(thinnest, 0.5 * lens.lens.minimumThickness()) << name;
    const double share = double(inside) / double(m.inside.size());
    const double expected = kPi / 4 / ((1 + 2 * kHeightMapMargin) * (1 + 2 * kHeightMapMargin));
    EXPECT_NEAR(share, expected, 2.0 / std::min(m.nx, m.ny)) << name;
    EXPECT_EQ(m.clamped_texels, 0) << name;
    // The shader's search stops at the map's reach: no straight path inside the outline is longer than the
    // diagonal of the outline's box.
    EXPECT_GE(m.reach, glm::length(hi - lo)) << name;
  }
}

TEST(LensHeightMap, RejectsAMirrorAndBadSizes) {
  const Scene car = test::shippedScene("car-mirror");
  EXPECT_THROW(buildLensHeightMap(car.elements[0], 512), Error);
  const Scene lens = test::shippedScene("spectacle-lens");
  EXPECT_THROW(buildLensHeightMap(lens.elements[0], 4), Error);
  EXPECT_THROW(buildLensHeightMap(lens.elements[0], 100000), Error);
}

}  // namespace
}  // namespace pvrr
