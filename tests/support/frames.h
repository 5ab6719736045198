// Comparing whole renderer frames, for the tests that check that an optimisation leaves every pixel as it was.
#pragma once

#include <gtest/gtest.h>

#include <string>

#include "pvrr/gl/renderer.h"

namespace pvrr::test {

// Whether any output of the two frames differs at pixel i: colour, seen point, element id, surface point.
inline bool pixelDiffers(const gl::RasterFrame& a, const gl::RasterFrame& b, size_t i) {
  return a.color[i] != b.color[i] || a.seen[i] != b.seen[i] || a.element[i] != b.element[i] ||
         a.element_point[i] != b.element_point[i];
}

// The number of pixels where any output of two frames with seen points differs at all (every pixel, after a
// failed expectation, when a frame lacks them).
inline size_t differingPixels(const gl::RasterFrame& a, const gl::RasterFrame& b) {
  EXPECT_EQ(a.color.size(), b.color.size());
  for (const gl::RasterFrame* f : {&a, &b}) {
    const bool complete = f->seen.size() == f->color.size() && f->element.size() == f->color.size() &&
                          f->element_point.size() == f->color.size();
    EXPECT_TRUE(complete) << "seen points are needed for the comparison";
    if (!complete) return a.color.size();
  }
  size_t n = 0;
  for (size_t i = 0; i < a.color.size() && i < b.color.size(); ++i) n += pixelDiffers(a, b, i);
  return n;
}

}  // namespace pvrr::test
