// Grid and adaptive tessellation with vertices on the exact surface and normals from the surface.
//
// Adaptive refinement is Rivara's longest-edge bisection with conforming closure (M.-C. Rivara, "Mesh
// refinement processes based on the generalized bisection of simplices", SIAM J. Numer. Anal. 21 (1984)):
// a triangle that fails a criterion marks its longest edge; any triangle with a marked edge also marks its
// own longest edge, until stable; then every triangle is split at all its marked edges (2, 3 or 4 children,
// the longest edge first). Shared edges are split once, at one shared vertex, so the mesh stays conforming
// (crack-free) and the angles stay bounded away from 0.
#include "cad/tessellate.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <unordered_map>

#include "pvrr/base/error.h"
#include "cad/sag.h"

namespace pvrr::cad {
namespace {

// Above this many vertices a grid is evaluated in parallel (rows are independent).
constexpr int kParallelRows = 8;
// Adaptive refinement stops with an error beyond this many triangles (a tolerance far too small for the
// surface, or a surface whose normals jump).
constexpr size_t kMaxAdaptiveTriangles = size_t(1) << 23;
constexpr int kMaxAdaptivePasses = 64;
// Vertices per side of the starting grid of adaptive refinement.
constexpr int kAdaptiveStart = 5;

bool degenerate(const Tessellation& t, const Triangle& tri) {
  const Vec3 &a = t.positions[tri.x], &b = t.positions[tri.y], &c = t.positions[tri.z];
  return a == b || b == c || c == a;
}

// Winding: triangles are built counter-clockwise in the parameter plane, which is counter-clockwise seen
// from du × dv. A surface whose normal() points the other way gets every triangle reversed, so the winding
// always agrees with the stored normals.
void orientToNormals(Tessellation& t) {
  double agree = 0;
  for (const Triangle& tri : t.triangles) {
    const Vec3 g = glm::cross(t.positions[tri.y] - t.positions[tri.x], t.positions[tri.z] - t.positions[tri.x]);
    agree += glm::dot(g, t.normals[tri.x] + t.normals[tri.y] + t.normals[tri.z]);
  }
  if (agree < 0)
    for (Triangle& tri : t.triangles) std::swap(tri.y, tri.z);
}

void checkVertex(const Surface& s, const Vec3& p, const Vec3& n, Vec2 uv) {
  if (!isFinite(p) || !isFinite(n) || n == Vec3(0))
    throw Error(s.describe() + ": no finite position and normal at (u, v) = (" + std::to_string(uv.x) + ", " +
                std::to_string(uv.y) + ")");
}

// Square coordinates [-1,1]^2 to parameters: through the outline, or linearly onto the domain.
struct SquareMap {
  const Outline* outline;
  ParamDomain dom;
  Vec2 operator()(Vec2 s) const {
    if (outline) return outline->fromSquare(s);
    auto lerp = [](double a, double b, double t) { return t >= 1 ? b : (t <= -1 ? a : a + (b - a) * 0.5 * (t + 1)); };
    return {lerp(dom.u0, dom.u1, s.x), lerp(dom.v0, dom.v1, s.y)};
  }
};

// Coordinate k of n evenly spaced values from -1 to 1, with the ends exact.
double squareCoord(int k, int n) { return k == n - 1 ? 1.0 : -1.0 + 2.0 * k / (n - 1); }

uint64_t edgeKey(uint32_t a, uint32_t b) {
  return a < b ? (uint64_t(a) << 32) | b : (uint64_t(b) << 32) | a;
}

class Adaptive {
 public:
  Adaptive(const Surface& s, double chordal_tol, double angle_tol, const Outline* outline)
      : s_(s), sag_(dynamic_cast<const SagSurface*>(&s) != nullptr), dom_(s.domain()), map_{outline, dom_},
        chordal_tol_(chordal_tol), angle_tol_(angle_tol) {}

