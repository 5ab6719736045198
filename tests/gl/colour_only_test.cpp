// RendererOptions::seen_points off (pvrr render: the picture only): every mode draws the same colours as with
// the seen-point attachments on, leaves the seen points out, and says so in its stages. OSMesa and EGL.
#include <gtest/gtest.h>

#include <string>

#include "pvrr/gl/context.h"
#include "pvrr/gl/renderer.h"
#include "pvrr/scene_build.h"
#include "pvrr/scene_json.h"
#include "support/gl_backends.h"

namespace pvrr {
namespace {

// The same shaders and inputs, minus outputs that are not written: the colours should agree to float
// rounding; 1e-6 in linear units is far below one 8-bit step (~4e-3).
constexpr double kColourTol = 1e-6;

class ColourOnlyTest : public ::testing::TestWithParam<gl::GlBackend> {};

TEST_P(ColourOnlyTest, SameColoursWithoutSeenPoints) {
  const auto ctx = test::glContextOrFail(GetParam());
  if (!ctx) return;
  for (const char* scene : {"car-mirror", "reading-lens", "mirror-pair"}) {
    Scene s = buildScene(loadScene(std::string(PVRR_SOURCE_DIR) + "/models/" + scene + ".json",
                                   {"observer.image_size=[96,72]", "render.map_size=256"}));
    RayScene rays(s);
    gl::RendererOptions with, without;
    with.vertex.channels.clear();
    without.vertex.channels.clear();
    without.seen_points = false;
    gl::Renderer a(s, rays, with), b(s, rays, without);
    for (gl::RasterMode mode : {gl::RasterMode::Pvrr, gl::RasterMode::Envmap, gl::RasterMode::Raster}) {
      const gl::RasterFrame fa = a.render(mode), fb = b.render(mode);
      ASSERT_EQ(fa.color.size(), fb.color.size()) << scene;
      EXPECT_EQ(fa.seen.size(), fa.color.size());
      EXPECT_TRUE(fb.seen.empty() && fb.element.empty() && fb.element_point.empty()) << scene;
      double worst = 0;
      for (size_t i = 0; i < fa.color.size(); ++i) worst = std::max(worst, glm::length(fa.color[i] - fb.color[i]));
      EXPECT_LE(worst, kColourTol) << scene << " mode " << int(mode);
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
  Scene s = buildScene(loadScene(std::string(PVRR_SOURCE_DIR) + "/models/car-mirror.json",
                                 {"observer.image_size=[96,72]", "render.map_size=256"}));
  RayScene rays(s);
  for (gl::RasterMode mode : {gl::RasterMode::Raster, gl::RasterMode::Envmap, gl::RasterMode::Pvrr}) {
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
    EXPECT_GT(element_pixels, 200u) << "mode " << int(mode);
    EXPECT_EQ(same, first.color.size()) << "mode " << int(mode);
    EXPECT_LE(worst, kColourTol) << "mode " << int(mode);
  }
}

PVRR_GL_BACKENDS(ColourOnlyTest);

}  // namespace
}  // namespace pvrr
