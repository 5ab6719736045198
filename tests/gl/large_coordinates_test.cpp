// Huge coordinates (a design placed in site or map coordinates, millions of metres from the origin): the
// whole scene translated by such an offset renders as it does at the origin, in the reference and in every
// raster mode, because the CPU works in doubles and the GPU in coordinates relative to each pass's camera.
// OSMesa and EGL.
#include <gtest/gtest.h>

#include <algorithm>
#include <iostream>
#include <vector>

#include "pvrr/gl/renderer.h"
#include "pvrr/trace/tracer.h"
#include "support/accuracy.h"
#include "support/gl_backends.h"
#include "support/scenes.h"
#include "support/test_scenes.h"

namespace pvrr {
namespace {

// Every world position of the scene moved by `offset` (directions unchanged).
void translate(Scene& s, const Vec3& offset) {
  s.observer.eye += offset;
  s.observer.target += offset;
  for (EnvMesh& m : s.meshes) m.anchor += offset;
  for (Light& l : s.lights) l.position += offset;
  for (Element& e : s.elements) {
    e.local_to_world[3] += Vec4(offset, 0.0);
    e.world_to_local = glm::inverse(e.local_to_world);
  }
  s.updateBounds();
}

Scene mirrorInARoom(const Vec3& offset) {
  Scene s = test::roomScene(Vec3(0.3, 0.2, 1.2), Vec3(0, 0, 0), 120, 90);
  const cad::Outline outline = cad::Outline::rectangle(0.5, 0.4, 0.05);
  test::addMirror(s, cad::makeSphere(1.0, outline), outline, test::pose(Vec3(0, 0, -0.3), Vec3(0, 0, 1)), 25, 0.9);
  Light point;
  point.type = Light::Type::Point;
  point.position = Vec3(0.5, 2.0, 0.5);
  point.radiance = Vec3(0.5);
  s.lights.push_back(point);
  s.updateBounds();
  translate(s, offset);
  return s;
}

// The +10 D lens of the lens tests (tests/support/test_scenes.h), the room seen through it.
Scene lensInARoom(const Vec3& offset) {
  const cad::Outline disc = cad::Outline::circle(0.04);
  Scene s = test::roomLensScene("+10 D", cad::makeSphere(0.1, disc), cad::makeSphere(-0.1, disc), 0.005, disc);
  translate(s, offset);
  return s;
}

// The shipped mirror pair (a mirror seen in a mirror): pvrr's nested maps, impostor mode's mirrors in each
// other's cube maps.
Scene mirrorPair(const Vec3& offset) {
  Scene s = test::shippedScene("mirror-pair", {"observer.image_size=[120,90]"});
  translate(s, offset);
  return s;
}
enum class Kind { Mirror, Lens, MirrorPair };

struct Result {
  std::vector<Vec3> color, seen_rel;  // seen points relative to the eye
  std::vector<int> element;
  double median_arcmin = 0;
};

Result run(const Vec3& offset, RenderMode mode, Kind kind) {
  Scene s = kind == Kind::Lens         ? lensInARoom(offset)
            : kind == Kind::MirrorPair ? mirrorPair(offset)
                                       : mirrorInARoom(offset);
  RayScene rays(s);
  const Frame ref = test::referenceFrame(rays);
  gl::RendererOptions opt;
  opt.map_size = 512;
  gl::Renderer r(s, rays, opt);
  const gl::RasterFrame f = r.render(mode);
  Result out;
  out.color = f.color;
  out.element = f.element;
  std::vector<double> err;
  for (size_t i = 0; i < f.seen.size(); ++i) {
    out.seen_rel.push_back(f.seen[i] - s.observer.eye);
    if (ref.element[i] >= 0)
      err.push_back(arcminutes(angleBetween(ref.seen[i] - ref.element_point[i], f.seen[i] - ref.element_point[i])));
  }
  std::sort(err.begin(), err.end());
  out.median_arcmin = err.empty() ? 1e9 : err[err.size() / 2];
  return out;
}

class LargeCoordinatesTest : public ::testing::TestWithParam<gl::GlBackend> {};

// The same frame at the origin and far away: the same element pixels (to 1 %), colours and seen points.
void expectSameFarAway(RenderMode mode, Kind kind) {
  const Vec3 far_away(3.2e6, 1.5e3, -5.4e6);  // UTM-like easting/northing, metres
  const Result near = run(Vec3(0.0), mode, kind), far = run(far_away, mode, kind);
  ASSERT_EQ(near.color.size(), far.color.size());
  size_t differ = 0, pixels = 0;
  double worst_seen = 0;
  for (size_t i = 0; i < near.color.size(); ++i) {
    ASSERT_TRUE(isFinite(far.color[i]) && isFinite(far.seen_rel[i])) << "pixel " << i;
    if (near.element[i] != far.element[i]) {
      ++differ;
      continue;
    }
    pixels += near.element[i] >= 0;
    // Colours: the same shading of the same relative geometry; float rounding of the camera-relative
    // positions (~1e-7 relative) moves an edge by a pixel at most, so compare the bulk.
    if (glm::length(near.color[i] - far.color[i]) > 1e-3) ++differ;
    // Seen points relative to the eye: exact to float rounding of metre-scale coordinates, not of 5e6 m
    // ones (which would be ~0.5 m).
    if (near.element[i] >= 0) worst_seen = std::max(worst_seen, glm::length(near.seen_rel[i] - far.seen_rel[i]));
  }
  const char* name = kind == Kind::Lens ? "lens" : kind == Kind::MirrorPair ? "mirror pair" : "mirror";
  std::cout << "[ measured ] " << name << ", mode " << nameOf(mode) << ": " << differ
            << " of " << near.color.size() << " pixels differ, seen points within " << worst_seen << " m, median "
            << near.median_arcmin << "' at the origin, " << far.median_arcmin << "' far away\n";
  EXPECT_LE(differ, near.color.size() / 100) << nameOf(mode);
  EXPECT_LT(worst_seen, 1e-3) << nameOf(mode);
  if (mode == RenderMode::Pvrr || mode == RenderMode::Impostor) {
    EXPECT_LT(far.median_arcmin, 1.0) << nameOf(mode);
    EXPECT_NEAR(far.median_arcmin, near.median_arcmin, 0.01 + 0.05 * near.median_arcmin) << nameOf(mode);
  }
  EXPECT_GT(pixels, 500u);  // element pixels compared
}

TEST_P(LargeCoordinatesTest, SceneMillionsOfMetresAwayRendersAsAtTheOrigin) {
  const auto ctx = test::glContextOrFail(GetParam());
  if (!ctx) return;
  for (RenderMode mode :
       {RenderMode::Pvrr, RenderMode::Envmap, RenderMode::Impostor, RenderMode::Raster})
    expectSameFarAway(mode, Kind::Mirror);
}

// A lens: pvrr's refraction on the CPU in doubles, the impostor's in the lens's own frame on the GPU.
TEST_P(LargeCoordinatesTest, LensMillionsOfMetresAwayRendersAsAtTheOrigin) {
  const auto ctx = test::glContextOrFail(GetParam());
  if (!ctx) return;
  for (RenderMode mode : {RenderMode::Pvrr, RenderMode::Impostor}) expectSameFarAway(mode, Kind::Lens);
}

// A mirror seen in a mirror: pvrr's nested first passes from virtual viewpoints, the impostor's search
// continued in the other mirror's cube maps, both in camera-relative coordinates.
TEST_P(LargeCoordinatesTest, MirrorPairMillionsOfMetresAwayRendersAsAtTheOrigin) {
  const auto ctx = test::glContextOrFail(GetParam());
  if (!ctx) return;
  for (RenderMode mode : {RenderMode::Pvrr, RenderMode::Impostor})
    expectSameFarAway(mode, Kind::MirrorPair);
}

PVRR_GL_BACKENDS(LargeCoordinatesTest);

}  // namespace
}  // namespace pvrr
