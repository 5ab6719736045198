// Raster shadow maps (pvrr/gl/shadow_pass.h) against the reference's shadow rays (pvrr/trace/shadow_rays.h):
// on the ground of closed-form shadow scenes (tests/support/shadow_scenes.h), each receiver pixel is in
// shadow or lit in both, but in a band around the reference's shadow edges (the raster filter's penumbra and
// the pixel grid's rounding of the outline); and so is the ground seen in a mirror in pvrr mode, whose first
// pass reads the same maps. OSMesa and EGL.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include "pvrr/gl/context.h"
#include "pvrr/gl/renderer.h"
#include "pvrr/gl/shadow_pass.h"
#include "pvrr/trace/shadow_rays.h"
#include "pvrr/trace/tracer.h"
#include "support/gl_backends.h"
#include "support/shadow_scenes.h"

namespace pvrr {
namespace {

class ShadowTest : public ::testing::TestWithParam<gl::GlBackend> {};

// The issue's bound: at least 99 % of receiver pixels away from penumbra edges agree.
constexpr double kMinAgreement = 0.99;
// The band around the reference's shadow edges left out, in pixels: the raster penumbra is 4 map texels
// wide (PCF 3 x 3 of bilinear taps) plus the normal offset's 1.5 texels, a few millimetres, under a pixel of
// these pictures (about 2 cm on the ground); two pixels more cover the rounding of the outline to the grid.
constexpr int kEdgeBand = 3;
// The ground's albedo and the ambient light of the shadow scenes; the mirror's reflectance.
constexpr double kGroundAlbedo = 0.7, kAmbient = 0.2, kMirrorReflectance = 0.9;

struct Agreement {
  int receivers = 0, banded = 0, agree = 0, shadowed = 0;
  double fraction() const { return receivers ? double(agree) / receivers : 0; }
};

// Each pixel whose reference path ends on the ground (y = 0) after `bounces` reflections: in shadow per the
// reference (shadow ray transmittance below 1/2) and per the raster picture (its light's term, recovered from
// the colour, below half the unshadowed term).
Agreement agreement(const Scene& s, const RayScene& rays, const Frame& ref, const gl::RasterFrame& raster, int bounces,
                    double reflectance, int band = kEdgeBand) {
  const int w = ref.width, h = ref.height;
  const Light& light = s.lights[0];
  const ShadowRays shadow_rays(rays);
  std::vector<int> state(size_t(w) * size_t(h), -1), raster_state(state.size(), -1);
  for (size_t i = 0; i < state.size(); ++i) {
    if (std::abs(ref.seen[i].y) > 1e-9 || ref.bounces[i] != bounces) continue;
    if (bounces == 0 && ref.element[i] >= 0) continue;
    const Vec3 p = ref.seen[i];
    double direct;
    if (light.type == Light::Type::Directional) {
      direct = -light.direction.y;
    } else {
      const Vec3 to = light.position - p;
      direct = to.y / glm::length(to) / glm::dot(to, to);
    }
    if (!(direct > 0.05)) continue;  // a term too faint to tell lit from shadowed
    state[i] = shadow_rays.transmittance(light, p).x < 0.5;
    const double term = (raster.color[i].x / (reflectance * kGroundAlbedo) - kAmbient) / direct;
    raster_state[i] = term < 0.5;
  }
  Agreement a;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const size_t i = size_t(y) * size_t(w) + size_t(x);
      if (state[i] < 0) continue;
      bool near_edge = false;
      for (int dy = -band; dy <= band && !near_edge; ++dy)
        for (int dx = -band; dx <= band && !near_edge; ++dx) {
          const int xx = x + dx, yy = y + dy;
          if (xx < 0 || yy < 0 || xx >= w || yy >= h) continue;
          const int o = state[size_t(yy) * size_t(w) + size_t(xx)];
          near_edge = o >= 0 && o != state[i];
        }
      if (near_edge) {
        ++a.banded;
        continue;
      }
      ++a.receivers;
      a.shadowed += state[i];
      a.agree += state[i] == raster_state[i];
    }
  return a;
}

std::string lightJson(const char* type, const Vec3& v) {
  char buf[200];
  std::snprintf(buf, sizeof buf, R"({"type": "%s", "%s": [%.6f, %.6f, %.6f]})", type,
                std::string(type) == "point" ? "position" : "direction", v.x, v.y, v.z);
  return buf;
}

TEST_P(ShadowTest, RasterShadowsAgreeWithTheReferencesShadowRays) {
  const auto ctx = test::glContextOrFail(GetParam());
  if (!ctx) return;
  struct Case {
    const char* occluder;
    std::string light;
  };
  const Case cases[] = {{"sphere", lightJson("directional", Vec3(0.5, -1, 0.2))},
                        {"sphere", lightJson("directional", Vec3(-0.7, -1, -0.4))},
                        {"quad", lightJson("point", Vec3(0.3, 2.5, -0.2))},
                        {"sphere", lightJson("point", Vec3(-0.4, 1.4, 0.3))}};
  for (const Case& c : cases) {
    const Scene s = test::shadowScene(c.occluder, c.light, "", 320, 240);
    RayScene rays(s);
    const Frame ref = Tracer(rays, TraceOptions{}).render();
    gl::Renderer renderer(s, rays, gl::RendererOptions{});
    const gl::RasterFrame raster = renderer.render(RenderMode::Raster);
    const Agreement a = agreement(s, rays, ref, raster, 0, 1.0);
    std::printf("[ shadows ] %s %s: %d of %d receiver pixels agree (%.4f), %d in shadow, %d in the edge band\n",
                c.occluder, c.light.c_str(), a.agree, a.receivers, a.fraction(), a.shadowed, a.banded);
    // Measured, not asserted: how far the disagreement reaches from the reference's edges (docs/accuracy.md).
    for (int band : {0, 1, 2}) {
      const Agreement b = agreement(s, rays, ref, raster, 0, 1.0, band);
      std::printf("[ shadows ]   band %d px: %d of %d agree (%.4f)\n", band, b.agree, b.receivers, b.fraction());
    }
    EXPECT_GT(a.shadowed, 200) << c.light;  // the shadow is in the picture (~350 pixels and more)
    EXPECT_GE(a.fraction(), kMinAgreement) << c.occluder << " " << c.light;
    const StageTiming* stage = raster.stages.find(gl::kShadowMapsStage);
    ASSERT_TRUE(stage);
    EXPECT_TRUE(stage->ran);
    // The next frame reuses the maps: nothing moved.
    const gl::RasterFrame again = renderer.render(RenderMode::Raster);
    const StageTiming* reused = again.stages.find(gl::kShadowMapsStage);
    ASSERT_TRUE(reused);
    EXPECT_NE(reused->note.find("reused"), std::string::npos) << reused->note;
    EXPECT_EQ(again.color, raster.color);
  }
}

// A shadow seen in a plane mirror, in pvrr mode (its first pass draws the environment with the maps) and in
// envmap mode (its cube's faces do).
TEST_P(ShadowTest, AShadowSeenInAMirrorAgreesWithTheReference) {
  const auto ctx = test::glContextOrFail(GetParam());
  if (!ctx) return;
  // The mirror at m turns the ray from the eye into one towards the sphere's shadow on the ground (centred at
  // (0.35, 0, 0) under this light), which it sees from beyond, the sphere behind the shadow.
  const Vec3 eye(0, 3.2, 1.6), m(1.1, 0.5, 0.6), shadow_centre(0.35, 0, 0);
  const Vec3 n = glm::normalize(glm::normalize(eye - m) + glm::normalize(shadow_centre - m));
  char mirror[600];
  std::snprintf(
      mirror, sizeof mirror,
      R"({"name": "m", "type": "mirror", "pose": {"position": [%.6f, %.6f, %.6f], "normal": [%.6f, %.6f, %.6f],
                "up": [0, 1, 0]}, "outline": {"shape": "rectangle", "width": 0.8, "height": 0.8},
                "surface": {"type": "plane"}, "tessellation": 7, "material": {"reflectance": 0.9}})",
      m.x, m.y, m.z, n.x, n.y, n.z);
  const Scene s = test::shadowScene("sphere", lightJson("directional", Vec3(0.5, -1, 0.2)), mirror, 320, 240);
  RayScene rays(s);
  const Frame ref = Tracer(rays, TraceOptions{}).render();
  gl::Renderer renderer(s, rays, gl::RendererOptions{});
  for (RenderMode mode : {RenderMode::Pvrr, RenderMode::Envmap}) {
    const gl::RasterFrame raster = renderer.render(mode);
    const Agreement a = agreement(s, rays, ref, raster, 1, kMirrorReflectance);
    std::printf("[ shadows ] in the mirror, mode %d: %d of %d receiver pixels agree (%.4f), %d in shadow, %d banded\n",
                int(mode), a.agree, a.receivers, a.fraction(), a.shadowed, a.banded);
    EXPECT_GT(a.shadowed, 50);  // ~100: without the shadow, agreement would fall below the bound
    // envmap mode's cube is centred on the mirror, not at the viewpoint: its picture of the ground is
    // displaced (the baseline's known error), so only pvrr mode is held to the bound.
    if (mode == RenderMode::Pvrr) {
      EXPECT_GE(a.fraction(), kMinAgreement);
    }
  }
}

