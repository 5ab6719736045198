// The texels of a first-pass map that its reader can fetch (beyond the paper: the renderer leaves the others
// unshaded).
//
// A map is read only where the element's triangles, drawn with their vertices' texture coordinates, put
// samples: a fragment's (s, t) is a convex combination of its triangle's corner coordinates (the projective
// (s q, t q, q) interpolation divides by a positive q, so the weights stay non-negative), and a bilinear fetch
// at a point reads the texels whose centres lie within one texel of it on each axis. The footprint is
// therefore every texel centre within one texel (L-infinity) of some triangle, with a safety margin for the
// float arithmetic of both passes. A car mirror's warped image covers about three quarters of the rectangle of
// its view volume; the rest of the map need not be drawn.
//
// The footprint is kept per band of rows as one span per band: the hull, along the band, of every triangle's
// part in it. A superset of the texels needed (concave outlines leave their hollow open), never a subset.
//
// Conventions: (s, t) in [0, 1]^2 of the map's view volume (pvrr/method/view_volume.h); the map renders width x height
// texels; texel (x, y) has its centre at ((x + 0.5) / width, (y + 0.5) / height); row 0 is the bottom (t = 0).
#pragma once
#include <array>
#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>

#include "pvrr/base/math.h"

namespace pvrr {

struct MapFootprint {
  int width = 0, height = 0;
  int band = 1;  // rows per band; band b holds rows [b * band, min((b + 1) * band, height))
  // Per band: the open columns [x0, x1) (x0 >= x1: none). Empty when `all`.
  std::vector<std::array<int, 2>> spans;
  // Every texel may be read (a non-finite coordinate, or nothing to go by): draw the whole map.
  bool all = true;

  // Whether texel (x, y) is in the footprint.
  bool open(int x, int y) const;
  // Texels in the footprint (width * height when `all`).
  int64_t openTexels() const;
};

// The footprint of the triangles (corner indices into each channel's coordinates) over all channels of
// `st` ([channel][vertex]), on a width x height map, in bands of `band` rows, widened by `margin` texels
// (>= 1: one for the bilinear neighbourhood; the default adds one for rounding). A coordinate that is not
// finite gives `all`.
MapFootprint mapFootprint(const std::vector<std::vector<Vec2>>& st, const std::vector<glm::u32vec3>& triangles,
                          int width, int height, int band = 4, double margin = 2.0);

}  // namespace pvrr
