// Comparing whole renderer frames, and loading the shipped scenes small, for the tests that check that an
// optimisation leaves every pixel as it was.
#pragma once

#include <gtest/gtest.h>

#include <string>

#include "pvrr/gl/renderer.h"
#include "pvrr/scene_build.h"
#include "pvrr/scene_json.h"

namespace pvrr::test {

// The number of pixels where any output of the two frames differs at all: colour, and where both frames have
// them, seen points, element ids and surface points.
inline size_t differingPixels(const gl::RasterFrame& a, const gl::RasterFrame& b) {
  EXPECT_EQ(a.color.size(), b.color.size());
  const bool seen = !a.seen.empty() && !b.seen.empty();
  size_t n = 0;
  for (size_t i = 0; i < a.color.size() && i < b.color.size(); ++i)
    n += a.color[i] != b.color[i] ||
         (seen && (a.seen[i] != b.seen[i] || a.element[i] != b.element[i] || a.element_point[i] != b.element_point[i]));
  return n;
}

// models/NAME.json at 160 x 120 pixels.
inline Scene shippedScene(const std::string& name) {
  return buildScene(loadScene(std::string(PVRR_SOURCE_DIR) + "/models/" + name + ".json", {"observer.image_size=[160,120]"}));
}

}  // namespace pvrr::test
