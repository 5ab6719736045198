// The raster caustics' CPU side (pvrr/method/caustic_mesh.h): planar receivers found with their rectangles,
// and the photon mesh of a thin lens in the sun carrying the power the lens passes (energy-correct before any
// GPU work); the GPU side is tested against the reference in tests/gl/caustic.
#include "pvrr/method/caustic_mesh.h"

#include <gtest/gtest.h>

#include <cmath>

#include "cad/lens.h"
#include "support/test_scenes.h"

namespace pvrr {
namespace {

// The light tracer test's lens: biconvex R = +-0.5 m, n = 1.5, 3 mm, 40 mm round, the sun along its axis, a
// table 0.5 m below (at the focus) to receive it, and a ball beside (not planar).
constexpr double kR = 0.5, kN = 1.5, kT = 0.003, kD = 0.04;

Scene lensOverTable(bool caustics) {
  Scene s;
  s.name = "caustic-mesh";
  s.meshes.push_back(makeQuadMesh(Vec3(0, 0, -0.5), Vec3(0, 0, 1), Vec3(0, 1, 0), 0.3, 0.2));
  s.meshes.back().name = "table";
  s.meshes.push_back(makeSphereMesh(Vec3(1, 0, -0.5), 0.1));
  s.meshes.back().name = "ball";
  s.materials.push_back(DiffuseMaterial{});
  Light sun;
  sun.direction = Vec3(0, 0, -1);
  sun.radiance = Vec3(1.0);
  sun.caustics = caustics;
  s.lights = {sun};
  const cad::Outline disc = cad::Outline::circle(kD);
  Element e;
  e.name = "lens";
  e.type = ElementType::Lens;
  e.lens = cad::makeLens(cad::makeSphere(kR, disc), cad::makeSphere(-kR, disc), disc, kT, 0.0, "lens");
  e.outline = disc;
  e.local_to_world = test::pose(Vec3(0), Vec3(0, 0, 1));
  e.world_to_local = glm::inverse(e.local_to_world);
  e.dispersion = Dispersion::constant(kN);
  s.elements.push_back(e);
  s.updateBounds();
  return s;
}

TEST(CausticMesh, PlanarReceiversAreTheFlatMeshesWithTheirRectangles) {
  const Scene s = lensOverTable(true);
  const std::vector<CausticReceiver> r = planarReceivers(s);
  ASSERT_EQ(r.size(), 1u);  // the ball is not planar
  EXPECT_EQ(r[0].mesh, 0);
  constexpr double kTol = 1e-6;  // float mesh vertices
  EXPECT_NEAR(glm::length(r[0].full.centre - Vec3(0, 0, -0.5)), 0, kTol);
  EXPECT_NEAR(glm::dot(r[0].full.normal(), Vec3(0, 0, 1)), 1, kTol);
  const double w = r[0].full.width_m, h = r[0].full.height_m;
  EXPECT_NEAR(std::min(w, h), 0.2, kTol);
  EXPECT_NEAR(std::max(w, h), 0.3, kTol);
}

TEST(CausticMesh, ThinLensMeshCarriesThePowerTheLensPasses) {
  const Scene s = lensOverTable(true);
  RayScene rays(s);
  const CausticPlan plan = planCaustics(rays, CausticPlanOptions{});
  ASSERT_EQ(plan.meshes.size(), 1u);
  ASSERT_EQ(plan.receivers.size(), 1u);
  EXPECT_EQ(plan.receivers[0].mesh, 0);
  // The power the mesh carries: per triangle, its aperture area times the mean of its corners' density.
  const CausticMesh& m = plan.meshes[0];
  double power = 0;
  for (size_t k = 0; k < m.triangles.size(); k += 3) {
    const CausticVertex& a = m.vertices[m.triangles[k]];
    const CausticVertex& b = m.vertices[m.triangles[k + 1]];
    const CausticVertex& c = m.vertices[m.triangles[k + 2]];
    const Vec2 e1 = b.xy - a.xy, e2 = c.xy - a.xy;
    const double area = 0.5 * std::abs(e1.x * e2.y - e1.y * e2.x);
    power += area * (a.power_density.x + b.power_density.x + c.power_density.x) / 3.0;
  }
  // Incidence under 2.5 deg everywhere: 1 - R differs from 1 - R0 by under 1e-5 (docs/caustics.md).
  const double r0 = std::pow((kN - 1) / (kN + 1), 2);
  const double expected = kPi * 0.25 * kD * kD * (1 - r0) * (1 - r0);
  constexpr double kPowerTol = 0.02;  // the bound for the reference's power conservation
  std::printf(
      "[ caustic mesh ] %zu vertices, %zu triangles, %lld exact photons: power %.6g W, expected %.6g W "
      "(ratio %.5f), rim sliver dropped %.4f\n",
      m.vertices.size(), m.triangles.size() / 3, plan.traced, power, expected, power / expected, m.lost_fraction);
  EXPECT_NEAR(power / expected, 1.0, kPowerTol);
  // The window holds the focus: a paraxial focus 0.5 m below lies on the table's centre.
  EXPECT_LT(glm::length(plan.receivers[0].window.centre - Vec3(0, 0, -0.5)), 1e-3);
}

TEST(CausticMesh, NothingPlannedWithoutALightWithCaustics) {
  const Scene s = lensOverTable(false);
  RayScene rays(s);
  EXPECT_TRUE(causticLights(s).empty());
  const CausticPlan plan = planCaustics(rays, CausticPlanOptions{});
  EXPECT_TRUE(plan.meshes.empty());
  EXPECT_TRUE(plan.receivers.empty());
}

}  // namespace
}  // namespace pvrr
