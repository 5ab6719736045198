// Bilinear interpolation of a grid of RGBA float samples, as the impostor shader reads its maps
// (shaders/bilinear.glsl: GL_LINEAR with clamp-to-edge, in float weights). For the maps' CPU twins
// and their tests.
#pragma once
#include <algorithm>
#include <cmath>
#include <vector>

#include "pvrr/base/math.h"

namespace pvrr {

// `rgba`: nx x ny samples of 4 floats, rows of increasing y. (x, y): continuous sample coordinates, sample
// (i, j) at the integers (i, j) (a texture coordinate s is s nx - 0.5); beyond the grid the edge samples hold.
inline Vec4 bilinearSample(const std::vector<float>& rgba, int nx, int ny, double x, double y) {
  const double fx = std::floor(x), fy = std::floor(y), a = x - fx, b = y - fy;
  auto at = [&](double i, double j) {
    const size_t k = 4 * (size_t(std::clamp(int(j), 0, ny - 1)) * size_t(nx) + size_t(std::clamp(int(i), 0, nx - 1)));
    return Vec4(rgba[k], rgba[k + 1], rgba[k + 2], rgba[k + 3]);
  };
  return (1 - a) * (1 - b) * at(fx, fy) + a * (1 - b) * at(fx + 1, fy) + (1 - a) * b * at(fx, fy + 1) +
         a * b * at(fx + 1, fy + 1);
}

}  // namespace pvrr
