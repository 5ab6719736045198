// Issue 6, item 1: a strong plus lens held far from the eye, whose image of the room is real and inverted
// (paper Fig. 13: the outgoing rays cross in a focal region between the lens and the scene), and a minus
// lens, whose image is upright and minified: pvrr mode against the reference tracer on OSMesa and EGL.
//
// Set-up: the room of tests/support/test_scenes.h, the eye 0.5 m in front of a 40 mm lens (n = 1.5, no
// dispersion) looking through it at the far wall 5 m away, a narrow 8 deg field so the lens fills ~70 px.
// +10 D: equiconvex, R = 2 (n - 1) / P = 0.1 m, 5 mm thick; f = 0.1 m, so the wall (5 m) lies far beyond the
// focal length and the eye (0.5 m) beyond the real image (0.1 m from the lens): the eye sees it inverted.
// -10 D: equiconcave R = 0.1 m, 1.5 mm at the centre: a virtual, upright, minified image.
#include <gtest/gtest.h>

#include <algorithm>
#include <iostream>
#include <vector>

#include "cad/lens.h"
#include "pvrr/gl/context.h"
#include "pvrr/gl/renderer.h"
#include "pvrr/trace/tracer.h"
#include "support/test_scenes.h"
#include "support/accuracy.h"
#include "support/gl_backends.h"

