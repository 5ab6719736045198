// The raster paths against the reference tracer, on OSMesa and on EGL.
#include <gtest/gtest.h>

#include <algorithm>

#include "pvrr/gl/context.h"
#include "pvrr/gl/renderer.h"
#include "pvrr/tracer.h"
#include "support/test_scenes.h"

namespace pvrr {
namespace {

// The bound for a plane mirror away from depth edges.
constexpr double kPlaneMirrorMaxArcmin = 0.05;
// Seen points of the raster environment vs the tracer: float positions relative to the camera over a
// 6 m room, plus rasterisation at exactly the same pixel centres: 1e-4 m is ~100x the float error.
constexpr double kSeenPointTol_m = 1e-4;
// Colour: identical shading model; llvmpipe filters sRGB textures in 8 bits and the colour buffer is float.
// Mean over pixels away from edges, in linear units.
constexpr double kMeanColourTol = 2e-3;

std::unique_ptr<gl::GlContext> makeContext(gl::GlBackend b) {
  try {
    return gl::GlContext::create(b);
  } catch (const std::exception& e) {
    ADD_FAILURE() << "no GL context: " << e.what();
    return nullptr;
  }
}

// Pixels whose reference seen point is close to all of its 8 neighbours' (no depth edge nearby).
std::vector<bool> awayFromDepthEdges(const TracedFrame& ref, const Vec3& eye) {
  std::vector<bool> ok(ref.seen.size(), false);
  for (int y = 1; y + 1 < ref.height; ++y)
    for (int x = 1; x + 1 < ref.width; ++x) {
      const size_t i = size_t(y) * size_t(ref.width) + size_t(x);
      const double dist = glm::length(ref.seen[i] - eye);
      bool smooth = true;
      for (int dy = -1; dy <= 1 && smooth; ++dy)
        for (int dx = -1; dx <= 1 && smooth; ++dx) {
          const size_t j = size_t(y + dy) * size_t(ref.width) + size_t(x + dx);
          if (glm::length(ref.seen[j] - ref.seen[i]) > 0.05 * dist || ref.element[j] != ref.element[i]) smooth = false;
        }
      ok[i] = smooth;
    }
  return ok;
}

class RendererTest : public ::testing::TestWithParam<gl::GlBackend> {};

TEST_P(RendererTest, RasterEnvironmentMatchesTheTracer) {
  auto ctx = makeContext(GetParam());
  if (!ctx) return;
  Scene s = test::roomScene(Vec3(0.3, 0.2, 2.0), Vec3(0, -0.2, 0));
  RayScene rays(s);
  TracedFrame ref = Tracer(rays, TraceOptions{}).render();
  gl::Renderer r(s, rays, gl::RendererOptions{});
  gl::RasterFrame f = r.render(gl::RasterMode::Raster);
  ASSERT_EQ(f.color.size(), ref.color.size());
  const std::vector<bool> smooth = awayFromDepthEdges(ref, s.observer.eye);
  double colour_sum = 0;
  size_t n = 0;
  for (size_t i = 0; i < ref.color.size(); ++i) {
    if (!smooth[i]) continue;
    EXPECT_LT(glm::length(f.seen[i] - ref.seen[i]), kSeenPointTol_m) << "pixel " << i;
    colour_sum += glm::length(f.color[i] - ref.color[i]) / std::sqrt(3.0);
    ++n;
  }
  ASSERT_GT(n, ref.color.size() / 2);
  EXPECT_LT(colour_sum / double(n), kMeanColourTol);
}

TEST_P(RendererTest, PlaneMirrorPvrrIsExactAwayFromDepthEdges) {
  auto ctx = makeContext(GetParam());
  if (!ctx) return;
  Scene s = test::roomScene(Vec3(0.3, 0.2, 2.0), Vec3(0, 0, 0));
  const cad::Outline outline = cad::Outline::rectangle(1.2, 0.9, 0.1);
  test::addMirror(s, cad::makePlane(outline), outline, test::pose(Vec3(0, 0, -0.5), Vec3(0, 0, 1)), 7, 0.9);
  s.updateBounds();
  RayScene rays(s);
  TracedFrame ref = Tracer(rays, TraceOptions{}).render();
  gl::RendererOptions opt;
  opt.map_size = 512;
  gl::Renderer r(s, rays, opt);
  gl::RasterFrame f = r.render(gl::RasterMode::Pvrr);
  const std::vector<bool> smooth = awayFromDepthEdges(ref, s.observer.eye);
  size_t mirror_pixels = 0;
  double worst = 0;
  for (size_t i = 0; i < ref.color.size(); ++i) {
    if (ref.element[i] != 0 || !smooth[i]) continue;
    ++mirror_pixels;
    ASSERT_EQ(f.element[i], 0) << "pixel " << i;
    worst = std::max(worst, arcminutes(angleBetween(ref.seen[i] - ref.element_point[i], f.seen[i] - ref.element_point[i])));
  }
  EXPECT_GT(mirror_pixels, 500u);
  EXPECT_LE(worst, kPlaneMirrorMaxArcmin);
  // The stages the issue names ran.
  for (const char* name : {"vertex-rays", "viewpoint-fit", "first-pass", "second-pass"}) {
    auto it = std::find_if(f.stages.stages.begin(), f.stages.stages.end(), [&](const StageTiming& t) { return t.name == name; });
    ASSERT_NE(it, f.stages.stages.end()) << name;
    EXPECT_TRUE(it->ran) << name;
  }
}

TEST_P(RendererTest, ConvexMirrorPvrrBeatsTheCubeMap) {
  auto ctx = makeContext(GetParam());
  if (!ctx) return;
  Scene s = test::roomScene(Vec3(0.3, 0.2, 1.2), Vec3(0, 0, 0), 120, 90);
  const cad::Outline outline = cad::Outline::rectangle(0.5, 0.4, 0.05);
  test::addMirror(s, cad::makeSphere(1.0, outline), outline, test::pose(Vec3(0, 0, -0.3), Vec3(0, 0, 1)), 15, 0.9);
  s.updateBounds();
  RayScene rays(s);
  TracedFrame ref = Tracer(rays, TraceOptions{}).render();
  gl::RendererOptions opt;
  opt.map_size = 512;
  gl::Renderer r(s, rays, opt);
  auto medianError = [&](const gl::RasterFrame& f) {
    std::vector<double> e;
    for (size_t i = 0; i < ref.color.size(); ++i) {
      if (ref.element[i] != 0) continue;
      const double a = arcminutes(angleBetween(ref.seen[i] - ref.element_point[i], f.seen[i] - ref.element_point[i]));
      EXPECT_TRUE(std::isfinite(a));
      e.push_back(a);
    }
    std::sort(e.begin(), e.end());
    return e.empty() ? 1e9 : e[e.size() / 2];
  };
  const double pvrr = medianError(r.render(gl::RasterMode::Pvrr));
  const double envmap = medianError(r.render(gl::RasterMode::Envmap));
  EXPECT_LT(pvrr, 1.0);
  EXPECT_LT(pvrr * 3, envmap) << "pvrr " << pvrr << "', envmap " << envmap << "'";
  for (const Vec3& c : r.render(gl::RasterMode::Pvrr).color) ASSERT_TRUE(isFinite(c));
}

INSTANTIATE_TEST_SUITE_P(Backends, RendererTest, ::testing::Values(gl::GlBackend::OsMesa, gl::GlBackend::Egl),
                         [](const auto& info) { return info.param == gl::GlBackend::OsMesa ? "OsMesa" : "Egl"; });

}  // namespace
}  // namespace pvrr
