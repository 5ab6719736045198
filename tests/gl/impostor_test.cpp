// The distance-impostor glass mode (`--mode impostor`, shaders/element.frag MODE_IMPOSTOR) against the reference
// tracer, on OSMesa and EGL: mirrors (the exact reflected ray of each fragment searched in the cube map's
// distances) and lenses (the ray refracted through the lens's refractor height maps, then searched).
//
// Closed form: a plane mirror and a planar environment. There the search's planar-surface step is exact
// (seeds 003, 2.1), so the impostor sees what the tracer sees to the resolution of the cube maps, everywhere
// but where the mirror shows something its cube-map centre cannot see.
#include <gtest/gtest.h>

#include <algorithm>
#include <iostream>
#include <vector>

#include "cad/lens.h"
#include "pvrr/gl/context.h"
#include "pvrr/gl/renderer.h"
#include "pvrr/spectrum.h"
#include "pvrr/tracer.h"
#include "support/accuracy.h"
#include "support/gl_backends.h"
#include "support/scenes.h"
#include "support/test_scenes.h"

namespace pvrr {
namespace {

using test::medianArcmin;

// Per-pixel angular errors (arcmin) where both the reference and the frame see element `element`.
std::vector<double> elementErrors(const TracedFrame& ref, const std::vector<Vec3>& ref_seen, const gl::RasterFrame& f) {
  std::vector<double> e;
  for (size_t i = 0; i < ref.color.size(); ++i)
    if (ref.element[i] >= 0 && f.element[i] == ref.element[i])
      e.push_back(arcminutes(angleBetween(ref_seen[i] - ref.element_point[i], f.seen[i] - ref.element_point[i])));
  std::sort(e.begin(), e.end());
  return e;
}
double quantile(const std::vector<double>& sorted, double q) {
  return sorted.empty() ? 1e9 : sorted[std::min(sorted.size() - 1, size_t(q * double(sorted.size())))];
}
void expectFinite(const gl::RasterFrame& f) {
  for (size_t i = 0; i < f.color.size(); ++i) {
    ASSERT_TRUE(isFinite(f.color[i])) << "pixel " << i;
    ASSERT_TRUE(isFinite(f.seen[i])) << "pixel " << i;
  }
}

class ImpostorTest : public ::testing::TestWithParam<gl::GlBackend> {};

// A plane mirror in the room of planar walls (tests/support/test_scenes.h), the box inside it casting the
// only view-dependent occlusion. Issue 5's bound for a plane mirror, 0.05', on 95 % of the mirror pixels
// (measured: all of them, median 0.0006'); the cube map's median error is 204'.
TEST_P(ImpostorTest, PlaneMirrorInAPlanarRoomSeesWhatTheTracerSees) {
  const auto ctx = test::glContextOrFail(GetParam());
  if (!ctx) return;
  Scene s = test::roomScene(Vec3(0.4, 0.3, 1.5), Vec3(0, 0, 0), 160, 120);
  const cad::Outline outline = cad::Outline::rectangle(0.6, 0.45, 0.03);
  test::addMirror(s, cad::makePlane(outline), outline, test::pose(Vec3(0, 0, -0.4), Vec3(0.1, 0, 1)), 7, 0.9);
  s.updateBounds();
  RayScene rays(s);
  const TracedFrame ref = Tracer(rays, TraceOptions{}).render();
  gl::RendererOptions o;
  o.map_size = 512;
  gl::Renderer r(s, rays, o);
  const gl::RasterFrame f = r.render(gl::RasterMode::Impostor);
  expectFinite(f);
  const std::vector<double> e = elementErrors(ref, ref.seen, f);
  ASSERT_GT(e.size(), 1500u);  // 1862 at 160 x 120
  const double within = double(std::upper_bound(e.begin(), e.end(), 0.05) - e.begin()) / double(e.size());
  const double envmap = medianArcmin(ref, r.render(gl::RasterMode::Envmap));
  std::cout << "[ measured ] plane mirror on " << gl::glBackendName(GetParam()) << ": impostor median "
            << quantile(e, 0.5) << "', " << 100 * within << " % of " << e.size() << " px within 0.05'; envmap median "
            << envmap << "'\n";
  EXPECT_GE(within, 0.95);
  EXPECT_GT(envmap, 100 * quantile(e, 0.5));
}

// The default scene: the street is piecewise planar but full of occlusion (the car's own door close to the
// mirror). Measured at 320 x 240: median 0.08' against the cube map's 10.8' and pvrr's 0.78'; the p95 (~75')
// lies where the door hides from the mirror's centre what the mirror's edge sees.
TEST_P(ImpostorTest, CarMirrorFarBelowTheCubeMap) {
  const auto ctx = test::glContextOrFail(GetParam());
  if (!ctx) return;
  Scene s = test::shippedScene("car-mirror", {"observer.image_size=[320,240]"});
  RayScene rays(s);
  const TracedFrame ref = Tracer(rays, TraceOptions{}).render();
  gl::Renderer r(s, rays, gl::RendererOptions{});
  const gl::RasterFrame f = r.render(gl::RasterMode::Impostor);
  expectFinite(f);
  const double impostor = medianArcmin(ref, f), envmap = medianArcmin(ref, r.render(gl::RasterMode::Envmap));
  std::cout << "[ measured ] car mirror: impostor median " << impostor << "', envmap " << envmap << "'\n";
  EXPECT_LE(impostor, 0.3);
  EXPECT_GE(envmap, 20 * impostor);
  // What ran: no CPU stage, the cube maps with their distances, the search in the second pass.
  const StageTiming* vr = f.stages.find("vertex-rays");
  const StageTiming* fp = f.stages.find("first-pass");
  ASSERT_TRUE(vr && fp);
  EXPECT_FALSE(vr->ran);
  EXPECT_NE(vr->reason.find("each fragment"), std::string::npos) << vr->reason;
  EXPECT_TRUE(fp->ran);
  EXPECT_NE(fp->note.find("distance impostors"), std::string::npos) << fp->note;
}

// Lenses: the spectacle lens (-3 D, the eye chart 4 m away) and the +10 D and -10 D lenses of
// lens_types_test.cpp (real inverted image, focal region between lens and wall; upright minified image).
// The glass is traced per fragment in the refractor height maps: measured medians 0.056' (spectacle lens at
// 320 x 240), far below issue 6's 1' and the cube map's (7.4'), which looks up the exact exit directions of the
// vertices from the lens centre.
TEST_P(ImpostorTest, LensesRefractedThroughTheirHeightMaps) {
  const auto ctx = test::glContextOrFail(GetParam());
  if (!ctx) return;
  struct Case {
    const char* name;
    double r_front, r_back, thickness;
  };
  std::vector<std::pair<std::string, Scene>> scenes;
  scenes.emplace_back("spectacle-lens", test::shippedScene("spectacle-lens", {"observer.image_size=[160,120]"}));
  for (const Case& c : {Case{"+10 D", 0.1, -0.1, 0.005}, Case{"-10 D", -0.1, 0.1, 0.0015}}) {
    const Vec3 eye(0, 0, 2.5);
    Scene s = test::roomScene(eye, Vec3(0, 0, -3), 160, 120);
    s.observer.fov_y_rad = radians(8);
    const cad::Outline disc = cad::Outline::circle(0.04);
    Element e;
    e.name = c.name;
    e.type = ElementType::Lens;
    e.lens = cad::makeLens(cad::makeSphere(c.r_front, disc), cad::makeSphere(c.r_back, disc), disc, c.thickness, 0.0, c.name);
    e.outline = disc;
    e.local_to_world = test::pose(Vec3(0, 0, 2.0), Vec3(0, 0, 1));
    e.world_to_local = glm::inverse(e.local_to_world);
    e.dispersion = Dispersion::constant(1.5);
    e.tess_u = e.tess_v = 24;
    s.elements.push_back(e);
    s.updateBounds();
    scenes.emplace_back(c.name, std::move(s));
  }
  for (auto& [name, s] : scenes) {
    RayScene rays(s);
    TraceOptions to;
    to.max_depth = s.render.max_depth;
    const TracedFrame ref = Tracer(rays, to).render();
    gl::RendererOptions o;
    o.map_size = 512;
    gl::Renderer r(s, rays, o);
    const gl::RasterFrame f = r.render(gl::RasterMode::Impostor);
    expectFinite(f);
    const std::vector<double> e = elementErrors(ref, ref.seen, f);
    const double envmap = medianArcmin(ref, r.render(gl::RasterMode::Envmap));
    std::cout << "[ measured ] " << name << ": impostor median " << quantile(e, 0.5) << "', p95 " << quantile(e, 0.95)
              << "' over " << e.size() << " px; envmap median " << envmap << "'\n";
    ASSERT_GT(e.size(), 2000u) << name;
    EXPECT_LE(quantile(e, 0.5), 0.2) << name;
    EXPECT_LE(quantile(e, 0.95), 1.0) << name;
    EXPECT_GT(envmap, 5 * quantile(e, 0.5)) << name;
    const StageTiming* rf = f.stages.find("refraction");
    ASSERT_TRUE(rf);
    EXPECT_NE(rf->reason.find("refractor height maps"), std::string::npos) << rf->reason;
  }
}

// RGB dispersion (the reading lens over a page): each channel is refracted with its own index, so each
// channel's seen point matches the reference's channel, and blue bends more than red as in the tracer.
// Red's seen points lie as far from the reference's blue ones as the fringe is wide (8' median): a single
// index for all three channels would fail one of the two checks.
TEST_P(ImpostorTest, EachColourChannelRefractedWithItsOwnIndex) {
  const auto ctx = test::glContextOrFail(GetParam());
  if (!ctx) return;
  Scene s = test::shippedScene("reading-lens", {"observer.image_size=[160,120]", "render.dispersion=\"rgb\""});
  RayScene rays(s);
  TraceOptions to;
  to.dispersion = DispersionMode::Rgb;
  to.max_depth = s.render.max_depth;
  const TracedFrame ref = Tracer(rays, to).render();
  ASSERT_FALSE(ref.channel_seen[0].empty());
  std::array<std::vector<double>, 3> e;
  gl::RasterFrame green;
  double red_against_blue = 0;
  for (int c = 0; c < 3; ++c) {
    gl::RendererOptions o;
    o.map_size = 512;
    o.seen_channel = c;
    gl::Renderer r(s, rays, o);
    const gl::RasterFrame f = r.render(gl::RasterMode::Impostor);
    expectFinite(f);
    e[size_t(c)] = elementErrors(ref, ref.channel_seen[size_t(c)], f);
    if (c == 1) green = f;
    if (c == 0) red_against_blue = quantile(elementErrors(ref, ref.channel_seen[2], f), 0.5);
    std::cout << "[ measured ] reading lens channel " << c << ": median " << quantile(e[size_t(c)], 0.5) << "' over "
              << e[size_t(c)].size() << " px\n";
    ASSERT_GT(e[size_t(c)].size(), 500u);
    EXPECT_LE(quantile(e[size_t(c)], 0.5), 0.05) << "channel " << c;
  }
  std::cout << "[ measured ] red against the reference's blue: median " << red_against_blue << "'\n";
  EXPECT_GE(red_against_blue, 4.0);
  const StageTiming* cc = green.stages.find("colour-channels");
  ASSERT_TRUE(cc);
  EXPECT_TRUE(cc->ran);
  EXPECT_EQ(cc->count, 3);
}

// Total internal reflection (the plano-convex lens of lens_types_test.cpp, 36 mm across, R = 20 mm, 12 mm
// thick): beyond 13.4 mm from the axis the rays reflect off the curved back and leave through the plane front
// towards the wall behind the eye, most after a second reflection off the back's far side. The shader follows
// them inside the glass as the tracer does: in the ring 14.9 to 16.3 mm, where every ray is reflected, the
// impostor sees the reference's points (measured: median 0.11', mean colour error 4e-5 of the colour). A
// search that stopped at the root where a reflected ray leaves the back surface (t = 0) drew the ring dark.
TEST_P(ImpostorTest, TotalInternalReflectionFollowedInsideTheGlass) {
  const auto ctx = test::glContextOrFail(GetParam());
  if (!ctx) return;
  const Vec3 eye(0, 0, 2.5);
  Scene s = test::roomScene(eye, Vec3(0, 0, -3), 160, 120);
  s.observer.fov_y_rad = radians(8);
  const cad::Outline disc = cad::Outline::circle(0.036);
  Element e;
  e.name = "plano-convex";
  e.type = ElementType::Lens;
  e.lens = cad::makeLens(cad::makePlane(disc), cad::makeSphere(-0.02, disc), disc, 0.012, 0.0, "plano-convex");
  e.outline = disc;
  e.local_to_world = test::pose(Vec3(0, 0, 2.0), Vec3(0, 0, 1));
  e.world_to_local = glm::inverse(e.local_to_world);
  e.dispersion = Dispersion::constant(1.5);
  e.tess_u = e.tess_v = 24;
  s.elements.push_back(e);
  s.updateBounds();
  RayScene rays(s);
  TraceOptions to;
  to.max_depth = s.render.max_depth;
  const TracedFrame ref = Tracer(rays, to).render();
  gl::RendererOptions o;
  o.map_size = 512;
  const gl::RasterFrame f = gl::Renderer(s, rays, o).render(gl::RasterMode::Impostor);
  expectFinite(f);
  const Vec3 axis_point(0, 0, 2.0);
  std::vector<double> angles;
  double err = 0, ref_sum = 0;
  size_t behind = 0;
  for (size_t i = 0; i < ref.color.size(); ++i) {
    if (ref.element[i] < 0 || f.element[i] < 0) continue;
    const double h = glm::length(Vec2(ref.element_point[i] - axis_point));
    if (h < 0.0149 || h > 0.0163) continue;
    behind += std::abs(ref.seen[i].z - 3.0) < 1e-6;
    angles.push_back(arcminutes(angleBetween(ref.seen[i] - ref.element_point[i], f.seen[i] - ref.element_point[i])));
    const Vec3 d = glm::abs(f.color[i] - ref.color[i]);
    err += (d.x + d.y + d.z) / 3;
    ref_sum += (ref.color[i].x + ref.color[i].y + ref.color[i].z) / 3;
  }
  std::sort(angles.begin(), angles.end());
  std::cout << "[ measured ] TIR ring: " << angles.size() << " px (" << behind << " seeing the wall behind the eye), median "
            << quantile(angles, 0.5) << "', mean colour error " << err / double(angles.size()) << " of "
            << ref_sum / double(angles.size()) << "\n";
  ASSERT_GT(angles.size(), 300u);
  EXPECT_GT(behind, angles.size() / 2);  // the ring does show the reflected light
  EXPECT_LE(quantile(angles, 0.5), 1.0);
  EXPECT_LE(err, 0.01 * ref_sum);
}

PVRR_GL_BACKENDS(ImpostorTest);

}  // namespace
}  // namespace pvrr