  Tessellation run(TessellationOptions opt) {
    const int n = kAdaptiveStart;
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) addVertex(Vec2(squareCoord(i, n), squareCoord(j, n)));
    for (int i = 0; i + 1 < n; ++i)
      for (int j = 0; j + 1 < n; ++j) {
        const uint32_t a = uint32_t(i * n + j), b = uint32_t((i + 1) * n + j), c = uint32_t((i + 1) * n + j + 1),
                       d = uint32_t(i * n + j + 1);
        tris_.push_back({a, b, c});
        tris_.push_back({a, c, d});
      }
    passed_.assign(tris_.size(), 0);

    for (int pass = 0;; ++pass) {
      std::unordered_map<uint64_t, uint32_t> marked;  // edge -> midpoint vertex (assigned when splitting)
      for (size_t t = 0; t < tris_.size(); ++t) {
        if (passed_[t]) continue;
        if (meets(tris_[t])) {
          passed_[t] = 1;
        } else {
          const int e = longestEdge(tris_[t]);
          marked.emplace(edgeKey(tris_[t][size_t(e)], tris_[t][size_t((e + 1) % 3)]), 0);
        }
      }
      if (marked.empty()) break;
      if (pass >= kMaxAdaptivePasses || tris_.size() > kMaxAdaptiveTriangles)
        throw Error(s_.describe() + ": adaptive tessellation did not reach chordal tolerance " +
                    std::to_string(chordal_tol_) + " and angle tolerance " + std::to_string(angle_tol_) +
                    " rad within " + std::to_string(tris_.size()) + " triangles");
      close(marked);
      split(marked);
    }

    Tessellation out;
    out.positions = std::move(pos_);
    out.normals = std::move(nrm_);
    out.params = std::move(uv_);
    for (const auto& t : tris_) {
      const Triangle tri(t[0], t[1], t[2]);
      if (!degenerate(out, tri)) out.triangles.push_back(tri);
    }
    if (opt.curvatures) {
      out.curvatures.resize(out.params.size());
      for (size_t k = 0; k < out.params.size(); ++k)
        out.curvatures[k] = s_.curvature(out.params[k].x, out.params[k].y);
    }
    orientToNormals(out);
    return out;
  }

 private:
  using Tri = std::array<uint32_t, 3>;

  uint32_t addVertex(Vec2 sq) {
    const Vec2 uv = map_(sq);
    const SurfacePoint sp = s_.sample(uv.x, uv.y, false);
    const Vec3 p = sp.p, nn = sp.n;
    checkVertex(s_, p, nn, uv);
    sq_.push_back(sq);
    uv_.push_back(uv);
    pos_.push_back(p);
    nrm_.push_back(nn);
    return uint32_t(pos_.size() - 1);
  }

  // Chordal deviation at a point c of the flat triangle whose parameters are about uv: the distance from c
  // to its projection onto the surface. For a sag surface the projection is along z (the surface at the
  // same (x, y), i.e. at uv itself), so the bound is on the z gap; for other surfaces it is the closest
  // point, found by Gauss-Newton from uv (the parametric point alone would also count the
  // parametrisation's tangential distortion, which is no geometric error).
  double deviation(Vec2 uv, const Vec3& c) const {
    SurfaceDerivs d = s_.evaluate(uv.x, uv.y);
    double best = glm::length(d.p - c);
    if (sag_) return best;
    for (int it = 0; it < 4; ++it) {
      const Vec3 r = c - d.p;
      const double a = glm::dot(d.du, d.du), b = glm::dot(d.du, d.dv), e = glm::dot(d.dv, d.dv);
      const double det = a * e - b * b;
      if (!(det > 1e-24 * a * e)) break;
      const double gu = glm::dot(d.du, r), gv = glm::dot(d.dv, r);
      uv.x = std::clamp(uv.x + (e * gu - b * gv) / det, dom_.u0, dom_.u1);
      uv.y = std::clamp(uv.y + (a * gv - b * gu) / det, dom_.v0, dom_.v1);
      d = s_.evaluate(uv.x, uv.y);
      best = std::min(best, glm::length(d.p - c));
    }
    return best;
  }

