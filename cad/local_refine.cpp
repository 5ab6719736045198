// Local refinement of a grid tessellation: a restricted quadtree over the grid's quads.
//
// All vertices live on one integer lattice over the parameter square: base vertex (i, j) at (i R, j R) with
// R = 2^(L + 1), L the finest level, so that every sub-quad of every level (and its centre, for the transition
// fans) has integer corners. A vertex is identified by its lattice point alone, so two quads that meet on an
// edge use the same vertex for each point of it, and a sub-quad's triangulation takes every lattice vertex
// that either side puts on its edges: the mesh is conforming by construction.
#include "cad/local_refine.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <string>
#include <unordered_map>

#include "pvrr/base/error.h"

namespace pvrr::cad {
namespace {

// Above this many new vertices they are evaluated in parallel.
constexpr size_t kParallelVertices = 512;

void checkLevels(int gu, int gv, const std::vector<uint8_t>& levels) {
  if (gu < 2 || gv < 2)
    throw Error("local refinement: not a grid (" + std::to_string(gu) + " x " + std::to_string(gv) + " vertices)");
  if (levels.size() != size_t(gu - 1) * size_t(gv - 1))
    throw Error("local refinement: " + std::to_string(levels.size()) + " quad levels for a grid of " +
                std::to_string(gu - 1) + " x " + std::to_string(gv - 1) + " quads");
  for (uint8_t l : levels)
    if (l > kMaxLocalLevel)
      throw Error("local refinement: level " + std::to_string(int(l)) + " above the finest, " +
                  std::to_string(kMaxLocalLevel));
}

// The conforming triangulation on the lattice, before any surface evaluation.
class Builder {
 public:
  Builder(int gu, int gv, const std::vector<uint8_t>& levels) : gu_(gu), gv_(gv), levels_(levels) {
    int l_max = 0;
    for (uint8_t l : levels_) l_max = std::max(l_max, int(l));
    r_ = int64_t(1) << (l_max + 1);
    const size_t n_grid = size_t(gu) * size_t(gv);
    for (int i = 0; i + 1 < gu_; ++i)
      for (int j = 0; j + 1 < gv_; ++j) quad(i, j, n_grid);
  }

  int64_t r_;
  std::vector<std::array<int64_t, 2>> extra;  // lattice point of appended vertex k (index n_grid + k)
  std::vector<Triangle> triangles;            // counter-clockwise in the lattice (i along x, j along y)
  std::vector<uint32_t> quads;

 private:
  int level(int i, int j) const {
    if (i < 0 || j < 0 || i + 1 >= gu_ || j + 1 >= gv_) return -1;
    return levels_[size_t(i) * size_t(gv_ - 1) + size_t(j)];
  }

  uint32_t vertex(int64_t x, int64_t y, size_t n_grid) {
    if (x % r_ == 0 && y % r_ == 0) return uint32_t((x / r_) * gv_ + y / r_);
    const uint64_t key = (uint64_t(x) << 32) | uint64_t(y);
    auto [it, fresh] = index_.emplace(key, uint32_t(n_grid + extra.size()));
    if (fresh) extra.push_back({x, y});
    return it->second;
  }

