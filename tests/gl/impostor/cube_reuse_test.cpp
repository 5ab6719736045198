// Cube-map reuse across frames (pvrr/gl/cube_pass.h): in envmap and impostor modes the cubes are drawn from
// each element's centre and do not depend on the eye, so a renderer with a frame cache draws them once and
// reuses them while the environment and every element's pose stay as they were. The pictures must be the
// ones a renderer that redraws its cubes every frame makes: identical pixels, on OSMesa and EGL.
#include <gtest/gtest.h>

#include <string>

#include <glm/gtc/matrix_transform.hpp>

#include "pvrr/gl/context.h"
#include "pvrr/gl/renderer.h"
#include "pvrr/scene/scene_build.h"
#include "pvrr/scene/scene_json.h"
#include "support/gl_backends.h"

namespace pvrr {
namespace {

// The frame's "first-pass" stage: whether it ran, and its note or skip reason.
std::string firstPass(const gl::RasterFrame& f, bool* ran) {
  const StageTiming* t = f.stages.find("first-pass");
  *ran = t && t->ran;
  return t ? t->note + t->reason : "";
}

// Pixels (colour, seen point, element) that differ between two frames. Expected 0: reuse keeps the very
// cubes a redraw would draw again from the same inputs, with the same GL commands.
size_t differingPixels(const gl::RasterFrame& a, const gl::RasterFrame& b) {
  size_t n = 0;
  for (size_t i = 0; i < a.color.size(); ++i)
    n += a.color[i] != b.color[i] || a.seen[i] != b.seen[i] || a.element[i] != b.element[i];
  return n;
}

struct OrbitCase {
  const char* scene;
  RenderMode mode;
  bool attached;  // the element moves with the head: its cubes are drawn again every frame that turns
};

class CubeReuseTest : public ::testing::TestWithParam<gl::GlBackend> {
 protected:
  // An orbit of the head about the eye (as `pvrr render --orbit`): one renderer with a frame cache against
  // one that redraws every frame (no cache), frame by frame.
  void orbit(const OrbitCase& c) {
    SCOPED_TRACE(std::string(c.scene) + " " + nameOf(c.mode));
    const SceneDesc desc =
        loadScene(std::string(PVRR_SOURCE_DIR) + "/models/" + c.scene + ".json", {"observer.image_size=[160,120]"});
    Scene s = buildScene(desc);
    RayScene rays(s);
    gl::RendererOptions o;
    o.map_size = 128;
    gl::Renderer cached(s, rays, o), redrawn(s, rays, o);
    gl::FrameCache cache;
    const Vec3 eye = s.observer.eye, target0 = s.observer.target;
    for (int i = 0; i < 4; ++i) {
      s.observer.target =
          eye + Vec3(glm::rotate(Mat4(1.0), radians(2.0 * i), s.observer.up) * Vec4(target0 - eye, 0.0));
      updateAttachedElements(s, desc);
      rays.updateElementPoses();
      if (i > 0) cache.environment_changed = false;
      const gl::RasterFrame a = cached.render(c.mode, &cache), b = redrawn.render(c.mode);
      EXPECT_EQ(differingPixels(a, b), 0u) << "frame " << i;
      bool ran = false;
      const std::string note = firstPass(a, &ran);
      const bool expect_reuse = i > 0 && !c.attached;
      EXPECT_EQ(ran, !expect_reuse) << "frame " << i << ": " << note;
      if (expect_reuse) {
        EXPECT_NE(note.find("cube maps reused"), std::string::npos) << note;
      }
      if (i > 0 && c.attached) {
        EXPECT_NE(note.find("moved (attached to the observer)"), std::string::npos) << note;
      }
      firstPass(b, &ran);
      EXPECT_TRUE(ran) << "without a frame cache every frame draws its cubes";
    }
    // A changed environment draws them again.
    cache.environment_changed = true;
    bool ran = false;
    const std::string note = firstPass(cached.render(c.mode, &cache), &ran);
    EXPECT_TRUE(ran);
    EXPECT_NE(note.find("the environment changed"), std::string::npos) << note;
  }
};

TEST_P(CubeReuseTest, OrbitWithReuseMatchesRedrawingEveryFrame) {
  auto ctx = test::glContextOrFail(GetParam());
  if (!ctx) return;
  for (const OrbitCase& c :
       {OrbitCase{"car-mirror", RenderMode::Impostor, false}, OrbitCase{"car-mirror", RenderMode::Envmap, false},
        OrbitCase{"mirror-pair", RenderMode::Impostor, false}, OrbitCase{"spectacle-lens", RenderMode::Impostor, true}})
    orbit(c);
}

PVRR_GL_BACKENDS(CubeReuseTest);

}  // namespace
}  // namespace pvrr