  bool meets(const Tri& t) const {
    for (int e = 0; e < 3; ++e)
      for (int f = e + 1; f < 3; ++f)
        if (angleBetween(nrm_[t[size_t(e)]], nrm_[t[size_t(f)]]) > angle_tol_) return false;
    for (int e = 0; e < 3; ++e) {
      const uint32_t a = t[size_t(e)], b = t[size_t((e + 1) % 3)];
      if (deviation(0.5 * (uv_[a] + uv_[b]), 0.5 * (pos_[a] + pos_[b])) > chordal_tol_) return false;
    }
    return deviation((uv_[t[0]] + uv_[t[1]] + uv_[t[2]]) / 3.0, (pos_[t[0]] + pos_[t[1]] + pos_[t[2]]) / 3.0) <=
           chordal_tol_;
  }

  // Longest edge by 3D chord length; ties broken by parameter length, then by the edge key, so the choice
  // is a function of the triangle alone.
  int longestEdge(const Tri& t) const {
    int best = 0;
    std::array<double, 3> len3{}, len2{};
    for (int e = 0; e < 3; ++e) {
      const uint32_t a = t[size_t(e)], b = t[size_t((e + 1) % 3)];
      len3[size_t(e)] = glm::length(pos_[a] - pos_[b]);
      len2[size_t(e)] = glm::length(sq_[a] - sq_[b]);
    }
    for (int e = 1; e < 3; ++e) {
      const auto key = [&](int k) {
        return std::make_tuple(len3[size_t(k)], len2[size_t(k)],
                               edgeKey(t[size_t(k)], t[size_t((k + 1) % 3)]));
      };
      if (key(e) > key(best)) best = e;
    }
    return best;
  }

  // Conforming closure: every triangle with a marked edge gets its longest edge marked.
  void close(std::unordered_map<uint64_t, uint32_t>& marked) const {
    std::vector<std::pair<uint64_t, uint32_t>> edges;  // (edge, triangle), sorted by edge
    edges.reserve(tris_.size() * 3);
    for (size_t t = 0; t < tris_.size(); ++t)
      for (int e = 0; e < 3; ++e)
        edges.emplace_back(edgeKey(tris_[t][size_t(e)], tris_[t][size_t((e + 1) % 3)]), uint32_t(t));
    std::sort(edges.begin(), edges.end());
    std::vector<uint32_t> work;
    for (const auto& m : marked) {
      auto it = std::lower_bound(edges.begin(), edges.end(), std::make_pair(m.first, uint32_t(0)));
      for (; it != edges.end() && it->first == m.first; ++it) work.push_back(it->second);
    }
    while (!work.empty()) {
      const uint32_t t = work.back();
      work.pop_back();
      const int e = longestEdge(tris_[t]);
      const uint64_t k = edgeKey(tris_[t][size_t(e)], tris_[t][size_t((e + 1) % 3)]);
      if (marked.count(k)) continue;
      marked.emplace(k, 0);
      auto it = std::lower_bound(edges.begin(), edges.end(), std::make_pair(k, uint32_t(0)));
      for (; it != edges.end() && it->first == k; ++it) work.push_back(it->second);
    }
  }

  uint32_t midpoint(std::unordered_map<uint64_t, uint32_t>& marked, uint32_t a, uint32_t b) {
    uint32_t& m = marked.at(edgeKey(a, b));
    if (m == 0) m = addVertex(0.5 * (sq_[a] + sq_[b]));  // vertex 0 is a corner, never a midpoint
    return m;
  }

