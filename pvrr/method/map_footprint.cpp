#include "pvrr/method/map_footprint.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "pvrr/base/error.h"

namespace pvrr {

bool MapFootprint::open(int x, int y) const {
  if (x < 0 || y < 0 || x >= width || y >= height) return false;
  if (all) return true;
  const std::array<int, 2>& s = spans[size_t(y / band)];
  return x >= s[0] && x < s[1];
}

int64_t MapFootprint::openTexels() const {
  if (all) return int64_t(width) * height;
  int64_t n = 0;
  for (size_t b = 0; b < spans.size(); ++b) {
    const int rows = std::min(int(b + 1) * band, height) - int(b) * band;
    n += int64_t(std::max(0, spans[b][1] - spans[b][0])) * rows;
  }
  return n;
}

namespace {

// Extends [lo, hi] by the x extent of the part of triangle (a, b, c) with ya <= y <= yb (texel units).
void slabExtent(const Vec2& a, const Vec2& b, const Vec2& c, double ya, double yb, double* lo, double* hi) {
  auto take = [&](double x) {
    *lo = std::min(*lo, x);
    *hi = std::max(*hi, x);
  };
  const Vec2* v[3] = {&a, &b, &c};
  for (int i = 0; i < 3; ++i) {
    const Vec2 &p = *v[i], &q = *v[(i + 1) % 3];
    if (p.y >= ya && p.y <= yb) take(p.x);
    // Where the edge crosses each of the slab's bounding lines (an edge along a line adds its end points
    // above).
    for (const double y : {ya, yb}) {
      if ((p.y - y) * (q.y - y) < 0) take(p.x + (q.x - p.x) * ((y - p.y) / (q.y - p.y)));
    }
  }
}

}  // namespace

MapFootprint mapFootprint(const std::vector<std::vector<Vec2>>& st, const std::vector<glm::u32vec3>& triangles,
                          int width, int height, int band, double margin) {
  PVRR_CHECK(width > 0 && height > 0 && band > 0 && margin >= 1, << width << "x" << height << " band " << band
                                                                   << " margin " << margin);
  MapFootprint fp;
  fp.width = width;
  fp.height = height;
  fp.band = band;
  for (const std::vector<Vec2>& channel : st)
    for (const Vec2& p : channel)
      if (!std::isfinite(p.x) || !std::isfinite(p.y)) return fp;  // all
  fp.all = false;
  const int bands = (height + band - 1) / band;
  std::vector<std::array<double, 2>> extent(size_t(bands), {kInf, -kInf});
  for (const std::vector<Vec2>& channel : st) {
    for (const glm::u32vec3& t : triangles) {
      PVRR_CHECK(t.x < channel.size() && t.y < channel.size() && t.z < channel.size(),
                 << "triangle (" << t.x << ", " << t.y << ", " << t.z << ") of " << channel.size() << " vertices");
      const Vec2 scale(width, height);
      const Vec2 a = channel[t.x] * scale, b = channel[t.y] * scale, c = channel[t.z] * scale;
      // Fetches happen at the point clamped to the centres of the edge texels ([0.5, width - 0.5] on x: the
      // texture's clamp to edge below, the second pass's u_st_max above; likewise on y). Rows a fetch from
      // the triangle can reach: |y + 0.5 - clamped p.y| < margin.
      const double y_lo = std::clamp(std::min({a.y, b.y, c.y}), 0.5, height - 0.5);
      const double y_hi = std::clamp(std::max({a.y, b.y, c.y}), 0.5, height - 0.5);
      const int row_lo = std::max(0, int(std::floor(y_lo - margin - 0.5)) + 1);
      const int row_hi = std::min(height - 1, int(std::ceil(y_hi + margin - 0.5)) - 1);
      for (int bi = row_lo / band; bi <= row_hi / band; ++bi) {
        // The band's rows [r0, r1) are reached from clamped points with r0 + 0.5 - margin < y < r1 - 0.5 +
        // margin; a band that reaches an edge row's centre takes every point beyond that edge too.
        const int r0 = bi * band, r1 = std::min(r0 + band, height);
        const double ya = r0 + 0.5 - margin < 0.5 ? -kInf : r0 + 0.5 - margin;
        const double yb = r1 - 0.5 + margin > height - 0.5 ? kInf : r1 - 0.5 + margin;
        auto& e = extent[size_t(bi)];
        slabExtent(a, b, c, ya, yb, &e[0], &e[1]);
      }
    }
  }
  fp.spans.resize(size_t(bands));
  for (int bi = 0; bi < bands; ++bi) {
    const auto& e = extent[size_t(bi)];
    if (e[0] > e[1]) {
      fp.spans[size_t(bi)] = {0, 0};
      continue;
    }
    // Columns x with |x + 0.5 - p.x| < margin for some clamped p.x in [e0, e1].
    const double e0 = std::clamp(e[0], 0.5, width - 0.5), e1 = std::clamp(e[1], 0.5, width - 0.5);
    const double x0 = std::max(0.0, std::floor(e0 - margin - 0.5) + 1), x1 = std::min(double(width), std::ceil(e1 + margin - 0.5));
    fp.spans[size_t(bi)] = {int(x0), int(std::max(x0, x1))};
  }
  return fp;
}

}  // namespace pvrr