// A lens over the ground passes (1 - R0)^2 of the light in both: the raster light term under it (away from
// its shadow's edge) equals the reference's transmittance to R16F rounding and float shading.
TEST_P(ShadowTest, ALensTransmitsItsFresnelShareInBoth) {
  const auto ctx = test::glContextOrFail(GetParam());
  if (!ctx) return;
  constexpr double kTermTol = 2e-3;  // R16F holds 0.92 to 5e-4; colours are float
  const std::string lens = R"({"name": "l", "type": "lens", "pose": {"position": [-0.7, 1.5, 0.6],
      "normal": [0, 1, 0], "up": [0, 0, -1]}, "outline": {"shape": "circle", "diameter": 0.4},
      "front": {"type": "sphere", "radius": 2.0}, "back": {"type": "sphere", "radius": -2.0},
      "centre_thickness": 0.03, "material": {"n_d": 1.5, "V_d": 60, "dispersion": false}})";
  const Scene s = test::shadowScene("quad", R"({"type": "directional", "direction": [0, -1, 0]})", lens, 320, 240);
  RayScene rays(s);
  const Frame ref = Tracer(rays, TraceOptions{}).render();
  gl::Renderer renderer(s, rays, gl::RendererOptions{});
  const gl::RasterFrame raster = renderer.render(RenderMode::Raster);
  const ShadowRays shadow_rays(rays);
  const double t_lens = lensShadowTransmittance(s.elements[0]);
  int under = 0;
  double worst = 0;
  for (size_t i = 0; i < ref.seen.size(); ++i) {
    const Vec3 p = ref.seen[i];
    if (std::abs(p.y) > 1e-9 || ref.element[i] >= 0) continue;
    // Well inside the lens's shadow (its disc of r = 0.2 m under a vertical light), 2 cm from the edge.
    if (glm::length(Vec3(p.x + 0.7, 0, p.z - 0.6)) > 0.18) continue;
    ++under;
    EXPECT_NEAR(shadow_rays.transmittance(s.lights[0], p).x, t_lens, 1e-12);
    const double term = raster.color[i].x / kGroundAlbedo - kAmbient;  // the light's term, cos = 1
    worst = std::max(worst, std::abs(term - t_lens));
  }
  std::printf("[ shadows ] under the lens: %d pixels, raster term within %.2e of (1 - R0)^2 = %.6f\n", under, worst,
              t_lens);
  EXPECT_GT(under, 100);
  EXPECT_LE(worst, kTermTol);
}