  void split(std::unordered_map<uint64_t, uint32_t>& marked) {
    std::vector<Tri> next;
    std::vector<uint8_t> next_passed;
    next.reserve(tris_.size() * 2);
    auto emit = [&](uint32_t a, uint32_t b, uint32_t c) {
      next.push_back({a, b, c});
      next_passed.push_back(0);
    };
    for (size_t t = 0; t < tris_.size(); ++t) {
      const Tri tri = tris_[t];
      const int e = longestEdge(tri);
      const uint32_t a = tri[size_t(e)], b = tri[size_t((e + 1) % 3)], c = tri[size_t((e + 2) % 3)];
      if (!marked.count(edgeKey(a, b))) {
        next.push_back(tri);
        next_passed.push_back(passed_[t]);
        continue;
      }
      // (a, b, c) counter-clockwise with (a, b) the longest edge: bisect it at m, then split (m, b, c) at the
      // midpoint of b-c and (a, m, c) at the midpoint of c-a where those edges are marked.
      const uint32_t m = midpoint(marked, a, b);
      if (marked.count(edgeKey(b, c))) {
        const uint32_t m1 = midpoint(marked, b, c);
        emit(m, b, m1);
        emit(m, m1, c);
      } else {
        emit(m, b, c);
      }
      if (marked.count(edgeKey(c, a))) {
        const uint32_t m2 = midpoint(marked, c, a);
        emit(a, m, m2);
        emit(m, c, m2);
      } else {
        emit(a, m, c);
      }
    }
    tris_ = std::move(next);
    passed_ = std::move(next_passed);
  }

  const Surface& s_;
  bool sag_;
  ParamDomain dom_;
  SquareMap map_;
  double chordal_tol_, angle_tol_;
  std::vector<Vec2> sq_, uv_;
  std::vector<Vec3> pos_, nrm_;
  std::vector<Tri> tris_;
  std::vector<uint8_t> passed_;
};

}  // namespace

Tessellation tessellateGrid(const Surface& s, int n_u, int n_v, const Outline* outline, TessellationOptions opt) {
  if (n_u < 2 || n_v < 2)
    throw Error(s.describe() + ": grid tessellation needs at least 2 x 2 vertices, got " + std::to_string(n_u) +
                " x " + std::to_string(n_v));
  if (double(n_u) * double(n_v) > 4.0e9)
    throw Error(s.describe() + ": grid of " + std::to_string(n_u) + " x " + std::to_string(n_v) +
                " vertices exceeds 32-bit indices");
  const SquareMap map{outline, s.domain()};
  Tessellation t;
  t.grid_u = n_u;
  t.grid_v = n_v;
  const size_t nv = size_t(n_u) * size_t(n_v);
  t.positions.resize(nv);
  t.normals.resize(nv);
  t.params.resize(nv);
  if (opt.curvatures) t.curvatures.resize(nv);
  auto rows = [&](int i0, int i1) {
    for (int i = i0; i < i1; ++i)
      for (int j = 0; j < n_v; ++j) {
        const size_t k = size_t(i) * size_t(n_v) + size_t(j);
        const Vec2 uv = map(Vec2(squareCoord(i, n_u), squareCoord(j, n_v)));
        const SurfacePoint sp = s.sample(uv.x, uv.y, opt.curvatures);
        checkVertex(s, sp.p, sp.n, uv);
        t.params[k] = uv;
        t.positions[k] = sp.p;
        t.normals[k] = sp.n;
        if (opt.curvatures) t.curvatures[k] = sp.k;
      }
  };
  if (n_u >= kParallelRows && nv >= 4096)
    tbb::parallel_for(tbb::blocked_range<int>(0, n_u, 4),
                      [&](const tbb::blocked_range<int>& r) { rows(r.begin(), r.end()); });
  else
    rows(0, n_u);

  // Each quad (i, j)-(i+1, j+1) is split along the same diagonal, from (i, j) to (i+1, j+1). Triangles with
  // two coincident vertices (at a pole or collapsed edge) are left out.
  t.triangles.reserve(2 * size_t(n_u - 1) * size_t(n_v - 1));
  for (int i = 0; i + 1 < n_u; ++i)
    for (int j = 0; j + 1 < n_v; ++j) {
      const uint32_t a = uint32_t(i * n_v + j), b = uint32_t((i + 1) * n_v + j),
                     c = uint32_t((i + 1) * n_v + j + 1), d = uint32_t(i * n_v + j + 1);
      for (const Triangle tri : {Triangle(a, b, c), Triangle(a, c, d)})
        if (!degenerate(t, tri)) t.triangles.push_back(tri);
    }
  orientToNormals(t);
  return t;
}