  void quad(int i, int j, size_t n_grid) {
    const int l = level(i, j);
    const int64_t step = r_ >> l, n = int64_t(1) << l;
    const int64_t bx = i * r_, by = j * r_;
    const uint32_t q = uint32_t(i * (gv_ - 1) + j);
    std::vector<uint32_t> ring;
    // The lattice points that a finer neighbour (nb) puts strictly inside a sub-quad edge from (x0, y0) to
    // (x1, y1), in that direction.
    auto edge = [&](int nb, int64_t x0, int64_t y0, int64_t x1, int64_t y1) {
      if (nb <= l) return;
      const int64_t s = r_ >> nb;
      const int64_t dx = x1 > x0 ? s : (x1 < x0 ? -s : 0), dy = y1 > y0 ? s : (y1 < y0 ? -s : 0);
      for (int64_t x = x0 + dx, y = y0 + dy; x != x1 || y != y1; x += dx, y += dy) ring.push_back(vertex(x, y, n_grid));
    };
    for (int64_t a = 0; a < n; ++a)
      for (int64_t b = 0; b < n; ++b) {
        const int64_t x0 = bx + a * step, y0 = by + b * step, x1 = x0 + step, y1 = y0 + step;
        const uint32_t c0 = vertex(x0, y0, n_grid), c1 = vertex(x1, y0, n_grid), c2 = vertex(x1, y1, n_grid),
                       c3 = vertex(x0, y1, n_grid);
        ring.clear();
        ring.push_back(c0);
        if (b == 0) edge(level(i, j - 1), x0, y0, x1, y0);
        ring.push_back(c1);
        if (a == n - 1) edge(level(i + 1, j), x1, y0, x1, y1);
        ring.push_back(c2);
        if (b == n - 1) edge(level(i, j + 1), x1, y1, x0, y1);
        ring.push_back(c3);
        if (a == 0) edge(level(i - 1, j), x0, y1, x0, y0);
        const size_t m = ring.size();
        if (m == 4) {  // the grid's own diagonal, (i, j)-(i+1, j+1)
          emit(c0, c1, c2, q);
          emit(c0, c2, c3, q);
        } else if (m == 5) {  // one finer vertex: a fan from it over the other four
          size_t k = 0;
          while (ring[k] == c0 || ring[k] == c1 || ring[k] == c2 || ring[k] == c3) ++k;
          for (size_t t = 1; t <= 3; ++t) emit(ring[k], ring[(k + t) % m], ring[(k + t + 1) % m], q);
        } else {  // a fan from the sub-quad's centre
          const uint32_t c = vertex(x0 + step / 2, y0 + step / 2, n_grid);
          for (size_t t = 0; t < m; ++t) emit(c, ring[t], ring[(t + 1) % m], q);
        }
      }
  }

  void emit(uint32_t a, uint32_t b, uint32_t c, uint32_t q) {
    triangles.emplace_back(a, b, c);
    quads.push_back(q);
  }