// Shadows off in the scene: the stage is skipped with its reason and the picture is the unshadowed one.
TEST_P(ShadowTest, ShadowsOffSkipTheStage) {
  const auto ctx = test::glContextOrFail(GetParam());
  if (!ctx) return;
  const Scene s = test::shadowScene("sphere", R"({"type": "directional", "direction": [0, -1, 0], "shadows": false})");
  RayScene rays(s);
  gl::Renderer renderer(s, rays, gl::RendererOptions{});
  const gl::RasterFrame f = renderer.render(RenderMode::Raster);
  const StageTiming* stage = f.stages.find(gl::kShadowMapsStage);
  ASSERT_TRUE(stage);
  EXPECT_FALSE(stage->ran);
  EXPECT_NE(stage->reason.find("no light casts shadows"), std::string::npos);
  // The ground under the sphere is lit in full, as in the reference.
  const Frame ref = Tracer(rays, TraceOptions{}).render();
  const Agreement a = agreement(s, rays, ref, f, 0, 1.0);
  EXPECT_EQ(a.shadowed, 0);
  EXPECT_GT(a.receivers, 5000);
  EXPECT_GE(a.fraction(), kMinAgreement);
}

PVRR_GL_BACKENDS(ShadowTest);

}  // namespace
}  // namespace pvrr
