// The static/dynamic split (issue 24): with the overtaking car moving, one renderer and one ray scene follow it
// in place (the moved meshes' buffers, their own small ray scene, the cube maps drawn again only where the
// car is and was, pvrr/gl/cube_pass.h) and must give the pictures of a renderer and a ray scene built anew
// at each instant, which redraw everything: identical pixels (colour, seen point, element) in every raster
// mode, on OSMesa and EGL. The car must show in the pictures: frames at different instants differ, so an
// update that is ignored (a stale buffer, ray scene or cube) fails.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "pvrr/gl/context.h"
#include "pvrr/gl/renderer.h"
#include "pvrr/scene/scene_build.h"
#include "pvrr/scene/scene_json.h"
#include "support/gl_backends.h"

namespace pvrr {
namespace {

// Pixels (colour, seen point, element) that differ between two frames. Expected 0 against the rebuilt
// renderer: the in-place updates keep the very data a new build makes, and the cube texels redrawn are drawn
// by the same GL commands as a whole face's.
size_t differingPixels(const gl::RasterFrame& a, const gl::RasterFrame& b) {
  size_t n = 0;
  for (size_t i = 0; i < a.color.size(); ++i)
    n += a.color[i] != b.color[i] || a.seen[i] != b.seen[i] || a.element[i] != b.element[i];
  return n;
}

// The car covers some dozens of mirror pixels at 160 x 120 while it is 7 to 13 m behind; a frame in which it
// did not move would differ from the next in none.
constexpr size_t kMinCarPixels = 20;

std::string stageText(const gl::RasterFrame& f, const char* stage) {
  const StageTiming* t = f.stages.find(stage);
  return t ? t->note + t->reason : std::string("(no stage)");
}

class StaticDynamicSplitTest : public ::testing::TestWithParam<gl::GlBackend> {
 protected:
  void clip(RenderMode mode, const std::vector<std::string>& sets) {
    const bool shadows = sets.size() > 1 && sets[1].find("shadows") != std::string::npos;
    SCOPED_TRACE(nameOf(mode) + std::string(shadows ? " with shadows" : ""));
    const SceneDesc desc = loadScene(std::string(PVRR_SOURCE_DIR) + "/models/overtaking-car.json", sets);
    Scene s = buildScene(desc);
    RayScene rays(s);
    gl::RendererOptions o = gl::rendererOptionsFor(s);
    o.map_size = 128;
    gl::Renderer inplace(s, rays, o);
    gl::FrameCache cache;
    std::vector<gl::RasterFrame> frames;
    for (const double t : {0.5, 0.65, 0.8}) {
      applyAnimation(s, desc, t);
      rays.updateElementPoses();
      rays.updateEnvironmentMeshes();
      if (!frames.empty()) cache.environment_changed = false;
      frames.push_back(inplace.render(mode, &cache));
      // Everything built anew at this instant.
      Scene f = buildScene(desc);
      applyAnimation(f, desc, t);
      RayScene fresh_rays(f);
      gl::Renderer fresh(f, fresh_rays, o);
      const gl::RasterFrame b = fresh.render(mode);
      EXPECT_EQ(differingPixels(frames.back(), b), 0u) << "t = " << t;
      const std::string first_pass = stageText(frames.back(), "first-pass");
      if (frames.size() > 1 && (mode == RenderMode::Envmap || mode == RenderMode::Impostor)) {
        EXPECT_EQ(first_pass.find("updated in place") != std::string::npos, !shadows) << first_pass;
        if (shadows) {
          EXPECT_NE(first_pass.find("casts shadows"), std::string::npos) << first_pass;
        }
      }
      // The overtaking car's mirror needs the impostor's second layers at some pixels: updated in place too.
      if (mode == RenderMode::Impostor && !shadows && frames.size() > 1) {
        const std::string second = stageText(frames.back(), "second-pass");
        EXPECT_NE(second.find("second layers drawn"), std::string::npos) << second;
        EXPECT_NE(second.find("updated in place"), std::string::npos) << second;
      }
      if (shadows && frames.size() > 1) {
        const std::string sm = stageText(frames.back(), "shadow-maps");
        EXPECT_NE(sm.find("moved"), std::string::npos) << sm;
      }
    }
    for (size_t i = 1; i < frames.size(); ++i)
      EXPECT_GE(differingPixels(frames[i - 1], frames[i]), kMinCarPixels) << "frame " << i << ": the car did not move";
  }
};

TEST_P(StaticDynamicSplitTest, MovingCarUpdatedInPlaceMatchesRedrawingEverything) {
  auto ctx = test::glContextOrFail(GetParam());
  if (!ctx) return;
  const std::vector<std::string> small = {"observer.image_size=[160,120]"};
  for (RenderMode m : {RenderMode::Impostor, RenderMode::Envmap, RenderMode::Pvrr}) clip(m, small);
  // Raster mode shows the mirror as a plain surface: the observer turns to see the car directly.
  clip(RenderMode::Raster, {"observer.image_size=[160,120]", "observer.target=[-3.25, 0.8, 11]"});
}

// A light that casts shadows: the moving car's shadow falls on the static road, so the cubes are drawn whole
// again (and say why), and the shadow maps are drawn again: still the pictures of a new build.
TEST_P(StaticDynamicSplitTest, WithShadowsTheCubesAreDrawnWhole) {
  auto ctx = test::glContextOrFail(GetParam());
  if (!ctx) return;
  clip(RenderMode::Impostor, {"observer.image_size=[160,120]", "lights[0].shadows=true"});
}

PVRR_GL_BACKENDS(StaticDynamicSplitTest);

}  // namespace
}  // namespace pvrr
