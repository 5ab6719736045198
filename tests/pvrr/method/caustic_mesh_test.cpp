// The raster caustics' CPU side (pvrr/method/caustic_mesh.h): planar receivers found with their rectangles,
// and the photon mesh of a thin lens in the sun carrying the power the lens passes (energy-correct before any
// GPU work); the GPU side is tested against the reference in tests/gl/caustic.
#include "pvrr/method/caustic_mesh.h"

#include <gtest/gtest.h>

#include <cmath>

#include "cad/lens.h"
#include "support/height_field.h"
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

// Curved receivers: the meshes that are height fields over their best-fit plane, and only those.
TEST(CausticMesh, HeightFieldReceiversAreTheCurvedSheetsOverAPlane) {
  Scene s;
  const Vec3 up(0, 0, 1), x(1, 0, 0);
  s.meshes.push_back(test::heightFieldMesh(test::sphericalBowl(Vec3(0), up, x, 0.1, 0.07), 32, 32, "bowl"));
  // A cylinder segment of 170 deg (its rim triangles nearly vertical) and a convex one.
  s.meshes.push_back(test::heightFieldMesh(
      test::cylinderSegment(Vec3(1, 0, 0), up, x, 0.05, 0.05 * std::sin(radians(85)), 0.1), 64, 8, "cylinder"));
  s.meshes.push_back(test::heightFieldMesh(test::cylinderSegment(Vec3(2, 0, 0), up, x, -0.3, 0.1, 0.1), 16, 16, "hill"));
  s.meshes.push_back(makeQuadMesh(Vec3(0, 1, 0), up, Vec3(0, 1, 0), 0.3, 0.2));  // planar: planarReceivers'
  s.meshes.back().name = "table";
  s.meshes.push_back(makeSphereMesh(Vec3(0, 2, 0), 0.1));
  s.meshes.back().name = "ball";
  s.meshes.push_back(makeBoxMesh(Vec3(0, 3, 0), Vec3(0.1), Mat3(1.0)));
  s.meshes.back().name = "box";
  // Two sheets of one mesh, one above the other: every triangle faces up, but the plane is covered twice.
  EnvMesh folded = test::heightFieldMesh(test::sphericalBowl(Vec3(0, 4, 0), up, x, 0.1, 0.05), 8, 8, "folded");
  const EnvMesh upper = test::heightFieldMesh(test::sphericalBowl(Vec3(0, 4, 0.02), up, x, 0.1, 0.05), 8, 8, "");
  const uint32_t base = uint32_t(folded.positions.size());
  for (size_t k = 0; k < upper.positions.size(); ++k) {
    folded.positions.push_back(upper.positions[k] + glm::vec3(0, 0, 0.02f));
    folded.normals.push_back(upper.normals[k]);
    folded.uvs.push_back(upper.uvs[k]);
  }
  for (const glm::u32vec3& t : upper.triangles) folded.triangles.push_back(t + glm::u32vec3(base));
  s.meshes.push_back(folded);
  const std::vector<CausticReceiver> r = heightFieldReceivers(s);
  std::vector<std::string> names;
  for (const CausticReceiver& c : r) {
    names.push_back(s.meshes[size_t(c.mesh)].name);
    EXPECT_TRUE(c.curved);
    EXPECT_NEAR(glm::dot(c.full.normal(), up), 1, 1e-9) << names.back();  // symmetric about their axes
  }
  EXPECT_EQ(names, (std::vector<std::string>{"bowl", "cylinder", "hill"}));
  // The bowl's rectangle: its 140 mm square, the plane through the middle of its heights.
  ASSERT_FALSE(r.empty());
  EXPECT_NEAR(std::max(r[0].full.width_m, r[0].full.height_m), 0.14, 1e-6);
  const double rim = 0.1 - std::sqrt(0.01 - 2 * 0.07 * 0.07);
  EXPECT_NEAR(r[0].full.centre.z, 0.5 * rim, 1e-6);
}

// The heights over a window's cells lie on the surface (within the facets' sagitta), and the reference's light
// field looks the irradiance up only on it: a plane mirror's beam (reflectance 0.9, the sun along -z turned to +x)
// on a bowl facing it gives 0.9 cos(theta) on the bowl and nothing 5 mm off it.
TEST(CausticMesh, CurvedReceiverHeightsAndLookup) {
  const test::HeightField bowl = test::sphericalBowl(Vec3(0.4, 0, 0), Vec3(-1, 0, 0), Vec3(0, 1, 0), 0.1, 0.07);
  Scene s;
  s.name = "beam-on-bowl";
  test::addBeamOnReceiver(s, bowl, 140, 140, "bowl");
  s.updateBounds();
  RayScene rays(s);
  FrameStages stages;
  const std::optional<CausticLightField> field = referenceCaustics(rays, CausticPlanOptions{}, 512, stages);
  ASSERT_TRUE(field);
  ASSERT_EQ(field->receivers.size(), 1u);
  const CausticReceiverMap& m = field->receivers[0];
  const ReceiverRect& w = m.grid.rect;
  ASSERT_EQ(m.height.size(), m.grid.irradiance.size());
  // Facets 1 mm wide (in the plane) on R = 0.1 m: the chord's sagitta (s / cos)^2 / 8R, twice across a diagonal;
  // float vertices.
  double worst = 0;
  int covered = 0;
  for (int j = 0; j < w.cells_v; ++j)
    for (int i = 0; i < w.cells_u; ++i) {
      const float h = m.height[m.grid.index(i, j)];
      if (h == kNoHeight) continue;
      ++covered;
      const Vec3 p = w.toWorld(w.cellCentre(i, j)) + double(h) * w.normal();
      const double cos = std::abs(glm::dot(glm::normalize(bowl.base + 0.1 * bowl.n - p), w.normal()));
      const double tol = 2 * std::pow(1e-3 / cos, 2) / (8 * 0.1) + 1e-6;
      worst = std::max(worst, std::abs(glm::length(p - (bowl.base + 0.1 * bowl.n)) - 0.1) / tol);
    }
  std::printf("[ caustic mesh ] bowl window %d x %d cells, %d with heights, off the sphere at most %.3f of the "
              "facets' sagitta\n", w.cells_u, w.cells_v, covered, worst);
  EXPECT_EQ(covered, w.cells_u * w.cells_v);  // the beam's window lies inside the bowl
  EXPECT_LE(worst, 1.0);
  // The lookup on the surface, averaged over a 20 mm square of it about (u, v) = (20, 10) mm of the bowl's own
  // frame (some 1600 cells: the photons' noise averages out), against the closed form's average; and 5 mm off it.
  double e = 0, expected = 0;
  for (int b = 0; b <= 20; ++b)
    for (int a = 0; a <= 20; ++a) {
      const double x = 0.01 + 0.001 * a, y = 0.001 * b;
      e += field->irradianceAt(bowl.point(x, y)).x;
      expected += 0.9 * std::abs(bowl.normal(x, y).x);
    }
  std::printf("[ caustic mesh ] lookup on the bowl %.5f W/m^2, closed form %.5f\n", e / 441, expected / 441);
  EXPECT_NEAR(e / expected, 1, 0.01);
  const Vec3 on = bowl.point(0.02, 0.01);
  EXPECT_EQ(field->irradianceAt(on + 0.005 * bowl.normal(0.02, 0.01)).x, 0.0);
}

}  // namespace
}  // namespace pvrr
