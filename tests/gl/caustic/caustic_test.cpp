// Raster caustics (pvrr/gl/caustic_pass.h, pvrr/method/caustic_mesh.h) against the reference's light tracer
// (pvrr/trace/light_tracer.h) on the same receiver cells (pvrr/analysis/caustic_metrics.h): the burning lens's
// spot and a concave mirror's focus at R/2. OSMesa and EGL. Figures: docs/caustics.md "Raster caustics".
#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include "cad/lens.h"
#include "pvrr/analysis/caustic_metrics.h"
#include "pvrr/gl/context.h"
#include "pvrr/gl/renderer.h"
#include "pvrr/scene/scene_build.h"
#include "pvrr/scene/scene_json.h"
#include "pvrr/trace/light_tracer.h"
#include "support/gl_backends.h"
#include "support/test_scenes.h"

namespace pvrr {
namespace {

class CausticTest : public ::testing::TestWithParam<gl::GlBackend> {};

// The bounds: the raster peak within 1 mm of the reference's at the burning-lens scale, and the
// irradiance inside the reference's spot (cells at or above half its peak) within 10 % relative L1.
constexpr double kPeakTol_m = 1e-3, kSpotL1Tol = 0.10;
// The reference's photons per side (its default: within 0.1 % of the 1024^2 map inside the spot,
// docs/caustics.md "Convergence").
constexpr int kReferencePhotons = 512;

// The reference's map on the raster map's own cells, from photons landing on the same mesh.
IrradianceGrid referenceOn(const RayScene& rays, const gl::CausticMap& map) {
  CausticOptions o;
  o.photons_per_side = kReferencePhotons;
  o.dispersion = rays.scene().render.dispersion;
  o.spectral_samples = rays.scene().render.spectral_samples;
  const PhotonBundle b = shootCausticPhotons(rays, o);
  DepositOptions d;
  d.mesh = map.mesh;
  return depositPhotons(b, map.grid.rect, d).grid;
}

const gl::CausticMap* mapOf(const std::vector<gl::CausticMap>& maps, const Scene& s, const std::string& mesh) {
  for (const gl::CausticMap& m : maps)
    if (s.meshes[size_t(m.mesh)].name == mesh) return &m;
  return nullptr;
}

void print(const char* what, const IrradianceComparison& c) {
  std::printf(
      "[ caustic ] %s: peak %.4g W/m^2 (reference %.4g), peaks %.4f mm apart, centroids %.4f mm, "
      "relative L1 in the spot %.4f (%d cells), power ratio %.4f\n",
      what, c.test.peak_irradiance, c.reference.peak_irradiance, 1e3 * c.peak_distance_m, 1e3 * c.centroid_distance_m,
      c.relative_l1_in_spot, c.reference.spot_cells, c.power_ratio);
}

TEST_P(CausticTest, BurningLensSpotMatchesTheReference) {
  const auto ctx = test::glContextOrFail(GetParam());
  if (!ctx) return;
  const Scene s = buildScene(loadScene(PVRR_SOURCE_DIR "/models/burning-lens.json",
                                       {"lights[0].caustics=true", "observer.image_size=[160,120]"}));
  RayScene rays(s);
  gl::Renderer renderer(s, rays, gl::rendererOptionsFor(s));
  const gl::RasterFrame frame = renderer.render(RenderMode::Raster);
  const StageTiming* stage = frame.stages.find(gl::kCausticMapsStage);
  ASSERT_TRUE(stage);
  EXPECT_TRUE(stage->ran) << stage->reason;
  std::printf("[ caustic ] stage: %.1f ms, %s\n", stage->ms, stage->note.c_str());
  const std::vector<gl::CausticMap> maps = renderer.causticMaps();
  const gl::CausticMap* table = mapOf(maps, s, "table-top");
  ASSERT_TRUE(table);
  const IrradianceComparison c = compareIrradiance(table->grid, referenceOn(rays, *table));
  print("burning lens", c);
  EXPECT_LE(c.peak_distance_m, kPeakTol_m);
  EXPECT_LE(c.relative_l1_in_spot, kSpotL1Tol);
  // The next frame reuses the maps: nothing moved.
  const gl::RasterFrame again = renderer.render(RenderMode::Raster);
  const StageTiming* reused = again.stages.find(gl::kCausticMapsStage);
  ASSERT_TRUE(reused);
  EXPECT_NE(reused->note.find("reused"), std::string::npos) << reused->note;
  EXPECT_EQ(again.color, frame.color);
}

// A concave mirror (R = 1 m, 100 mm round, reflectance 0.9) facing the sun along its axis, a 20 mm square
// receiver facing it at distance z (it shades the mirror's centre: the spot comes from the annulus around).
Scene mirrorScene(double z) {
  constexpr double kMirrorR = 1.0, kMirrorD = 0.1, kReflectance = 0.9, kScreen = 0.02;
  Scene s;
  s.name = "caustic-mirror";
  s.observer.eye = Vec3(0.3, 0.2, 0.8);
  s.observer.target = Vec3(0, 0, 0.25);
  s.observer.width = 80;
  s.observer.height = 60;
  s.meshes.push_back(makeQuadMesh(Vec3(0, 0, z), Vec3(0, 0, -1), Vec3(0, 1, 0), kScreen, kScreen));
  s.meshes.back().name = "screen";
  s.materials.push_back(DiffuseMaterial{});
  Light sun;
  sun.type = Light::Type::Directional;
  sun.direction = Vec3(0, 0, -1);
  sun.radiance = Vec3(1.0);
  sun.caustics = true;
  s.lights = {sun};
  const cad::Outline disc = cad::Outline::circle(kMirrorD);
  test::addMirror(s, cad::makeSphere(-kMirrorR, disc), disc, test::pose(Vec3(0), Vec3(0, 0, 1)), 7, kReflectance);
  s.updateBounds();
  return s;
}

TEST_P(CausticTest, ConcaveMirrorFocusesAtHalfItsRadius) {
  const auto ctx = test::glContextOrFail(GetParam());
  if (!ctx) return;
  // Receiver planes 1 mm apart about R/2; the brightest raster peak must lie within the depth of focus the
  // reference's own test allows (+-1.13 mm with 0.1 mm cells, docs/caustics.md), rounded up to the sweep step.
  constexpr double kHalfR = 0.5, kStep_m = 1e-3, kFocusTol_m = 1.5e-3;
  double best_z = 0, best_peak = 0;
  for (int k = -3; k <= 3; ++k) {
    const double z = kHalfR + k * kStep_m;
    const Scene s = mirrorScene(z);
    RayScene rays(s);
    gl::Renderer renderer(s, rays, gl::RendererOptions{});
    renderer.render(RenderMode::Raster);
    const std::vector<gl::CausticMap> maps = renderer.causticMaps();
    const gl::CausticMap* screen = mapOf(maps, s, "screen");
    ASSERT_TRUE(screen) << z;
    const IrradianceComparison c = compareIrradiance(screen->grid, referenceOn(rays, *screen));
    char what[64];
    std::snprintf(what, sizeof what, "mirror, screen at %.4f m", z);
    print(what, c);
    if (k == 0) {  // at R/2 itself, the raster map against the reference's
      EXPECT_LE(c.peak_distance_m, kPeakTol_m);
      EXPECT_LE(c.relative_l1_in_spot, kSpotL1Tol);
    }
    if (c.test.peak_irradiance > best_peak) best_peak = c.test.peak_irradiance, best_z = z;
  }
  std::printf("[ caustic ] mirror: brightest raster spot at %.4f m (R/2 = %.4f m)\n", best_z, kHalfR);
  EXPECT_NEAR(best_z, kHalfR, kFocusTol_m);
}

// Something between the element and the receiver that is not itself a receiver (a box: not planar, so it gets no
// light map) keeps the light off the receiver: the mirror's focus with a 20 x 20 x 10 mm box on the axis at
// 0.3 m. The box lies in the screen's own shadow, so it blocks no sunlight on its way in; on the way out it stops
// the light of the mirror's inner 50 mm square (about 28 % of what reaches the screen). The splat lands a photon
// only on the mesh its exit ray meets first, as the reference deposits it, so the two maps agree; landing it on the
// nearest receiver plane instead, as before, put the blocked light on the screen too.
TEST_P(CausticTest, AnOccluderBetweenElementAndReceiverKeepsItsShadow) {
  const auto ctx = test::glContextOrFail(GetParam());
  if (!ctx) return;
  Scene s = mirrorScene(0.5);
  s.meshes.push_back(makeBoxMesh(Vec3(0, 0, 0.3), Vec3(0.02, 0.02, 0.01), Mat3(1.0)));
  s.meshes.back().name = "box";
  s.updateBounds();
  RayScene rays(s);
  gl::Renderer renderer(s, rays, gl::RendererOptions{});
  const gl::RasterFrame frame = renderer.render(RenderMode::Raster);
  const StageTiming* stage = frame.stages.find(gl::kCausticMapsStage);
  ASSERT_TRUE(stage);
  std::printf("[ caustic ] stage: %s\n", stage->note.c_str());
  const std::vector<gl::CausticMap> maps = renderer.causticMaps();
  const gl::CausticMap* screen = mapOf(maps, s, "screen");
  ASSERT_TRUE(screen);
  EXPECT_FALSE(mapOf(maps, s, "box"));  // not planar: no map of its own
  const IrradianceComparison c = compareIrradiance(screen->grid, referenceOn(rays, *screen));
  print("mirror, the inner cone behind a box", c);
  EXPECT_LE(c.peak_distance_m, kPeakTol_m);
  EXPECT_LE(c.relative_l1_in_spot, kSpotL1Tol);
  EXPECT_NEAR(c.power_ratio, 1, 0.02);
  // The box blocks light: the reference's power on the screen is well below the open mirror's (72 % of it).
  const Scene open = mirrorScene(0.5);
  RayScene open_rays(open);
  const double open_power = referenceOn(open_rays, *screen).power().x;
  const double boxed_power = referenceOn(rays, *screen).power().x;
  std::printf("[ caustic ] reference power on the screen: %.4g W open, %.4g W behind the box\n", open_power,
              boxed_power);
  EXPECT_LT(boxed_power, 0.8 * open_power);
}

// Off unless a light turns it on: no stage work and no caustic defines (so no existing pixel changes).
TEST_P(CausticTest, OffUnlessALightTurnsItOn) {
  const auto ctx = test::glContextOrFail(GetParam());
  if (!ctx) return;
  const Scene s = buildScene(loadScene(PVRR_SOURCE_DIR "/models/burning-lens.json",
                                       {"lights[0].caustics=false", "observer.image_size=[80,60]"}));
  EXPECT_TRUE(gl::causticDefines(s).empty());
  RayScene rays(s);
  gl::Renderer renderer(s, rays, gl::rendererOptionsFor(s));
  const gl::RasterFrame frame = renderer.render(RenderMode::Raster);
  const StageTiming* stage = frame.stages.find(gl::kCausticMapsStage);
  ASSERT_TRUE(stage);
  EXPECT_FALSE(stage->ran);
  EXPECT_NE(stage->reason.find("caustics"), std::string::npos) << stage->reason;
  EXPECT_TRUE(renderer.causticMaps().empty());
}

PVRR_GL_BACKENDS(CausticTest);

}  // namespace
}  // namespace pvrr
