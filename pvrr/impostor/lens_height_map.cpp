#include "pvrr/impostor/lens_height_map.h"

#include <algorithm>
#include <cmath>

#include <tbb/parallel_for.h>

#include "pvrr/base/error.h"
#include "pvrr/base/bilinear.h"

namespace pvrr {

namespace {

// z and the outward normal of one surface at local (x, y). Where the sag is undefined (beyond a sphere's
// radius, in the margin), the point is moved towards the outline's centre until it is defined: the map only
// needs finite, continuous values there, which no ray through the lens reaches.
Vec4 surfaceTexel(const cad::SagSurface& s, const Vec2& centre, Vec2 p, bool back, bool& clamped) {
  clamped = false;
  for (int k = 0; k < 60 && !s.defined(p.x, p.y); ++k) {
    p = centre + 0.9 * (p - centre);
    clamped = true;
  }
  const cad::SurfacePoint sp = s.sample(p.x, p.y, false);
  const Vec3 n = back ? -sp.n : sp.n;
  return Vec4(sp.p.z, n.x, n.y, n.z);
}

}  // namespace

LensHeightMap buildLensHeightMap(const Element& lens, int n) {
  if (lens.type != ElementType::Lens || !lens.lens.front || !lens.lens.back)
    throw Error("buildLensHeightMap: element \"" + lens.name + "\" is not a lens");
  if (n < 8 || n > 8192) throw Error("buildLensHeightMap: map size " + std::to_string(n) + ", expected 8 to 8192");
  const cad::Outline& outline = lens.lens.outline;
  const Vec2 lo = outline.boundsMin(), hi = outline.boundsMax();
  const Vec2 size = hi - lo, margin = kHeightMapMargin * size;
  const Vec2 box0 = lo - margin, extent = size + 2.0 * margin;
  LensHeightMap m;
  // Square texels, n along the longer side.
  const double texel = std::max(extent.x, extent.y) / double(n);
  m.nx = std::max(2, int(std::ceil(extent.x / texel)));
  m.ny = std::max(2, int(std::ceil(extent.y / texel)));
  m.dx = extent.x / double(m.nx);
  m.dy = extent.y / double(m.ny);
  m.x0 = box0.x;
  m.y0 = box0.y;
  const size_t texels = size_t(m.nx) * size_t(m.ny);
  m.front.resize(4 * texels);
  m.back.resize(4 * texels);
  m.inside.resize(texels);
  std::vector<char> clamped(texels, 0);
  const Vec2 centre = outline.centre();
  tbb::parallel_for(0, m.ny, [&](int j) {
    for (int i = 0; i < m.nx; ++i) {
      const size_t k = size_t(j) * size_t(m.nx) + size_t(i);
      const Vec2 p(m.x0 + (i + 0.5) * m.dx, m.y0 + (j + 0.5) * m.dy);
      bool cf = false, cb = false;
      const Vec4 f = surfaceTexel(*lens.lens.front, centre, p, false, cf);
      const Vec4 b = surfaceTexel(*lens.lens.back, centre, p, true, cb);
      for (int c = 0; c < 4; ++c) m.front[4 * k + size_t(c)] = float(f[c]), m.back[4 * k + size_t(c)] = float(b[c]);
      clamped[k] = cf || cb;
      m.inside[k] = outline.contains(p) ? 1.0f : 0.0f;
    }
  });
  m.reach = glm::length(extent);
  m.back_z_min = kInf;
  m.front_z_max = -kInf;
  for (size_t k = 0; k < texels; ++k) {
    m.back_z_min = std::min(m.back_z_min, double(m.back[4 * k]));
    m.front_z_max = std::max(m.front_z_max, double(m.front[4 * k]));
    m.clamped_texels += clamped[k];
  }
  return m;
}

Vec4 sampleHeightMap(const LensHeightMap& m, bool back, double x, double y) {
  // Texel centres at (i + 0.5) texels from the map's corner.
  const Vec4 s = bilinearSample(back ? m.back : m.front, m.nx, m.ny, (x - m.x0) / m.dx - 0.5, (y - m.y0) / m.dy - 0.5);
  const Vec3 nrm = glm::normalize(Vec3(s.y, s.z, s.w));
  return Vec4(s.x, nrm.x, nrm.y, nrm.z);
}

}  // namespace pvrr
