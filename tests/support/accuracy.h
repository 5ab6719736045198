// Accuracy metrics shared by the GL tests: a raster frame's seen points against the reference tracer's.
#pragma once
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "pvrr/gl/renderer.h"
#include "pvrr/trace/tracer.h"

namespace pvrr::test {

// Median angular error (arcmin) over the pixels where the reference sees an element: at the reference's
// surface point, the angle between the directions to the frame's seen point and to the reference's (the
// metric of pvrr compare). 1e9 when there are no such pixels; `pixels` (optional) gets their count.
inline double medianArcmin(const TracedFrame& ref, const gl::RasterFrame& f, size_t* pixels = nullptr) {
  std::vector<double> e;
  for (size_t i = 0; i < ref.color.size(); ++i)
    if (ref.element[i] >= 0) {
      const double a = arcminutes(angleBetween(ref.seen[i] - ref.element_point[i], f.seen[i] - ref.element_point[i]));
      EXPECT_TRUE(std::isfinite(a)) << "pixel " << i;
      e.push_back(a);
    }
  if (pixels) *pixels = e.size();
  std::sort(e.begin(), e.end());
  return e.empty() ? 1e9 : e[e.size() / 2];
}

}  // namespace pvrr::test