  int gu_, gv_;
  const std::vector<uint8_t>& levels_;
  std::unordered_map<uint64_t, uint32_t> index_;
};

// As tessellate.cpp's: square coordinates [-1, 1]^2 to parameters, through the outline or onto the domain.
Vec2 squareToParams(const Surface& s, const Outline* outline, Vec2 sq) {
  if (outline) return outline->fromSquare(sq);
  const ParamDomain dom = s.domain();
  auto lerp = [](double a, double b, double t) { return t >= 1 ? b : (t <= -1 ? a : a + (b - a) * 0.5 * (t + 1)); };
  return {lerp(dom.u0, dom.u1, sq.x), lerp(dom.v0, dom.v1, sq.y)};
}

}  // namespace

std::vector<uint8_t> balanceQuadLevels(int grid_u, int grid_v, std::vector<uint8_t> levels) {
  checkLevels(grid_u, grid_v, levels);
  const int qu = grid_u - 1, qv = grid_v - 1;
  // A raised quad can only raise its neighbours to one below itself: passes until nothing changes.
  for (bool changed = true; changed;) {
    changed = false;
    for (int i = 0; i < qu; ++i)
      for (int j = 0; j < qv; ++j) {
        uint8_t& l = levels[size_t(i) * size_t(qv) + size_t(j)];
        const int nbs[4][2] = {{i - 1, j}, {i + 1, j}, {i, j - 1}, {i, j + 1}};
        for (const auto& nb : nbs) {
          if (nb[0] < 0 || nb[1] < 0 || nb[0] >= qu || nb[1] >= qv) continue;
          const uint8_t ln = levels[size_t(nb[0]) * size_t(qv) + size_t(nb[1])];
          if (ln > l + 1) {
            l = uint8_t(ln - 1);
            changed = true;
          }
        }
      }
  }
  return levels;
}

size_t locallyRefinedVertexCount(int grid_u, int grid_v, const std::vector<uint8_t>& levels) {
  const std::vector<uint8_t> balanced = balanceQuadLevels(grid_u, grid_v, levels);
  const Builder b(grid_u, grid_v, balanced);
  return size_t(grid_u) * size_t(grid_v) + b.extra.size();
}

Tessellation refineGridLocally(const Surface& s, const Tessellation& grid, const std::vector<uint8_t>& levels,
                               const Outline* outline) {
  const int gu = grid.grid_u, gv = grid.grid_v;
  const size_t n_grid = size_t(gu) * size_t(gv);
  if (grid.locallyRefined() || grid.positions.size() != n_grid || grid.normals.size() != n_grid ||
      grid.params.size() != n_grid)
    throw Error(s.describe() + ": local refinement needs a plain grid tessellation (grid " + std::to_string(gu) +
                " x " + std::to_string(gv) + ", " + std::to_string(grid.positions.size()) + " vertices)");
  const std::vector<uint8_t> balanced = balanceQuadLevels(gu, gv, levels);
  const Builder b(gu, gv, balanced);

  Tessellation t = grid;
  t.quad_levels = balanced;
  const bool curv = !grid.curvatures.empty();
  const size_t n = n_grid + b.extra.size();
  t.positions.resize(n);
  t.normals.resize(n);
  t.params.resize(n);
  if (curv) t.curvatures.resize(n);
  const double span_x = double(b.r_) * double(gu - 1), span_y = double(b.r_) * double(gv - 1);
  auto eval = [&](size_t k0, size_t k1) {
    for (size_t k = k0; k < k1; ++k) {
      const auto& xy = b.extra[k];
      const double sx = xy[0] == int64_t(span_x) ? 1.0 : -1.0 + 2.0 * double(xy[0]) / span_x;
      const double sy = xy[1] == int64_t(span_y) ? 1.0 : -1.0 + 2.0 * double(xy[1]) / span_y;
      const Vec2 uv = squareToParams(s, outline, Vec2(sx, sy));
      const SurfacePoint sp = s.sample(uv.x, uv.y, curv);
      if (!isFinite(sp.p) || !isFinite(sp.n) || sp.n == Vec3(0))
        throw Error(s.describe() + ": no finite position and normal at (u, v) = (" + std::to_string(uv.x) + ", " +
                    std::to_string(uv.y) + ")");
      t.params[n_grid + k] = uv;
      t.positions[n_grid + k] = sp.p;
      t.normals[n_grid + k] = sp.n;
      if (curv) t.curvatures[n_grid + k] = sp.k;
    }
  };
  if (b.extra.size() >= kParallelVertices)
    tbb::parallel_for(tbb::blocked_range<size_t>(0, b.extra.size(), 64),
                      [&](const tbb::blocked_range<size_t>& r) { eval(r.begin(), r.end()); });
  else
    eval(0, b.extra.size());

  // The grid's winding: counter-clockwise in (i, j) unless tessellateGrid reversed every triangle to agree
  // with the surface's normals (orientToNormals); the new triangles follow it.
  bool reversed = false;
  if (!grid.triangles.empty()) {
    const Triangle& g = grid.triangles.front();
    auto ij = [&](uint32_t k) { return std::array<int64_t, 2>{int64_t(k) / gv, int64_t(k) % gv}; };
    const auto a = ij(g.x), bb = ij(g.y), c = ij(g.z);
    reversed = (bb[0] - a[0]) * (c[1] - a[1]) - (bb[1] - a[1]) * (c[0] - a[0]) < 0;
  }
  t.triangles.clear();
  t.triangle_quads.clear();
  t.triangles.reserve(b.triangles.size());
  t.triangle_quads.reserve(b.triangles.size());
  for (size_t k = 0; k < b.triangles.size(); ++k) {
    Triangle tri = b.triangles[k];
    const Vec3 &p0 = t.positions[tri.x], &p1 = t.positions[tri.y], &p2 = t.positions[tri.z];
    if (p0 == p1 || p1 == p2 || p2 == p0) continue;  // at a pole or collapsed edge, as in the grid
    if (reversed) std::swap(tri.y, tri.z);
    t.triangles.push_back(tri);
    t.triangle_quads.push_back(b.quads[k]);
  }
  return t;
}

}  // namespace pvrr::cad
