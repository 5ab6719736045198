// Accuracy for the GL tests: a raster frame's seen points against the reference tracer's, with the metric of
// pvrr compare (pvrr/analysis/accuracy.h).
#pragma once
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "pvrr/gl/renderer.h"
#include "pvrr/trace/tracer.h"
#include "pvrr/analysis/accuracy.h"
#include "pvrr/base/frame.h"

namespace pvrr::test {

// The reference picture of `rays`'s scene at the scene's depth limit: what every accuracy test compares with
// (no dispersion, no caustic light; tests that need them set their own TraceOptions).
inline Frame referenceFrame(const RayScene& rays) {
  TraceOptions to;
  to.max_depth = rays.scene().render.max_depth;
  return Tracer(rays, to).render();
}

// The median angular error (arcmin; pvrr/analysis/accuracy.h: for an even count the mean of the two middle errors) over
// the pixels where the reference sees an element (and its path did not end at the depth limit). Every such pixel must
// have a finite error (a test failure names each that does not). 1e9 when no pixel has one or the frame has no seen
// points (a failure); `pixels` (optional) gets the count of finite errors.
inline double medianArcmin(const Frame& ref, const Frame& f, size_t* pixels = nullptr) {
  if (f.seen.size() != ref.seen.size()) {
    ADD_FAILURE() << "the frame has " << f.seen.size() << " seen points, the reference " << ref.seen.size();
    return 1e9;
  }
  const std::vector<double> e = angularErrors(ref, ref.seen, f.seen);
  for (size_t i = 0; i < e.size(); ++i) {
    if (ref.element[i] < 0 || depthLimited(ref, i)) continue;  // no seen point: no angular error
    EXPECT_TRUE(std::isfinite(e[i])) << "pixel " << i;
  }
  const ErrorStats s = summarizeErrors(e);
  if (pixels) *pixels = s.pixels;
  return s.pixels == 0 ? 1e9 : s.median_arcmin;
}

}  // namespace pvrr::test
