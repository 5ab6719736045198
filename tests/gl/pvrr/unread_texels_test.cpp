// RendererOptions::skip_unread_texels: the first passes leave unshaded the map texels that no element can fetch
// (pvrr/method/map_footprint.h), and every frame is the same, bit for bit, as with whole maps: colour, seen points,
// element ids and surface points. Covered: a convex mirror, a concave mirror's reversed (zooming) map, nested
// maps of a mirror seen in a mirror, a lens's R, G and B planes, a saddle, and map reuse across frames (maps
// widened for reuse are drawn whole: later frames read elsewhere in them). OSMesa and EGL.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include <glm/gtc/matrix_transform.hpp>

#include "pvrr/gl/context.h"
#include "pvrr/gl/renderer.h"
#include "pvrr/scene/scene_build.h"
#include "pvrr/scene/scene_json.h"
#include "support/frames.h"
#include "support/scenes.h"
#include "support/gl_backends.h"

namespace pvrr {
namespace {

using test::differingPixels;
// models/NAME.json at 160 x 120 pixels.
Scene shippedScene(const std::string& name) { return test::shippedScene(name, {"observer.image_size=[160,120]"}); }

class UnreadTexelsTest : public ::testing::TestWithParam<gl::GlBackend> {};

// The percentage in the first pass's note "K % of map texels left unshaded", or -1 without one.
int unshadedPercent(const gl::RasterFrame& f) {
  const StageTiming* s = f.stages.find("first-pass");
  if (!s) return -1;
  const size_t at = s->note.find(" % of map texels left unshaded");
  if (at == std::string::npos) return -1;
  const size_t from = s->note.rfind(' ', at - 1);
  return std::stoi(s->note.substr(from == std::string::npos ? 0 : from + 1, at - from));
}

TEST_P(UnreadTexelsTest, ShippedScenesAreTheSameBitForBit) {
  const auto ctx = test::glContextOrFail(GetParam());
  if (!ctx) return;
  // The least share of map texels left unshaded (measured at 160 x 120: 19, 21, 4, 20, 80 and under 1 %).
  const std::pair<const char*, int> scenes[] = {{"car-mirror", 15},   {"concave-mirror", 15}, {"mirror-pair", 2},
                                                {"reading-lens", 15}, {"saddle-mirror", 50},  {"plane-mirror", 0}};
  for (const auto& [name, least] : scenes) {
    const Scene s = shippedScene(name);
    RayScene rays(s);
    gl::RendererOptions whole_opts;
    whole_opts.skip_unread_texels = false;
    gl::Renderer whole(s, rays, whole_opts), skipping(s, rays, gl::RendererOptions{});
    const gl::RasterFrame a = whole.render(RenderMode::Pvrr), b = skipping.render(RenderMode::Pvrr);
    EXPECT_EQ(differingPixels(a, b), 0u) << name;
    EXPECT_EQ(unshadedPercent(a), -1) << name << ": whole maps";
    EXPECT_GE(unshadedPercent(b), least) << name << ": " << b.stages.find("first-pass")->note;
    std::printf("%s: %d %% of map texels left unshaded\n", name, unshadedPercent(b));
  }
}

// A small lens attached to the head (a 12 x 10 mm loupe 4 cm before the eye, which sees the room around it)
// while the head turns, with a frame cache and map reuse on: the first frame's map skips texels; the maps of
// the frames after it are widened for reuse and must be drawn whole (their notes say none skipped), because
// the frames drawn from them read texels that the frame that drew them did not (the lens turns with the
// head, the room does not): masking them changes those frames (tried: up to 45 pixels in 19,200). Every
// frame equals the one drawn with whole maps.
TEST_P(UnreadTexelsTest, MapReuseReadsWholeMaps) {
  const auto ctx = test::glContextOrFail(GetParam());
  if (!ctx) return;
  const SceneDesc desc = loadScene(PVRR_SOURCE_DIR "/models/spectacle-lens.json",
                                   {"observer.image_size=[160,120]", "elements[0].outline.width=0.012",
                                    "elements[0].outline.height=0.01", "elements[0].pose.position=[0.01,0,-0.04]"});
  Scene s = buildScene(desc);
  RayScene rays(s);
  gl::RendererOptions whole_opts;
  whole_opts.skip_unread_texels = false;
  gl::Renderer whole(s, rays, whole_opts), skipping(s, rays, gl::RendererOptions{});
  gl::FrameCache whole_cache, skipping_cache;
  const Vec3 eye = s.observer.eye, target0 = s.observer.target;
  int reused = 0;
  for (const double deg : {0.0, 0.4, 0.8, 1.2, 1.6, 4.0, 4.4}) {
    s.observer.target = eye + Vec3(glm::rotate(Mat4(1.0), radians(deg), Vec3(0, 1, 0)) * Vec4(target0 - eye, 0.0));
    updateAttachedElements(s, desc);
    rays.updateElementPoses();
    whole_cache.environment_changed = skipping_cache.environment_changed = false;
    const gl::RasterFrame a = whole.render(RenderMode::Pvrr, &whole_cache);
    const gl::RasterFrame b = skipping.render(RenderMode::Pvrr, &skipping_cache);
    EXPECT_EQ(differingPixels(a, b), 0u) << "turned " << deg << " deg";
    const StageTiming* first = b.stages.find("first-pass");
    ASSERT_TRUE(first);
    reused += !first->ran;
    if (deg == 0.0) {
      EXPECT_GT(unshadedPercent(b), 0) << "the first frame's map is not kept for reuse: " << first->note;
    } else if (first->ran) {
      EXPECT_NE(first->note.find("widened"), std::string::npos) << first->note;
      EXPECT_EQ(unshadedPercent(b), -1) << "a map widened for reuse is drawn whole: " << first->note;
    }
  }
  EXPECT_GE(reused, 3) << "frames drawn from earlier maps";
}

PVRR_GL_BACKENDS(UnreadTexelsTest);

}  // namespace
}  // namespace pvrr
