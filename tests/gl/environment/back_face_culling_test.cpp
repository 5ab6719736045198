// RendererOptions::cull_back_faces: culling the back faces of closed convex environment meshes leaves every
// pass's picture as it was, but for depth ties (silhouettes, thin or distant solids), where the front face now
// wins as in the reference tracer; meshes that near clipping could cut open (the room around the eye, a box
// grazing the eye) keep every face. OSMesa and EGL.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "cad/sag.h"
#include "pvrr/gl/context.h"
#include "pvrr/gl/renderer.h"
#include "pvrr/scene/scene_build.h"
#include "pvrr/scene/scene_json.h"
#include "pvrr/trace/tracer.h"
#include "support/gl_backends.h"
#include "support/test_scenes.h"

namespace pvrr {
namespace {

class BackFaceCullingTest : public ::testing::TestWithParam<gl::GlBackend> {};

// Colours that differ by more than float rounding of the same shading (1e-6 in linear units).
constexpr double kSame = 1e-6;

struct Culled {
  int culled = -1, drawn = -1;
};
// The counts of a stage note's "back faces culled on K of N closed-mesh draws".
Culled culledIn(const gl::RasterFrame& f, const std::string& stage) {
  const StageTiming* s = f.stages.find(stage);
  Culled c;
  if (!s) return c;
  const size_t at = s->note.find("back faces culled on ");
  if (at != std::string::npos) std::sscanf(s->note.c_str() + at, "back faces culled on %d of %d", &c.culled, &c.drawn);
  return c;
}

struct Comparison {
  size_t pixels = 0, differ = 0, culled_closer = 0;
};
// Pixels whose colour differs with culling, and of those, how many are at least as close to the tracer's.
Comparison compare(const gl::RasterFrame& off, const gl::RasterFrame& on, const Frame& ref) {
  Comparison c;
  c.pixels = on.color.size();
  for (size_t i = 0; i < on.color.size(); ++i) {
    if (glm::length(on.color[i] - off.color[i]) <= kSame) continue;
    ++c.differ;
    c.culled_closer += glm::length(on.color[i] - ref.color[i]) <= glm::length(off.color[i] - ref.color[i]) + kSame;
  }
  return c;
}

// The shipped scenes in every mode: the street's boxes (buildings, kerbs, car), the room's table and ball,
// the concave mirror's zooming region (reversed depth: never culled).
TEST_P(BackFaceCullingTest, ThePictureIsUnchangedButForSilhouetteTies) {
  const auto ctx = test::glContextOrFail(GetParam());
  if (!ctx) return;
  for (const char* scene : {"car-mirror", "plane-mirror", "concave-mirror", "mirror-pair"}) {
    Scene s = buildScene(loadScene(std::string(PVRR_SOURCE_DIR) + "/models/" + scene + ".json",
                                   {"observer.image_size=[160,120]", "render.map_size=512"}));
    RayScene rays(s);
    const Frame ref = Tracer(rays, TraceOptions{}).render();
    gl::RendererOptions off_opts;
    off_opts.cull_back_faces = false;
    gl::Renderer off(s, rays, off_opts), on(s, rays, gl::RendererOptions{});
    for (RenderMode mode : {RenderMode::Pvrr, RenderMode::Envmap, RenderMode::Raster}) {
      const gl::RasterFrame a = off.render(mode), b = on.render(mode);
      const Comparison c = compare(a, b, ref);
      // Ties happen only where a back face meets a front face on a silhouette: a few pixels in 19,200.
      EXPECT_LE(c.differ, c.pixels / 500) << scene << " mode " << int(mode);
      EXPECT_GE(c.culled_closer, c.differ * 3 / 4) << scene << " mode " << int(mode) << ": " << c.differ << " differ";
      const Culled second = culledIn(b, "second-pass");
      EXPECT_GT(second.culled, 0) << scene << " mode " << int(mode);
      const StageTiming* off_second = a.stages.find("second-pass");
      ASSERT_TRUE(off_second);
      EXPECT_NE(off_second->note.find("not culled"), std::string::npos);
      if (mode != RenderMode::Raster) {
        const Culled first = culledIn(b, "first-pass");
        EXPECT_GT(first.drawn, 0) << scene << " mode " << int(mode);
        // A reversed (zooming) map draws every face; forward maps and cube faces cull.
        bool forward = mode == RenderMode::Envmap;
        int reversed = 0;  // reversed maps drawn: every closed mesh in each keeps its back faces
        for (const ElementFrame& f : b.elements)
          for (const PatchView& v : f.views) {
            if (v.volume.backward) reversed += v.in_view;
            else forward = true;
          }
        if (forward) {
          EXPECT_GT(first.culled, 0) << scene << " mode " << int(mode);
        }
        int closed = 0;
        for (const EnvMesh& m : s.meshes) closed += m.closed_convex;
        EXPECT_GE(first.drawn - first.culled, reversed * closed) << scene << ": a reversed map culls nothing";
        if (std::string(scene) == "concave-mirror" && mode == RenderMode::Pvrr) {
          EXPECT_GT(reversed, 0);
        }
      }
    }
  }
}

// The eye inside a closed box (a room built as one box, seen from inside: every face a back face) and
// 0.2 mm from another box that runs past it on both sides (the eye's 1 mm near plane cuts it open): neither
// is culled. A box 5 mm above the eye, which the near plane also crosses but out of the near rectangle's
// reach, and a box far ahead are culled. The picture is the same as without culling, texel for texel, in the
// second pass and in the mirror's first pass.
TEST_P(BackFaceCullingTest, MeshesNearClippingCanOpenKeepEveryFace) {
  const auto ctx = test::glContextOrFail(GetParam());
  if (!ctx) return;
  Scene s = test::roomScene(Vec3(0.3, 0.2, 1.2), Vec3(0, 0, 0), 160, 120);
  s.meshes.clear();
  s.materials = {DiffuseMaterial{Vec3(0.7, 0.5, 0.3), -1}, DiffuseMaterial{Vec3(0.2, 0.6, 0.3), -1},
                 DiffuseMaterial{Vec3(0.3, 0.3, 0.8), -1}};
  EnvMesh room = makeBoxMesh(Vec3(0), Vec3(6), Mat3(1.0));  // around the eye
  room.material = 0;
  // Its face nearest the eye at x = 0.3002, from 1 m behind the eye to 3 m in front.
  EnvMesh grazing = makeBoxMesh(Vec3(0.3002 + 0.1, 0.2, 0.2), Vec3(0.2, 0.3, 4.0), Mat3(1.0));
  grazing.material = 1;
  EnvMesh far_box = makeBoxMesh(Vec3(-0.9, -0.4, -1.2), Vec3(0.5, 0.6, 0.4), Mat3(1.0));  // culled
  far_box.material = 2;
  // 5 mm above the eye, from 0.3 m behind it to 0.2 m in front: the near plane crosses it, but outside the
  // near rectangle's reach (1.2 mm): culled, and its underside fills the top of the view.
  EnvMesh above = makeBoxMesh(Vec3(0.3, 0.205 + 0.1, 1.15), Vec3(0.6, 0.2, 0.5), Mat3(1.0));
  above.material = 2;
  s.meshes = {room, grazing, far_box, above};
  const cad::Outline outline = cad::Outline::rectangle(0.5, 0.4, 0.05);
  test::addMirror(s, cad::makeSphere(1.0, outline), outline, test::pose(Vec3(0, 0, -0.3), Vec3(0, 0, 1)), 15, 0.9);
  s.updateBounds();
  RayScene rays(s);
  gl::RendererOptions off_opts;
  off_opts.cull_back_faces = false;
  gl::Renderer off(s, rays, off_opts), on(s, rays, gl::RendererOptions{});
  const gl::RasterFrame a = off.render(RenderMode::Pvrr), b = on.render(RenderMode::Pvrr);
  ASSERT_EQ(a.color.size(), b.color.size());
  size_t differ = 0, grazing_pixels = 0, above_pixels = 0;
  for (size_t i = 0; i < a.color.size(); ++i) {
    differ += glm::length(a.color[i] - b.color[i]) > kSame;
    grazing_pixels += b.element[i] < 0 && std::abs(b.seen[i].x - 0.3002) < 1e-3;
    above_pixels += b.element[i] < 0 && std::abs(b.seen[i].y - 0.205) < 1e-3;
  }
  EXPECT_EQ(differ, 0u);
  EXPECT_GT(grazing_pixels, 100u) << "the grazing box fills part of the view";
  EXPECT_GT(above_pixels, 100u) << "the box above the eye fills part of the view";
  const Culled second = culledIn(b, "second-pass"), first = culledIn(b, "first-pass");
  EXPECT_EQ(second.drawn, 4);
  EXPECT_EQ(second.culled, 2) << "the far box and the box above the eye, not the room nor the grazing box";
  int maps = 0;
  for (const PatchView& v : b.elements.at(0).views) maps += v.in_view;
  EXPECT_EQ(first.drawn, 4 * maps);
  EXPECT_LE(first.culled, 3 * maps) << "never the room around the viewpoint";
}

PVRR_GL_BACKENDS(BackFaceCullingTest);

}  // namespace
}  // namespace pvrr