namespace pvrr {
namespace {

// Issue 6's bound for lenses at the default tessellation (median over lens pixels).
constexpr double kMedianArcmin = 1.0;
// Orientation: of the lens pixels off the axis by more than a few pixels, the fraction whose seen point lies
// on the expected side of the axis (inverted: opposite to the pixel's offset; upright: the same side).
// Rim pixels whose ray leaves through the edge band may see anything, hence not 1.
constexpr double kOrientedFraction = 0.97;

struct LensCase {
  const char* name;
  double r_front, r_back, thickness;
  bool inverted;
};

// The room seen through a lens with outline `disc` 0.5 m in front of the eye (n = 1.5, no dispersion).
Scene lensScene(const char* name, cad::SagSurfacePtr front, cad::SagSurfacePtr back, double thickness,
                const cad::Outline& disc) {
  return test::roomLensScene(name, front, back, thickness, disc);
}

Scene lensScene(const LensCase& c) {
  const cad::Outline disc = cad::Outline::circle(0.04);
  return lensScene(c.name, cad::makeSphere(c.r_front, disc), cad::makeSphere(c.r_back, disc), c.thickness, disc);
}

class LensTypesTest : public ::testing::TestWithParam<gl::GlBackend> {};

TEST_P(LensTypesTest, InvertingPlusLensAndMinusLensMatchTheReference) {
  const auto ctx = test::glContextOrFail(GetParam());
  if (!ctx) return;
  for (const LensCase& c : {LensCase{"plus 10 D", 0.1, -0.1, 0.005, true}, LensCase{"minus 10 D", -0.1, 0.1, 0.0015, false}}) {
    Scene s = lensScene(c);
    RayScene rays(s);
    const Frame ref = Tracer(rays, TraceOptions{}).render();
    gl::Renderer r(s, rays, gl::RendererOptions{});
    const gl::RasterFrame f = r.render(RenderMode::Pvrr);

    std::vector<double> err;
    size_t off_axis = 0, oriented_ref = 0, oriented_pvrr = 0;
    const double cx = 0.5 * ref.width, cy = 0.5 * ref.height;
    for (int y = 0; y < ref.height; ++y)
      for (int x = 0; x < ref.width; ++x) {
        const size_t i = size_t(y) * size_t(ref.width) + size_t(x);
        if (ref.element[i] < 0) continue;
        ASSERT_TRUE(std::isfinite(f.seen[i].x) && std::isfinite(f.color[i].x)) << c.name << ": pixel " << x << "," << y;
        err.push_back(arcminutes(angleBetween(ref.seen[i] - ref.element_point[i], f.seen[i] - ref.element_point[i])));
        // Horizontal orientation: pixel offset from the axis against the seen point's x (the axis is x = 0).
        const double px = x + 0.5 - cx;
        if (std::abs(px) < 4 || std::abs(y + 0.5 - cy) > 20) continue;
        ++off_axis;
        const double want = c.inverted ? -px : px;
        oriented_ref += want * ref.seen[i].x > 0;
        oriented_pvrr += want * f.seen[i].x > 0;
      }
    ASSERT_GT(err.size(), 2000u) << c.name << ": the lens should fill ~3,800 pixels";
    ASSERT_GT(off_axis, 500u) << c.name;
    std::sort(err.begin(), err.end());
    const double median = err[err.size() / 2], p95 = err[size_t(0.95 * double(err.size()))];
    std::cout << "[ measured ] " << c.name << " on " << gl::glBackendName(GetParam()) << ": median " << median
              << " arcmin, p95 " << p95 << " over " << err.size() << " lens pixels; oriented (reference / pvrr) "
              << double(oriented_ref) / double(off_axis) << " / " << double(oriented_pvrr) / double(off_axis) << "\n";
    EXPECT_LE(median, kMedianArcmin) << c.name;
    EXPECT_GE(double(oriented_ref) / double(off_axis), kOrientedFraction) << c.name << ": the reference";
    EXPECT_GE(double(oriented_pvrr) / double(off_axis), kOrientedFraction) << c.name << ": pvrr";
  }
}

// render.max_depth = 1: the tracer absorbs at the lens's back surface (its second event), so the lens is
// black in the reference; pvrr draws it dark too, without a first pass for it.
TEST_P(LensTypesTest, LensBeyondTheDepthLimitIsDarkLikeTheReference) {
  const auto ctx = test::glContextOrFail(GetParam());
  if (!ctx) return;
  Scene s = lensScene({"plus 10 D", 0.1, -0.1, 0.005, true});
  s.render.max_depth = 1;
  RayScene rays(s);
  TraceOptions to;
  to.max_depth = 1;
  const Frame ref = Tracer(rays, to).render();
  gl::Renderer r(s, rays, gl::RendererOptions{});
  const gl::RasterFrame f = r.render(RenderMode::Pvrr);
  size_t lens = 0, dark_ref = 0, dark_pvrr = 0;
  for (size_t i = 0; i < ref.color.size(); ++i) {
    if (ref.element[i] < 0) continue;
    ++lens;
    dark_ref += glm::length(ref.color[i]) == 0.0;
    dark_pvrr += glm::length(f.color[i]) < 1e-6;
  }
  ASSERT_GT(lens, 2000u);
  EXPECT_EQ(dark_ref, lens);
  EXPECT_GE(double(dark_pvrr), 0.99 * double(lens));  // the tessellated rim may differ by a pixel ring
  const StageTiming* fp = f.stages.find("first-pass");
  ASSERT_NE(fp, nullptr);
  EXPECT_EQ(fp->count, 0) << fp->note;  // no map rendered for a lens drawn dark
}

// Total internal reflection (issue 6, item 1: the lens shows there what the reference shows). A plano-convex
// lens 36 mm across, 12 mm thick, back radius 20 mm, flat side to the eye: a ray entering near the axis meets
// the back at sin(angle) = h / R, beyond the critical angle (1 / 1.5) for h > 13.3 mm, so a ring of the lens
// reflects the light back inside. The tracer follows it (reflected again across the lens, it leaves through
// the front towards the wall behind the eye); pvrr's vertices there are flagged tir and take the tracer's
// colour and seen point for their ray (VertexRay::traced), interpolated towards the map's colours of their
// neighbours. Compared in the ring 14.9 to 16.3 mm from the axis (whole triangles of flagged vertices, the
// rings lie at 13.4, 14.9 and 16.4 mm; clear of the onset of TIR and of the band beyond 16.4 mm where the
// light leaves through the edge, dark in the reference): the mean colour error is a small fraction of the
// colour there (dark, as pvrr drew it before, would be an error of all of it).
TEST_P(LensTypesTest, TotalInternalReflectionShowsWhatTheReferenceShows) {
  const auto ctx = test::glContextOrFail(GetParam());
  if (!ctx) return;
  const cad::Outline disc = cad::Outline::circle(0.036);  // diameter
  Scene s = lensScene("plano-convex", cad::makePlane(disc), cad::makeSphere(-0.02, disc), 0.012, disc);
  RayScene rays(s);
  const Frame ref = test::referenceFrame(rays);
  gl::Renderer r(s, rays, gl::RendererOptions{});
  const gl::RasterFrame f = r.render(RenderMode::Pvrr);
  ASSERT_EQ(f.elements.size(), 1u);
  size_t tir = 0, traced = 0;
  for (const VertexRay& v : f.elements[0].rays[0]) {
    tir += v.status == VertexStatus::Tir;
    traced += v.traced;
  }
  EXPECT_GT(tir, 50u);
  EXPECT_GT(traced, 50u);
  const Vec3 axis_point(0, 0, 2.0);
  double err = 0, ref_sum = 0;
  std::vector<double> angles;
  size_t n = 0;
  for (size_t i = 0; i < ref.color.size(); ++i) {
    if (ref.element[i] < 0 || f.element[i] < 0) continue;
    const double h = glm::length(Vec2(ref.element_point[i] - axis_point));
    if (h < 0.0149 || h > 0.0163) continue;
    ++n;
    const Vec3 d = glm::abs(f.color[i] - ref.color[i]);
    err += (d.x + d.y + d.z) / 3;
    ref_sum += (ref.color[i].x + ref.color[i].y + ref.color[i].z) / 3;
    angles.push_back(arcminutes(angleBetween(ref.seen[i] - ref.element_point[i], f.seen[i] - ref.element_point[i])));
  }
  ASSERT_GT(n, 300u);
  // Where the reference sees the wall behind the eye (z = 3 m) through the reflecting ring, including the
  // triangles that mix reflected and ordinary vertices (13.5 to 16.3 mm): pvrr's seen point, the traced
  // vertices' where they hold most of the weight, lies on that wall too (a mean of points on it), not between
  // it and the lens.
  size_t on_wall = 0, behind = 0;
  for (size_t i = 0; i < ref.color.size(); ++i) {
    if (ref.element[i] < 0 || f.element[i] < 0 || std::abs(ref.seen[i].z - 3.0) > 1e-6) continue;
    const double h = glm::length(Vec2(ref.element_point[i] - axis_point));
    if (h < 0.0135 || h > 0.0163) continue;
    ++behind;
    on_wall += std::abs(f.seen[i].z - 3.0) < 1e-3;
  }
  std::cout << "[ measured ] " << on_wall << " of " << behind << " pixels seeing the wall behind have pvrr's seen point on it\n";
  ASSERT_GT(behind, 300u);
  EXPECT_GE(double(on_wall), 0.75 * double(behind));  // measured 81 %: the rest lie nearer ordinary vertices
  std::sort(angles.begin(), angles.end());
  std::cout << "[ measured ] TIR ring on " << gl::glBackendName(GetParam()) << ": " << n << " pixels, mean colour "
            << ref_sum / double(n) << " (reference), mean error " << err / double(n) << ", seen-point median "
            << angles[angles.size() / 2] << " arcmin\n";
  EXPECT_GT(ref_sum / double(n), 0.02) << "the reference is not dark there: the test compares something";
  // Measured: 5.4 % of the colour (the wall behind the eye, reflected twice inside the lens). The seen points
  // are exact at the vertices but sweep ~0.6 m of wall per millimetre of lens here, which the 1.5 mm triangles
  // interpolate poorly (median ~930'): reported, not bounded.
  EXPECT_LE(err, 0.10 * ref_sum);
}

PVRR_GL_BACKENDS(LensTypesTest);

}  // namespace
}  // namespace pvrr
