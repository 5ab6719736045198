// The progressive (freeform NURBS) lens of models/progressive-lens.json in pvrr mode against the reference
// tracer, on OSMesa and on EGL, at 160 x 120.
#include <gtest/gtest.h>

#include <cmath>

#include <algorithm>
#include <iostream>
#include <vector>

#include "pvrr/gl/context.h"
#include "pvrr/gl/renderer.h"
#include "pvrr/scene/scene_build.h"
#include "pvrr/scene/scene_json.h"
#include "pvrr/trace/tracer.h"
#include "support/gl_backends.h"

namespace pvrr {
namespace {

// Issue 6's goal for lenses: median angular error over lens pixels <= 1 arcmin at the default tessellation
// (measured with pvrr compare at 640 x 480: 0.07 arcmin, docs/scene-format.md).
constexpr double kMedianArcmin = 1.0;
// The 95th percentile holds the corridor's ends (where the design's third derivative jumps) and the page's
// silhouette, a few pixels wide at this size: measured 1.8 arcmin at 640 x 480 and at 160 x 120; 5 bounds it.
constexpr double kP95Arcmin = 5.0;
// Lens coverage: pvrr draws the tessellated outline (chords inscribed in the ellipse) and the reference the
// exact one; they could differ only along the rim.
constexpr double kCoverageMismatch = 0.01;

struct Errors {
  double median = 1e9, p95 = 1e9;
  size_t pixels = 0;
};

// Angular error (docs/method.md) over the pixels where the reference sees the lens, in rows [y0, y1).
Errors errors(const Frame& ref, const gl::RasterFrame& f, int y0, int y1) {
  std::vector<double> e;
  for (int y = y0; y < y1; ++y)
    for (int x = 0; x < ref.width; ++x) {
      const size_t i = size_t(y) * size_t(ref.width) + size_t(x);
      if (ref.element[i] < 0) continue;
      const double a = arcminutes(angleBetween(ref.seen[i] - ref.element_point[i], f.seen[i] - ref.element_point[i]));
      EXPECT_TRUE(std::isfinite(a)) << "pixel " << i;
      e.push_back(a);
    }
  Errors r;
  r.pixels = e.size();
  if (e.empty()) return r;
  std::sort(e.begin(), e.end());
  r.median = e[e.size() / 2];
  r.p95 = e[std::min(e.size() - 1, size_t(0.95 * double(e.size())))];
  return r;
}

class FreeformLensTest : public ::testing::TestWithParam<gl::GlBackend> {};

TEST_P(FreeformLensTest, ProgressiveLensMatchesTheReference) {
  const auto ctx = test::glContextOrFail(GetParam());
  if (!ctx) return;
  Scene s = buildScene(loadScene(PVRR_SOURCE_DIR "/models/progressive-lens.json", {"observer.image_size=[160,120]"}));
  RayScene rays(s);
  const Frame ref = Tracer(rays, TraceOptions{}).render();
  gl::Renderer r(s, rays, gl::RendererOptions{});
  const gl::RasterFrame f = r.render(RenderMode::Pvrr);
  const Errors all = errors(ref, f, 0, ref.height);
  // The lens fills the view (its rim is just outside the corners).
  EXPECT_GT(all.pixels, size_t(0.99 * ref.width * ref.height));
  EXPECT_LE(all.median, kMedianArcmin);
  EXPECT_LE(all.p95, kP95Arcmin);
  // Reported separately: the distance zone (upper half, the base sphere) and the corridor and near zone.
  const Errors top = errors(ref, f, 0, ref.height / 2), bottom = errors(ref, f, ref.height / 2, ref.height);
  EXPECT_LE(top.median, kMedianArcmin);
  EXPECT_LE(bottom.median, kMedianArcmin);
  std::cout << "[ measured ] progressive lens 160x120: median " << all.median << "', p95 " << all.p95
            << "' (distance zone " << top.median << "' / " << top.p95 << "', corridor and near zone " << bottom.median
            << "' / " << bottom.p95 << "')\n";
  size_t mismatch = 0;
  for (size_t i = 0; i < ref.element.size(); ++i) mismatch += (ref.element[i] >= 0) != (f.element[i] >= 0);
  EXPECT_LE(double(mismatch), kCoverageMismatch * double(ref.element.size()));
  // No vertex is totally reflected: the file's 56 x 46 mm blank carries the rim rays past the 50 x 40 mm
  // outline; the few seen ones that land beyond it by more than a thin band as seen from the eye leave through the
  // edge (eye_side.h lensEdgeExit), as the reference has them, and are drawn from the tracer.
  ASSERT_EQ(f.elements.size(), 1u);
  size_t edge = 0;
  for (const VertexRay& v : f.elements[0].rays.at(0)) {
    EXPECT_TRUE(v.status != VertexStatus::Tir || v.edge_exit);
    edge += v.edge_exit;
  }
  // At most the grid's rim (212 of the 64 x 64 grid's 252 rim vertices: the grid is refined where the traced
  // directions jump across the band).
  EXPECT_LE(double(edge), 4.0 * std::sqrt(double(f.elements[0].rays.at(0).size())));
}

PVRR_GL_BACKENDS(FreeformLensTest);

}  // namespace
}  // namespace pvrr
