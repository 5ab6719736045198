// RendererOptions::seen_points off (pvrr render: the picture only): every mode draws the same colours as with
// the seen-point attachments on, to the 16-bit target's rounding (clamped to [0, 1]), so that the 8-bit
// pictures differ by at most one code; it leaves the seen points out, and says so in its stages. OSMesa and
// EGL.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include <glm/gtc/matrix_transform.hpp>

#include "pvrr/gl/context.h"
#include "pvrr/gl/renderer.h"
#include "pvrr/base/image.h"
#include "pvrr/scene/scene_build.h"
#include "pvrr/scene/scene_json.h"
#include "pvrr/optics/spectrum.h"
#include "support/gl_backends.h"
#include "support/test_scenes.h"

namespace pvrr {
namespace {

// The same shaders and inputs, minus outputs that are not written: the colours should agree to float
// rounding; 1e-6 in linear units is far below one 8-bit step (~4e-3).
constexpr double kColourTol = 1e-6;
// The picture-only target (GL_RGBA16) rounds each clamped channel to the nearest 1/65535.
constexpr double kUnorm16Tol = 0.5 / 65535 + kColourTol;

class ColourOnlyTest : public ::testing::TestWithParam<gl::GlBackend> {};

TEST_P(ColourOnlyTest, SameColoursWithoutSeenPoints) {
  const auto ctx = test::glContextOrFail(GetParam());
  if (!ctx) return;
  // The spectral reading lens (16 samples) is drawn in six additive draws whose partial sums are negative or
  // above 1 in places: its picture-only frame keeps the float target.
  for (const std::string scene : {"car-mirror", "reading-lens", "mirror-pair", "reading-lens spectral"}) {
    const bool spectral = scene == "reading-lens spectral";
    std::vector<std::string> sets = {"observer.image_size=[96,72]", "render.map_size=256"};
    if (spectral) sets.push_back("render.dispersion=\"spectral\"");
    Scene s = buildScene(loadScene(std::string(PVRR_SOURCE_DIR) + "/models/" + (spectral ? "reading-lens" : scene) + ".json",
                                   sets));
    RayScene rays(s);
    gl::RendererOptions with, without;
    with.vertex.channels.clear();
    without.vertex.channels.clear();
    without.seen_points = false;
    gl::Renderer a(s, rays, with), b(s, rays, without);
    // Impostor: its cube maps keep their seen points (the distances it searches) in the colour-only frame;
    // envmap after it recreates them without (the same renderer switching modes).
    for (RenderMode mode :
         {RenderMode::Pvrr, RenderMode::Impostor, RenderMode::Envmap, RenderMode::Raster}) {
      const gl::RasterFrame fa = a.render(mode), fb = b.render(mode);
      ASSERT_EQ(fa.color.size(), fb.color.size()) << scene;
      EXPECT_EQ(fa.seen.size(), fa.color.size());
      EXPECT_TRUE(fb.seen.empty() && fb.element.empty() && fb.element_point.empty()) << scene;
      double worst = 0;
      int worst_code = 0;
      size_t codes_differ = 0;
      for (size_t i = 0; i < fa.color.size(); ++i)
        for (int c = 0; c < 3; ++c) {
          // The float target (spectral, pvrr mode) keeps the colours as they are; the 16-bit one clamps them.
          const bool float_target = spectral && mode == RenderMode::Pvrr;
          const double expected = float_target ? fa.color[i][c] : std::clamp(fa.color[i][c], 0.0, 1.0);
          worst = std::max(worst, std::abs(expected - fb.color[i][c]));
          const int code = std::abs(int(linearToSrgb8(fa.color[i][c])) - int(linearToSrgb8(fb.color[i][c])));
          worst_code = std::max(worst_code, code);
          codes_differ += code != 0;
        }
      EXPECT_LE(worst, spectral && mode == RenderMode::Pvrr ? kColourTol : kUnorm16Tol) << scene << " mode " << int(mode);
      EXPECT_LE(worst_code, 1) << scene << " mode " << int(mode);
      EXPECT_LE(codes_differ, fa.color.size() * 3 / 100) << scene << " mode " << int(mode);
      const StageTiming* on = fa.stages.find("seen-points");
      const StageTiming* off = fb.stages.find("seen-points");
      ASSERT_TRUE(on && off) << scene;
      EXPECT_TRUE(on->ran);
      EXPECT_FALSE(off->ran);
      EXPECT_NE(off->reason.find("not requested"), std::string::npos) << off->reason;
    }
  }
}

// The first frame of a fresh renderer in each mode (no earlier pass has set any GL state) shows the
// elements where a later frame does: the same element pixels, the same colours.
TEST_P(ColourOnlyTest, FirstFrameOfEachModeEqualsALaterOne) {
  // The reading lens in impostor mode: its first frame also builds the lens's height maps.
  const std::vector<std::pair<std::string, RenderMode>> cases = {
      {"car-mirror", RenderMode::Raster},   {"car-mirror", RenderMode::Envmap},
      {"car-mirror", RenderMode::Impostor}, {"car-mirror", RenderMode::Pvrr},
      {"reading-lens", RenderMode::Impostor}};
  for (const auto& [scene, mode] : cases) {
    Scene s = buildScene(loadScene(std::string(PVRR_SOURCE_DIR) + "/models/" + scene + ".json",
                                   {"observer.image_size=[96,72]", "render.map_size=256"}));
    RayScene rays(s);
    // A fresh context per mode: GL state belongs to the context, so no earlier renderer's frames set it.
    const auto ctx = test::glContextOrFail(GetParam());
    if (!ctx) return;
    gl::Renderer r(s, rays, gl::RendererOptions{});
    const gl::RasterFrame first = r.render(mode), second = r.render(mode);
    size_t element_pixels = 0, same = 0;
    double worst = 0;
    for (size_t i = 0; i < first.color.size(); ++i) {
      element_pixels += second.element[i] >= 0;
      same += first.element[i] == second.element[i];
      worst = std::max(worst, glm::length(first.color[i] - second.color[i]));
    }
    EXPECT_GT(element_pixels, 200u) << scene << " mode " << int(mode);
    EXPECT_EQ(same, first.color.size()) << scene << " mode " << int(mode);
    EXPECT_LE(worst, kColourTol) << scene << " mode " << int(mode);
  }
}

// No pass clears its colour attachments (the sky covers every pixel nothing else does, and a map renders
// only the region its volume needs): a renderer that has drawn another view first must give exactly the
// picture, seen points and element ids of a fresh renderer. A pixel or texel left unwritten would keep the
// other view's value. The other view is at 8 times the image size, so its maps fill larger regions of their
// textures: a texture read outside the current region (a wrong scale or clamp) would see them. The concave
// mirror's zooming region takes the reversed-depth map path.
TEST_P(ColourOnlyTest, EveryPixelIsDrawnWithoutAColourClear) {
  const auto ctx = test::glContextOrFail(GetParam());
  if (!ctx) return;
  for (const char* scene : {"car-mirror", "concave-mirror", "spectacle-lens"}) {
    Scene s = buildScene(loadScene(std::string(PVRR_SOURCE_DIR) + "/models/" + scene + ".json",
                                   {"observer.image_size=[96,72]", "render.map_size=256"}));
    RayScene rays(s);
    for (RenderMode mode : {RenderMode::Pvrr, RenderMode::Raster}) {
      for (const bool seen_points : {true, false}) {  // the float target, and the picture-only 16-bit one
        // In raster mode the spectacle lens is a uniform grey filling the view from any direction: nothing to see.
        if (mode == RenderMode::Raster && std::string(scene) == "spectacle-lens") continue;
        gl::RendererOptions o;
        o.seen_points = seen_points;
        // No adaptive refinement: the grid cache keeps what one view refined (the 8 x larger, turned view splits
        // the spectacle lens where its map errs, pvrr/method/local_split.h), so the view coming back would draw
        // a finer grid than a fresh renderer; this test is about the pixels a colour-only target keeps.
        o.vertex.refine_max_vertices = 0;
        const gl::RasterFrame fresh = gl::Renderer(s, rays, o).render(mode);
        gl::Renderer reused(s, rays, o);
        const Vec3 target = s.observer.target;
        s.observer.target = s.observer.eye + Vec3(glm::rotate(Mat4(1.0), radians(25.0), s.observer.up) *
                                                  Vec4(target - s.observer.eye, 0.0));
        s.observer.width *= 8;
        s.observer.height *= 8;
        const gl::RasterFrame other_large = reused.render(mode);
        s.observer.width /= 8;
        s.observer.height /= 8;
        const gl::RasterFrame other = reused.render(mode);  // the same view at the test's size, to compare
        s.observer.target = target;
        const gl::RasterFrame again = reused.render(mode);
        EXPECT_EQ(other_large.color.size(), 64 * fresh.color.size());
        if (mode == RenderMode::Pvrr) {  // the large view's maps were larger (the first-pass notes say so)
          const StageTiming *large_fp = other_large.stages.find("first-pass"), *fp = again.stages.find("first-pass");
          ASSERT_TRUE(large_fp && fp);
          EXPECT_NE(large_fp->note, fp->note) << scene;
        }
        ASSERT_EQ(again.color.size(), fresh.color.size());
        size_t differs_from_other = 0, mismatches = 0;
        for (size_t i = 0; i < fresh.color.size(); ++i) {
          differs_from_other += glm::length(other.color[i] - fresh.color[i]) > 1e-3;
          const bool same = glm::length(again.color[i] - fresh.color[i]) <= kColourTol &&
                            (!seen_points || (again.element[i] == fresh.element[i] &&
                                              glm::length(again.seen[i] - fresh.seen[i]) <= 1e-9 * (1.0 + glm::length(fresh.seen[i]))));
          mismatches += !same;
        }
        EXPECT_GT(differs_from_other, fresh.color.size() / 4) << scene << " mode " << int(mode) << ": the other view must differ";
        EXPECT_EQ(mismatches, 0u) << scene << " mode " << int(mode) << (seen_points ? "" : ", picture only");
      }
    }
  }
}

// A lens with RGB dispersion renders its maps as three R32F planes and reads one float per channel
// (shaders/outputs.glsl PLANES); any other channel set uses an RGBA32F map and the general weighted sum. The
// same RGB channels with a weight off the unit vectors by 1e-30 take the general path: the colours must
// agree to float rounding, and the seen points to 1e-6 m (both read the same seen-point map).
TEST_P(ColourOnlyTest, RgbLensPlanesEqualTheGeneralMap) {
  const auto ctx = test::glContextOrFail(GetParam());
  if (!ctx) return;
  Scene s = buildScene(loadScene(std::string(PVRR_SOURCE_DIR) + "/models/reading-lens.json",
                                 {"observer.image_size=[96,72]", "render.map_size=256", "render.dispersion=rgb"}));
  RayScene rays(s);
  gl::RendererOptions planes, general;
  planes.vertex.channels = dispersionChannels(s, 0, "rgb", s.render.spectral_samples);
  ASSERT_EQ(planes.vertex.channels.size(), 3u);
  general.vertex.channels = planes.vertex.channels;
  for (size_t c = 0; c < 3; ++c) {
    Vec3 w(0.0);
    w[int(c)] = 1.0;
    w[int((c + 1) % 3)] = 1e-30;
    general.vertex.channels[c].rgb_weight = w;
  }
  const gl::RasterFrame a = gl::Renderer(s, rays, planes).render(RenderMode::Pvrr);
  const gl::RasterFrame b = gl::Renderer(s, rays, general).render(RenderMode::Pvrr);
  ASSERT_EQ(a.color.size(), b.color.size());
  const StageTiming *pa = a.stages.find("first-pass"), *pb = b.stages.find("first-pass");
  ASSERT_TRUE(pa && pb);
  EXPECT_NE(pa->note.find("RGB planes"), std::string::npos) << pa->note;
  EXPECT_EQ(pb->note.find("planes"), std::string::npos) << pb->note;
  size_t lens_pixels = 0;
  double worst = 0;
  for (size_t i = 0; i < a.color.size(); ++i) {
    lens_pixels += a.element[i] == 0;
    worst = std::max(worst, glm::length(a.color[i] - b.color[i]));
    EXPECT_LE(glm::length(a.seen[i] - b.seen[i]), 1e-6) << "pixel " << i;
  }
  EXPECT_GT(lens_pixels, 200u);
  EXPECT_LE(worst, kColourTol);
}

// Elements drawn inside an RGB lens's planes map: a plane mirror lying on the page under the reading lens,
// with its own PVRR map (render.max_depth 4: the lens's two interfaces and the mirror) or drawn dark at the
// depth limit (max_depth 2). Both take the PLANES variants of the element programs. The picture is finite,
// the stages say what happened, and the lens shows the mirror's reflection where the dark one was.
TEST_P(ColourOnlyTest, ElementsInsideAnRgbLensMap) {
  const auto ctx = test::glContextOrFail(GetParam());
  if (!ctx) return;
  std::vector<Vec3> colours[2];
  for (int pass = 0; pass < 2; ++pass) {
    const int depth = pass == 0 ? 4 : 2;
    Scene s = buildScene(loadScene(std::string(PVRR_SOURCE_DIR) + "/models/reading-lens.json",
                                   {"observer.image_size=[96,72]", "render.map_size=256", "render.dispersion=rgb",
                                    "render.max_depth=" + std::to_string(depth)}));
    const cad::Outline outline = cad::Outline::rectangle(0.08, 0.08);
    test::addMirror(s, cad::makePlane(outline), outline, test::pose(Vec3(0, 0.752, 0), Vec3(0, 1, 0), Vec3(0, 0, -1)), 5);
    s.updateBounds();
    RayScene rays(s);
    gl::RendererOptions opt;
    opt.vertex.channels.clear();  // each element its own: the lens R, G, B; the mirror one
    const gl::RasterFrame f = gl::Renderer(s, rays, opt).render(RenderMode::Pvrr);
    const StageTiming *fp = f.stages.find("first-pass"), *np = f.stages.find("nested-passes");
    ASSERT_TRUE(fp && np);
    EXPECT_NE(fp->note.find("RGB planes"), std::string::npos) << fp->note;
    if (depth == 4) {
      EXPECT_TRUE(np->ran) << np->note;
      EXPECT_GE(np->count, 1) << np->note;
    } else {
      EXPECT_NE(np->reason.find("drawn dark"), std::string::npos) << np->reason;
    }
    for (const Vec3& c : f.color) ASSERT_TRUE(std::isfinite(c.x + c.y + c.z));
    colours[pass] = f.color;
  }
  size_t differ = 0;
  for (size_t i = 0; i < colours[0].size(); ++i) differ += glm::length(colours[0][i] - colours[1][i]) > 0.05;
  EXPECT_GT(differ, 10u);
}

PVRR_GL_BACKENDS(ColourOnlyTest);

}  // namespace
}  // namespace pvrr
