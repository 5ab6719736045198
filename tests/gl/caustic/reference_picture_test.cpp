// The reference picture with the caustic light (pvrr/trace/tracer.h TraceOptions::caustics,
// pvrr/method/caustic_mesh.h referenceCaustics): on the burning lens, its brightest table pixel lies at the focal
// spot, and the raster pvrr picture agrees with it inside the spot; with caustics off nothing changes.
// OSMesa and EGL. Figures: docs/caustics.md "In the reference picture".
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "pvrr/analysis/caustic_metrics.h"
#include "pvrr/base/image.h"
#include "pvrr/gl/context.h"
#include "pvrr/gl/renderer.h"
#include "pvrr/method/caustic_mesh.h"
#include "pvrr/scene/scene_build.h"
#include "pvrr/scene/scene_json.h"
#include "pvrr/trace/light_tracer.h"
#include "pvrr/trace/tracer.h"
#include "support/gl_backends.h"

namespace pvrr {
namespace {

class ReferenceCausticTest : public ::testing::TestWithParam<gl::GlBackend> {};

// The burning lens (models/burning-lens.json): f = 0.2532 m, the sun 10 deg off its axis (along +x), the table
// top at y = 0.7502 m.
constexpr double kFocal_m = 0.2532, kSunTilt_deg = 10, kTableY = 0.7502;
// The light tracer's peak against the closed form f tan 10 deg: coma pulls the brightest cell towards the axis
// (docs/caustics.md: 44.0 mm against 44.6 mm).
constexpr double kClosedFormTol_m = 2e-3;
// The spot region: table pixels whose caustic irradiance is at least the sun's own (1 W/m^2 facing it).
constexpr double kSpotIrradiance = 1.0;
// Inside it, the raster pvrr picture against the reference: mean sRGB code difference, and relative L1 of the
// linear colours.
constexpr double kCodeTol = 0.10, kLinearTol = 0.10;

TraceOptions traceOptions(const Scene& s) {
  TraceOptions to;
  to.max_depth = s.render.max_depth;
  to.dispersion = s.render.dispersion;
  to.spectral_samples = s.render.spectral_samples;
  return to;
}

CausticPlanOptions planOptions(const Scene& s) {
  CausticPlanOptions po;
  po.dispersion = s.render.dispersion;
  po.spectral_samples = s.render.spectral_samples;
  return po;
}

bool onTable(const Frame& f, size_t i) {
  const Vec3& p = f.seen[i];
  return f.element[i] < 0 && std::abs(p.y - kTableY) < 1e-4 && std::abs(p.x) < 0.6 && std::abs(p.z) < 0.4;
}

double luminance(const Vec3& c) { return (c.x + c.y + c.z) / 3; }

TEST_P(ReferenceCausticTest, BurningLensSpotInTheReferenceAndTheRasterPicture) {
  const auto ctx = test::glContextOrFail(GetParam());
  if (!ctx) return;
  const Scene s = buildScene(loadScene(PVRR_SOURCE_DIR "/models/burning-lens.json", {"observer.image_size=[160,120]"}));
  ASSERT_TRUE(s.lights[0].caustics);
  RayScene rays(s);
  FrameStages stages;
  const std::optional<CausticLightField> field =
      referenceCaustics(rays, planOptions(s), kReferenceCausticPhotons, stages);
  ASSERT_TRUE(field);
  const StageTiming* stage = stages.find(kReferenceCausticsStage);
  ASSERT_TRUE(stage && stage->ran);
  std::printf("[ refcaustic ] stage: %.0f ms, %s\n", stage->ms, stage->note.c_str());
  EXPECT_EQ(field->emitted, 3LL * kReferenceCausticPhotons * kReferenceCausticPhotons);  // rgb: 3 samples
  ASSERT_EQ(field->receivers.size(), 1u);
  EXPECT_EQ(s.meshes[size_t(field->receivers[0].mesh)].name, "table-top");
  const SpotMetrics spot = spotMetrics(field->receivers[0].grid);
  ASSERT_TRUE(spot.found);
  const double closed_form_x = kFocal_m * std::tan(kSunTilt_deg * kPi / 180);
  std::printf("[ refcaustic ] light tracer's peak %.1f W/m^2 at x = %.2f mm, z = %.2f mm (f tan 10 deg = %.2f mm)\n",
              spot.peak_irradiance, 1e3 * spot.peak_world.x, 1e3 * spot.peak_world.z, 1e3 * closed_form_x);
  EXPECT_NEAR(spot.peak_world.x, closed_form_x, kClosedFormTol_m);
  EXPECT_NEAR(spot.peak_world.z, 0.0, kClosedFormTol_m);

  TraceOptions to = traceOptions(s);
  to.caustics = &*field;
  const Frame ref = Tracer(rays, to).render();
  gl::Renderer renderer(s, rays, gl::rendererOptionsFor(s));
  const gl::RasterFrame raster = renderer.render(RenderMode::Pvrr);
  ASSERT_EQ(raster.color.size(), ref.color.size());

  // The brightest table pixel of the reference lies at the spot, within a pixel's footprint on the table.
  size_t best = 0;
  double best_l = -1;
  for (size_t i = 0; i < ref.color.size(); ++i)
    if (onTable(ref, i) && luminance(ref.color[i]) > best_l) best_l = luminance(ref.color[i]), best = i;
  ASSERT_GE(best_l, 0);
  const size_t w = size_t(ref.width);
  const double footprint = glm::length(ref.seen[best + 1] - ref.seen[best]);
  const double off = glm::length(ref.seen[best] - spot.peak_world);
  std::printf("[ refcaustic ] brightest table pixel (%zu, %zu): %.3g linear, %.2f mm from the peak (pixel %.2f mm)\n",
              best % w, best / w, best_l, 1e3 * off, 1e3 * footprint);
  EXPECT_LE(off, footprint);

  // The spot region: raster against reference.
  const auto spotDifference = [&](const Frame& r, double& code_diff, double& lin_l1) {
    int n = 0;
    double lin_diff = 0, lin_ref = 0;
    code_diff = 0;
    for (size_t i = 0; i < r.color.size(); ++i) {
      if (!onTable(ref, i) || luminance(field->irradianceAt(ref.seen[i])) < kSpotIrradiance) continue;
      ++n;
      for (int c = 0; c < 3; ++c) {
        code_diff += std::abs(int(linearToSrgb8(raster.color[i][c])) - int(linearToSrgb8(r.color[i][c]))) / 255.0;
        lin_diff += std::abs(raster.color[i][c] - r.color[i][c]);
        lin_ref += r.color[i][c];
      }
    }
    code_diff /= 3.0 * std::max(n, 1);
    lin_l1 = lin_diff / lin_ref;
    return n;
  };
  double code_diff = 0, lin_l1 = 0;
  const int n = spotDifference(ref, code_diff, lin_l1);
  ASSERT_GT(n, 0);
  std::printf("[ refcaustic ] spot region %d pixels: mean code difference %.2f %%, linear relative L1 %.2f %%\n", n,
              100 * code_diff, 100 * lin_l1);
  EXPECT_LE(code_diff, kCodeTol);
  EXPECT_LE(lin_l1, kLinearTol);
  // The measure tells them apart: the reference as it was (no caustic, the sun through the lens by Fresnel)
  // is far off the raster picture there.
  const Frame before = Tracer(rays, traceOptions(s)).render();
  double before_code = 0, before_l1 = 0;
  spotDifference(before, before_code, before_l1);
  std::printf("[ refcaustic ] without the caustic: mean code difference %.2f %%, linear relative L1 %.2f %%\n",
              100 * before_code, 100 * before_l1);
  EXPECT_GT(before_code, kCodeTol);
  EXPECT_GT(before_l1, kLinearTol);
}

// Caustics off: no stage work, no field, and a tracer given a field of zeros (its light without caustics is not
// blocked by the lens, nothing is added) draws the very bytes of one given none.
TEST(ReferenceCaustics, OffLeavesTheReferenceByteIdentical) {
  const Scene on = buildScene(loadScene(PVRR_SOURCE_DIR "/models/burning-lens.json", {"observer.image_size=[80,60]"}));
  const Scene s = buildScene(loadScene(PVRR_SOURCE_DIR "/models/burning-lens.json",
                                       {"lights[0].caustics=false", "observer.image_size=[80,60]"}));
  RayScene rays_on(on), rays(s);
  FrameStages stages;
  EXPECT_FALSE(referenceCaustics(rays, planOptions(s), 8, stages));
  const StageTiming* stage = stages.find(kReferenceCausticsStage);
  ASSERT_TRUE(stage);
  EXPECT_FALSE(stage->ran);
  // The caustics-on scene's windows, zeroed.
  std::optional<CausticLightField> zeros = referenceCaustics(rays_on, planOptions(on), 8, stages);
  ASSERT_TRUE(zeros && !zeros->receivers.empty());
  for (CausticReceiverMap& m : zeros->receivers) m.grid = IrradianceGrid::zeros(m.grid.rect);
  const Frame plain = Tracer(rays, traceOptions(s)).render();
  TraceOptions to = traceOptions(s);
  to.caustics = &*zeros;
  const Frame with = Tracer(rays, to).render();
  EXPECT_EQ(srgbPicture(with).rgb, srgbPicture(plain).rgb);
  EXPECT_EQ(with.color, plain.color);
}

PVRR_GL_BACKENDS(ReferenceCausticTest);

}  // namespace
}  // namespace pvrr
