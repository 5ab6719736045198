// mapFootprint (pvrr/method/map_footprint.h): every texel that a bilinear fetch at a point of a triangle can read is
// open; texels well away from every triangle are closed; a non-finite coordinate opens the whole map.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include "pvrr/method/map_footprint.h"

namespace pvrr {
namespace {

// The texels a bilinear fetch for texel-space point (x, y) reads with GL_LINEAR: the point is first clamped to
// the centres of the edge texels (the texture's clamp to edge below, the second pass's u_st_max above), then
// the 2 x 2 block whose centres surround it, from i0 = floor(x - 0.5). A texel past the region's far edge
// (weight 0 there) is not the pass's to draw.
void expectFetchOpen(const MapFootprint& fp, double x, double y, const std::string& what) {
  x = std::clamp(x, 0.5, fp.width - 0.5);
  y = std::clamp(y, 0.5, fp.height - 0.5);
  const int i0 = int(std::floor(x - 0.5)), j0 = int(std::floor(y - 0.5));
  for (int j = j0; j <= j0 + 1 && j < fp.height; ++j)
    for (int i = i0; i <= i0 + 1 && i < fp.width; ++i)
      ASSERT_TRUE(fp.open(i, j)) << what << ": a fetch at (" << x << ", " << y << ") reads texel (" << i << ", " << j
                                 << "), which is closed";
}

TEST(MapFootprint, OpensEveryTexelThatAFetchInsideATriangleReads) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> coord(-0.1, 1.1), unit(0.0, 1.0);
  for (int trial = 0; trial < 40; ++trial) {
    const int w = 40 + trial * 7, h = 30 + trial * 5, band = 1 + trial % 5;
    // A few small triangles (a tessellation's size) and a thin sliver, over two channels.
    std::vector<std::vector<Vec2>> st(2);
    std::vector<glm::u32vec3> tris;
    for (int t = 0; t < 6; ++t) {
      const Vec2 c(coord(rng), coord(rng));
      for (auto& ch : st) {
        for (int k = 0; k < 3; ++k) ch.push_back(c + 0.08 * Vec2(unit(rng) - 0.5, unit(rng) - 0.5));
      }
      tris.push_back({uint32_t(3 * t), uint32_t(3 * t + 1), uint32_t(3 * t + 2)});
    }
    st[0][0] = Vec2(0.2, 0.3), st[0][1] = Vec2(0.8, 0.3004), st[0][2] = Vec2(0.5, 0.3002);  // a sliver
    const MapFootprint fp = mapFootprint(st, tris, w, h, band);
    ASSERT_FALSE(fp.all);
    for (const auto& ch : st)
      for (const glm::u32vec3& t : tris) {
        const Vec2 a = ch[t.x] * Vec2(w, h), b = ch[t.y] * Vec2(w, h), c = ch[t.z] * Vec2(w, h);
        // Corners, edge points and interior points.
        for (int k = 0; k < 200; ++k) {
          double u = unit(rng), v = unit(rng);
          if (k < 3) u = (k == 1), v = (k == 2);
          if (u + v > 1) u = 1 - u, v = 1 - v;
          const Vec2 p = a + u * (b - a) + v * (c - a);
          expectFetchOpen(fp, p.x, p.y, "trial " + std::to_string(trial));
        }
      }
  }
}

TEST(MapFootprint, ClosesTexelsAwayFromTheTriangles) {
  // One triangle of the map's lower-left quarter, corners (0, 0), (0.5, 0), (0, 0.5), on 100 x 100 in rows.
  const std::vector<std::vector<Vec2>> st = {{Vec2(0.0, 0.0), Vec2(0.5, 0.0), Vec2(0.0, 0.5)}};
  const MapFootprint fp = mapFootprint(st, {glm::u32vec3(0, 1, 2)}, 100, 100, 1, 2.0);
  ASSERT_FALSE(fp.all);
  for (int y = 0; y < 100; ++y) {
    // Row y is reached from points with y + 0.5 - 2 < py < y + 0.5 + 2; the farthest x there is the
    // hypotenuse x = 50 - py at the lowest such py; columns x with x + 0.5 < that + 2 open.
    const double py = std::max(0.0, y + 0.5 - 2.0);
    const double reach = 50.0 - py;
    if (py > 50.0) {
      EXPECT_GE(fp.spans[size_t(y)][0], fp.spans[size_t(y)][1]) << "row " << y << " is beyond the triangle";
      continue;
    }
    EXPECT_EQ(fp.spans[size_t(y)][0], 0) << "row " << y;
    // (One more where the slab's edge meets the hypotenuse at a texel boundary, in rounding.)
    const int end = int(std::ceil(reach + 2.0 - 0.5));
    EXPECT_GE(fp.spans[size_t(y)][1], end) << "row " << y;
    EXPECT_LE(fp.spans[size_t(y)][1], end + 1) << "row " << y;
  }
  EXPECT_FALSE(fp.open(60, 10));
  EXPECT_FALSE(fp.open(30, 40));
  EXPECT_TRUE(fp.open(20, 20));
  // About an eighth of the map, widened by two texels along the hypotenuse.
  EXPECT_GT(fp.openTexels(), 1250);
  EXPECT_LT(fp.openTexels(), 1250 + 2 * 71 * 3 + 100);
  // Bands of 8 rows: the hull of those rows, still a subset of the map.
  const MapFootprint banded = mapFootprint(st, {glm::u32vec3(0, 1, 2)}, 100, 100, 8, 2.0);
  for (int y = 0; y < 100; ++y)
    for (int x = 0; x < 100; ++x)
      if (fp.open(x, y)) {
        EXPECT_TRUE(banded.open(x, y)) << x << ", " << y;
      }
  EXPECT_LT(banded.openTexels(), 100 * 100 / 3);
}

TEST(MapFootprint, NonFiniteCoordinatesOpenEverythingAndNoTrianglesNothing) {
  std::vector<std::vector<Vec2>> st = {{Vec2(0.1, 0.1), Vec2(0.2, 0.1), Vec2(0.1, std::numeric_limits<double>::quiet_NaN())}};
  const MapFootprint nan = mapFootprint(st, {glm::u32vec3(0, 1, 2)}, 64, 48);
  EXPECT_TRUE(nan.all);
  EXPECT_EQ(nan.openTexels(), 64 * 48);
  EXPECT_TRUE(nan.open(63, 47));
  st[0][2] = Vec2(0.1, 0.2);
  const MapFootprint none = mapFootprint(st, {}, 64, 48);
  EXPECT_FALSE(none.all);
  EXPECT_EQ(none.openTexels(), 0);
  // Coordinates beyond the map's right edge are fetched at the edge texels' centres (the second pass clamps
  // them there): the last two columns open on the rows beside the triangle, nothing else.
  const MapFootprint outside = mapFootprint({{Vec2(1.2, 0.5), Vec2(1.3, 0.5), Vec2(1.2, 0.6)}}, {glm::u32vec3(0, 1, 2)}, 64, 48);
  EXPECT_TRUE(outside.open(63, 26));
  EXPECT_TRUE(outside.open(62, 26));
  EXPECT_FALSE(outside.open(61, 26));
  EXPECT_FALSE(outside.open(63, 10));
  EXPECT_LE(outside.openTexels(), 2 * 16);
}

}  // namespace
}  // namespace pvrr
