// The reference's caustic on curved receivers (pvrr/trace/light_tracer.h DepositOptions::height_field): the map
// over the receiver's best-fit plane holds the irradiance per unit area of the curved surface. Closed form: a
// plane mirror (reflectance 0.9) turns the sun into a collimated beam along +x, which meets a concave cylinder
// segment or a spherical bowl; on the surface the irradiance is E rho |d . n_s| (n_s the surface's normal), and
// the power over the surface (the map times each cell's surface area, cell area / cos) is the beam's,
// E rho x the beam's cross-section. Figures: docs/caustics.md "Curved receivers".
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "cad/lens.h"
#include "pvrr/base/error.h"
#include "pvrr/method/caustic_mesh.h"
#include "pvrr/trace/light_tracer.h"
#include "support/height_field.h"
#include "support/test_scenes.h"

namespace pvrr {
namespace {

// The mirror: a plane disc 100 mm round at the origin, its normal (1, 0, 1)/sqrt 2, the sun along -z: the beam
// leaves along +x with an elliptic cross-section of half axes 50 mm (along y) and 35.4 mm (along z).
constexpr double kMirrorD = 0.1, kRho = 0.9;
constexpr double kBeamY = 0.05, kBeamZ = 0.05 / 1.4142135623730951;
// The receivers: radius 0.1 m, their lowest point (the base) at x = 0.4, concave towards the mirror (-x).
constexpr double kRadius = 0.1;
const Vec3 kBase(0.4, 0, 0), kFacing(-1, 0, 0), kAcross(0, 1, 0);

Scene beamScene(const test::HeightField& f) {
  Scene s;
  s.name = "curved-receiver";
  s.observer.eye = Vec3(0.2, 0.3, 0.3);
  s.observer.target = Vec3(0.3, 0, 0);
  test::addBeamOnReceiver(s, f, 160, 120, "receiver", kMirrorD, kRho);  // sun radiance 1 W/m^2
  s.updateBounds();
  return s;
}

struct Case {
  const char* name;
  test::HeightField field;
};

Case cylinderCase() {
  // Axis along z (the receiver's v), +-53 deg about it.
  return {"cylinder", test::cylinderSegment(kBase, kFacing, kAcross, kRadius, 0.08, 0.06)};
}
Case bowlCase() { return {"bowl", test::sphericalBowl(kBase, kFacing, kAcross, kRadius, 0.07)}; }

// The bounds. Per cell inside the beam (two cells from its rim): the kernel's average of a field that varies by
// under 2 % across a cell, the facets' normals (1 mm facets on R = 0.1 m: within 0.005 rad of the sphere's), and
// the stratified photons (about 500 a cell); measured at most 0.27 %. Power: the aperture's stratified estimate of
// the disc and the surface area per cell from the smooth surface; measured at most 0.05 %.
constexpr double kCellTol = 0.015, kPowerTol = 0.005;

TEST(CurvedReceiver, BeamOnACurvedSurfaceGivesTheClosedFormIrradianceAndPower) {
  for (const Case& c : {cylinderCase(), bowlCase()}) {
    const Scene s = beamScene(c.field);
    const std::vector<CausticReceiver> curved = heightFieldReceivers(s);
    ASSERT_EQ(curved.size(), 1u) << c.name;
    ASSERT_TRUE(curved[0].curved);
    ReceiverRect rect = curved[0].full;
    EXPECT_NEAR(glm::dot(rect.normal(), kFacing), 1, 1e-9) << c.name;  // symmetric: the plane faces the mirror
    rect.cells_u = int(std::lround(rect.width_m / 0.004));
    rect.cells_v = int(std::lround(rect.height_m / 0.004));
    RayScene rays(s);
    CausticOptions o;
    o.photons_per_side = 512;
    const PhotonBundle b = shootCausticPhotons(rays, o);
    DepositOptions d;
    d.mesh = 0;
    d.height_field = true;
    const CausticResult r = depositPhotons(b, rect, d);
    // Every photon that left the mirror lands on the receiver.
    EXPECT_NEAR(r.landed_power.x / b.leaving_power.x, 1, 1e-9) << c.name;
    const Vec3 beam(1, 0, 0);
    double worst = 0, mean = 0, surface_power = 0;
    int cells = 0;
    const Vec3 v = c.field.v();
    for (int j = 0; j < rect.cells_v; ++j)
      for (int i = 0; i < rect.cells_u; ++i) {
        const Vec2 uv = rect.cellCentre(i, j);
        const Vec3 p = rect.toWorld(uv);
        // The height field's own coordinates of the cell's centre (its axes are the receiver's, up to sign).
        const double x = glm::dot(p - kBase, c.field.u), y = glm::dot(p - kBase, v);
        // Surface area over the cell: cell area / cos, averaged on an 8 x 8 grid inside it.
        double inv_cos = 0;
        for (int b2 = 0; b2 < 8; ++b2)
          for (int a2 = 0; a2 < 8; ++a2) {
            const double xx = x + rect.cellWidth() * ((a2 + 0.5) / 8 - 0.5),
                         yy = y + rect.cellHeight() * ((b2 + 0.5) / 8 - 0.5);
            inv_cos += 1 / glm::dot(c.field.normal(xx, yy), c.field.n) / 64;
          }
        surface_power += r.grid.scalar(i, j) * rect.cellArea() * inv_cos;
        // Cells well inside the beam: the closed form.
        constexpr double kMargin = 0.006;  // 1.5 cells
        const double by = (std::abs(p.y) + kMargin) / kBeamY, bz = (std::abs(p.z) + kMargin) / kBeamZ;
        if (by * by + bz * bz > 1) continue;
        const double expected = kRho * std::abs(glm::dot(beam, c.field.normal(x, y)));
        const double err = std::abs(r.grid.scalar(i, j) / expected - 1);
        worst = std::max(worst, err);
        mean += err;
        ++cells;
      }
    mean /= cells;
    const double beam_power = kRho * kPi * kBeamY * kBeamZ;
    std::printf(
        "[ curved ] %s: %d cells inside the beam, relative error mean %.5f max %.5f; power over the surface / beam "
        "%.5f (the plane's sum of irradiance x cell area: %.5f)\n",
        c.name, cells, mean, worst, surface_power / beam_power, r.grid.power().x / beam_power);
    EXPECT_GT(cells, 100) << c.name;
    EXPECT_LE(worst, kCellTol) << c.name;
    EXPECT_NEAR(surface_power / beam_power, 1, kPowerTol) << c.name;
  }
}

// A curved deposit keeps the hits on the receiver's own mesh: it needs to be told which.
TEST(CurvedReceiver, HeightFieldNeedsItsMesh) {
  const ReceiverRect rect;
  DepositOptions d;
  d.height_field = true;
  EXPECT_THROW(depositPhotons(PhotonBundle{}, rect, d), Error);
}

// The concave mirror R = 1 m (100 mm, reflectance 0.9) facing the sun along its axis focuses at R/2 = 0.5 m onto
// a bowl (R = 0.1 m) whose lowest point sits at the focus, tilted 30 deg: the brightest cell lies at the focus,
// within the depth of focus (+-1.13 mm, docs/caustics.md) times tan 30 deg along the tilted surface, rounded up
// to 1 mm; the power over the surface is what the bowl receives.
TEST(CurvedReceiver, ConcaveMirrorFocusOnATiltedBowl) {
  const double tilt = radians(30);
  const Vec3 n(0, -std::sin(tilt), -std::cos(tilt));  // concave towards the mirror, tilted about x
  const test::HeightField f = test::sphericalBowl(Vec3(0, 0, 0.5), n, Vec3(1, 0, 0), kRadius, 0.01);
  Scene s;
  s.name = "mirror-bowl";
  s.observer.eye = Vec3(0.3, 0.2, 0.8);
  s.observer.target = Vec3(0, 0, 0.25);
  s.meshes.push_back(test::heightFieldMesh(f, 80, 80, "bowl"));
  s.materials.push_back(DiffuseMaterial{});
  Light sun;
  sun.direction = Vec3(0, 0, -1);
  s.lights = {sun};
  const cad::Outline disc = cad::Outline::circle(0.1);
  test::addMirror(s, cad::makeSphere(-1.0, disc), disc, test::pose(Vec3(0), Vec3(0, 0, 1)), 7, kRho);
  s.updateBounds();
  const std::vector<CausticReceiver> curved = heightFieldReceivers(s);
  ASSERT_EQ(curved.size(), 1u);
  ReceiverRect rect = curved[0].full;
  rect.cells_u = rect.cells_v = 200;  // 0.1 mm
  RayScene rays(s);
  CausticOptions o;
  o.photons_per_side = 512;
  const PhotonBundle b = shootCausticPhotons(rays, o);
  DepositOptions d;
  d.mesh = 0;
  d.height_field = true;
  const CausticResult r = depositPhotons(b, rect, d);
  size_t peak = 0;
  for (size_t k = 0; k < r.grid.irradiance.size(); ++k)
    if (r.grid.irradiance[k].x > r.grid.irradiance[peak].x) peak = k;
  const int pi = int(peak % size_t(rect.cells_u)), pj = int(peak / size_t(rect.cells_u));
  const Vec3 p = rect.toWorld(rect.cellCentre(pi, pj));
  const double x = glm::dot(p - f.base, f.u), y = glm::dot(p - f.base, f.v());
  const Vec3 on_surface = f.point(x, y);
  const double off = glm::length(on_surface - Vec3(0, 0, 0.5));
  std::printf("[ curved ] mirror focus on a bowl tilted 30 deg: peak %.4g W/m^2 at %.3f mm from R/2 on the surface\n",
              r.grid.irradiance[peak].x, 1e3 * off);
  EXPECT_LE(off, 1e-3);
}

}  // namespace
}  // namespace pvrr