Tessellation tessellateAdaptive(const Surface& s, double chordal_tol, double angle_tol_rad, const Outline* outline,
                                TessellationOptions opt) {
  if (!(chordal_tol > 0) || !std::isfinite(chordal_tol))
    throw Error(s.describe() + ": adaptive tessellation needs a finite chordal tolerance > 0, got " +
                std::to_string(chordal_tol));
  if (!(angle_tol_rad > 0))
    throw Error(s.describe() + ": adaptive tessellation needs an angle tolerance > 0, got " +
                std::to_string(angle_tol_rad));
  return Adaptive(s, chordal_tol, angle_tol_rad, outline).run(opt);
}

// Quad rows [0, grid_u - 1) are cut into patches_u runs of near-equal length (likewise along v); patch
// (a, b) is element a * patches_v + b. Its triangles are the grid's triangles whose quad lies in its runs,
// so the winding and diagonal are the grid's own.
std::vector<GridPatch> splitGrid(const Tessellation& grid, int patches_u, int patches_v) {
  const int gu = grid.grid_u, gv = grid.grid_v;
  const size_t n_grid = size_t(gu) * size_t(gv);
  const bool local = grid.locallyRefined();
  if (gu < 2 || gv < 2 || (local ? grid.positions.size() < n_grid : grid.positions.size() != n_grid) ||
      (local && grid.triangle_quads.size() != grid.triangles.size()))
    throw Error("splitGrid: not a grid tessellation (grid " + std::to_string(gu) + " x " + std::to_string(gv) +
                ", " + std::to_string(grid.positions.size()) + " vertices)");
  if (patches_u < 1 || patches_v < 1 || patches_u > gu - 1 || patches_v > gv - 1)
    throw Error("splitGrid: " + std::to_string(patches_u) + " x " + std::to_string(patches_v) +
                " patches requested for a grid of " + std::to_string(gu - 1) + " x " + std::to_string(gv - 1) +
                " quads; need 1 <= patches <= quads along each direction");
  auto cuts = [](int quads, int parts) {
    std::vector<int> c(size_t(parts) + 1);
    for (int k = 0; k <= parts; ++k) c[size_t(k)] = int((long long)quads * k / parts);
    return c;
  };
  const std::vector<int> cu = cuts(gu - 1, patches_u), cv = cuts(gv - 1, patches_v);
  std::vector<int> patch_of_qu(size_t(gu - 1)), patch_of_qv(size_t(gv - 1));
  for (int a = 0; a < patches_u; ++a)
    for (int i = cu[size_t(a)]; i < cu[size_t(a + 1)]; ++i) patch_of_qu[size_t(i)] = a;
  for (int b = 0; b < patches_v; ++b)
    for (int j = cv[size_t(b)]; j < cv[size_t(b + 1)]; ++j) patch_of_qv[size_t(j)] = b;

  std::vector<GridPatch> patches(size_t(patches_u) * size_t(patches_v));
  for (int a = 0; a < patches_u; ++a)
    for (int b = 0; b < patches_v; ++b) {
      GridPatch& p = patches[size_t(a * patches_v + b)];
      p.i0 = cu[size_t(a)];
      p.i1 = cu[size_t(a + 1)];
      p.j0 = cv[size_t(b)];
      p.j1 = cv[size_t(b + 1)];
      p.vertices.reserve(size_t(p.i1 - p.i0 + 1) * size_t(p.j1 - p.j0 + 1));
      p.triangles.reserve(2 * size_t(p.i1 - p.i0) * size_t(p.j1 - p.j0));  // two a quad (more where cut)
      for (int i = p.i0; i <= p.i1; ++i)
        for (int j = p.j0; j <= p.j1; ++j) p.vertices.push_back(uint32_t(i * gv + j));
    }
  // Each vertex's grid row and column, once (two integer divisions per triangle corner were most of the
  // split's time).
  const size_t n = grid.positions.size();
  std::vector<int> row(n_grid), col(n_grid);
  for (size_t k = 0; k < n_grid; ++k) row[k] = int(k) / gv, col[k] = int(k) % gv;
  if (!local) {
    for (const Triangle& tri : grid.triangles) {
      const uint32_t idx[3] = {tri.x, tri.y, tri.z};
      int qi = gu, qj = gv;
      for (uint32_t k : idx) {
        if (k >= n) throw Error("splitGrid: a triangle refers to vertex " + std::to_string(k) + " of " + std::to_string(n));
        qi = std::min(qi, row[k]);
        qj = std::min(qj, col[k]);
      }
      if (qi >= gu - 1 || qj >= gv - 1) throw Error("splitGrid: a triangle does not lie in a grid quad");
      GridPatch& p = patches[size_t(patch_of_qu[size_t(qi)] * patches_v + patch_of_qv[size_t(qj)])];
      const int w = p.j1 - p.j0 + 1;
      auto local_index = [&](uint32_t k) { return uint32_t((row[k] - p.i0) * w + (col[k] - p.j0)); };
      p.triangles.emplace_back(local_index(tri.x), local_index(tri.y), local_index(tri.z));
    }
    return patches;
  }
  // Locally refined: each triangle goes to the patch of its base quad; the appended vertices a patch uses
  // follow its grid block, in ascending order.
  std::vector<std::vector<size_t>> tris_of(patches.size());
  for (size_t t = 0; t < grid.triangles.size(); ++t) {
    const uint32_t q = grid.triangle_quads[t];
    const int qi = int(q) / (gv - 1), qj = int(q) % (gv - 1);
    if (qi >= gu - 1) throw Error("splitGrid: a triangle's base quad " + std::to_string(q) + " is not in the grid");
    tris_of[size_t(patch_of_qu[size_t(qi)] * patches_v + patch_of_qv[size_t(qj)])].push_back(t);
  }
  std::vector<uint32_t> extra;
  for (size_t pi = 0; pi < patches.size(); ++pi) {
    GridPatch& p = patches[pi];
    extra.clear();
    for (size_t t : tris_of[pi])
      for (uint32_t k : {grid.triangles[t].x, grid.triangles[t].y, grid.triangles[t].z}) {
        if (k >= n) throw Error("splitGrid: a triangle refers to vertex " + std::to_string(k) + " of " + std::to_string(n));
        if (k >= n_grid) extra.push_back(k);
      }
    std::sort(extra.begin(), extra.end());
    extra.erase(std::unique(extra.begin(), extra.end()), extra.end());
    const int w = p.j1 - p.j0 + 1;
    const uint32_t block = uint32_t(p.vertices.size());
    auto local_index = [&](uint32_t k) {
      if (k >= n_grid)
        return block + uint32_t(std::lower_bound(extra.begin(), extra.end(), k) - extra.begin());
      if (row[k] < p.i0 || row[k] > p.i1 || col[k] < p.j0 || col[k] > p.j1)
        throw Error("splitGrid: a triangle of a patch refers to a grid vertex outside it");
      return uint32_t((row[k] - p.i0) * w + (col[k] - p.j0));
    };
    p.vertices.insert(p.vertices.end(), extra.begin(), extra.end());
    for (size_t t : tris_of[pi]) {
      const Triangle& tri = grid.triangles[t];
      p.triangles.emplace_back(local_index(tri.x), local_index(tri.y), local_index(tri.z));
    }
  }
  return patches;
}

GridPatch wholeGrid(const Tessellation& grid) { return splitGrid(grid, 1, 1).front(); }

}  // namespace pvrr::cad
