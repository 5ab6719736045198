#include "pvrr/method/ao_receiver_grid.h"

#include <algorithm>
#include <cmath>
#include <unordered_map>
#include <unordered_set>

namespace pvrr {

namespace {

// A rectangle whose triangles' area differs from its bounds' by more than this (relative) is not one.
constexpr double kAreaTolerance = 1e-5;
// A vertex farther than this (m, or texture units) from the rectangle's plane or its affine texture map.
constexpr double kFitTolerance = 1e-5;
// An axis is split at a level where its cell side is at least this fraction of the larger side.
constexpr double kSplitRatio = 0.75;

}  // namespace

std::optional<AoRectangle> aoRectangleOf(const EnvMesh& mesh, const std::vector<uint32_t>& triangles,
                                         const Vec3& normal, std::string& why) {
  if (triangles.empty() || glm::length(normal) == 0) {
    why = "no face";
    return std::nullopt;
  }
  const Vec3 n = glm::normalize(normal);
  auto pos = [&](uint32_t i) { return Vec3(mesh.positions[i]); };
  const glm::uvec3 t0 = mesh.triangles[triangles[0]];
  const Vec3 p0 = pos(t0.x);
  double area = 0;
  for (const uint32_t t : triangles) {
    const glm::uvec3 tri = mesh.triangles[t];
    area += 0.5 * glm::length(glm::cross(pos(tri.y) - pos(tri.x), pos(tri.z) - pos(tri.x)));
  }
  // The rectangle's sides lie along one of the first triangle's edges.
  const uint32_t c[3] = {t0.x, t0.y, t0.z};
  std::optional<AoRectangle> best;
  double best_gap = kInf;
  for (int e = 0; e < 3; ++e) {
    const Vec3 edge = pos(c[(e + 1) % 3]) - pos(c[e]);
    if (glm::length(edge) == 0) continue;
    AoRectangle r;
    r.normal = n;
    r.u = glm::normalize(edge - glm::dot(edge, n) * n);
    r.v = glm::cross(n, r.u);
    Vec2 lo(kInf), hi(-kInf);
    double off_plane = 0;
    for (const uint32_t t : triangles)
      for (const uint32_t i : {mesh.triangles[t].x, mesh.triangles[t].y, mesh.triangles[t].z}) {
        const Vec3 d = pos(i) - p0;
        const Vec2 st(glm::dot(d, r.u), glm::dot(d, r.v));
        lo = glm::min(lo, st);
        hi = glm::max(hi, st);
        off_plane = std::max(off_plane, std::abs(glm::dot(d, n)));
      }
    r.width = hi.x - lo.x;
    r.height = hi.y - lo.y;
    const double gap = std::abs(r.width * r.height - area);
    if (off_plane > kFitTolerance || gap >= best_gap) continue;
    r.origin = p0 + lo.x * r.u + lo.y * r.v;
    best_gap = gap;
    best = r;
  }
  if (!best || best->width <= 0 || best->height <= 0 || best_gap > kAreaTolerance * best->width * best->height) {
    why = "its face is not a rectangle";
    return std::nullopt;
  }
  AoRectangle& r = *best;
  auto st = [&](uint32_t i) {
    const Vec3 d = pos(i) - r.origin;
    return Vec2(glm::dot(d, r.u), glm::dot(d, r.v));
  };
  r.ccw = glm::dot(glm::cross(pos(t0.y) - pos(t0.x), pos(t0.z) - pos(t0.x)), n) > 0;
  // The texture coordinates' affine map, from the first triangle.
  const Vec2 a = st(t0.x), b = st(t0.y), cc = st(t0.z);
  const Vec2 ua = Vec2(mesh.uvs[t0.x]), ub = Vec2(mesh.uvs[t0.y]), uc = Vec2(mesh.uvs[t0.z]);
  const double det = (b.x - a.x) * (cc.y - a.y) - (cc.x - a.x) * (b.y - a.y);
  if (std::abs(det) <= 0) {
    why = "a degenerate triangle";
    return std::nullopt;
  }
  r.uv_s = ((ub - ua) * (cc.y - a.y) - (uc - ua) * (b.y - a.y)) / det;
  r.uv_t = ((uc - ua) * (b.x - a.x) - (ub - ua) * (cc.x - a.x)) / det;
  r.uv0 = ua - a.x * r.uv_s - a.y * r.uv_t;
  for (const uint32_t t : triangles)
    for (const uint32_t i : {mesh.triangles[t].x, mesh.triangles[t].y, mesh.triangles[t].z}) {
      const Vec2 q = st(i);
      const Vec2 uv = r.uv0 + q.x * r.uv_s + q.y * r.uv_t;
      const bool same_turn = (glm::dot(glm::cross(pos(mesh.triangles[t].y) - pos(mesh.triangles[t].x),
                                                  pos(mesh.triangles[t].z) - pos(mesh.triangles[t].x)), n) > 0) == r.ccw;
      if (glm::length(uv - Vec2(mesh.uvs[i])) > kFitTolerance * (1 + glm::length(Vec2(mesh.uvs[i]))) || !same_turn) {
        why = same_turn ? "its texture coordinates are not affine over the face" : "its triangles' winding differs";
        return std::nullopt;
      }
    }
  return best;
}

std::array<double, 2> aoTwoSided(const std::vector<AoField>& fields, const Scene& scene, int receiver, const Vec3& x,
                                 const Vec3& n) {
  std::array<double, 2> o{0, 0};
  for (const AoField& f : fields) {
    if (f.occluder == receiver || f.volume.empty()) continue;
    const Mat4 motion = occluderMotion(scene, f.occluder);
    const std::array<double, 6> cube = volumeCube(f, motion, x);
    const Vec3 nf = glm::transpose(Mat3(motion)) * n;
    o[0] += cubeOcclusion(cube, nf);
    o[1] += cubeOcclusion(cube, -nf);
  }
  return {std::min(o[0], 1.0), std::min(o[1], 1.0)};
}

namespace {

// The quadtree's levels: per level whether each axis was split to reach it, and the cells' sides there.
struct Levels {
  int nu = 1, nv = 1;               // root cells per axis
  std::vector<int> ku, kv;          // splits of each axis up to the level
  std::vector<double> eu, ev;       // a cell's sides (m)
  int top() const { return int(ku.size()) - 1; }
  bool splitsU(int l) const { return ku[size_t(l)] != ku[size_t(l - 1)]; }
  bool splitsV(int l) const { return kv[size_t(l)] != kv[size_t(l - 1)]; }
  // Lattice units (half the finest cell) per cell of level l, along each axis.
  int64_t stepU(int l) const { return int64_t(2) << (ku.back() - ku[size_t(l)]); }
  int64_t stepV(int l) const { return int64_t(2) << (kv.back() - kv[size_t(l)]); }
  int64_t cellsU(int l) const { return int64_t(nu) << ku[size_t(l)]; }
  int64_t cellsV(int l) const { return int64_t(nv) << kv[size_t(l)]; }
};

Levels levelsOf(const AoRectangle& r, double min_cell) {
  Levels lv;
  lv.nu = std::max(1, int(std::ceil(r.width / kAoGridRootCell)));
  lv.nv = std::max(1, int(std::ceil(r.height / kAoGridRootCell)));
  lv.ku = {0};
  lv.kv = {0};
  lv.eu = {r.width / lv.nu};
  lv.ev = {r.height / lv.nv};
  // Levels down to min_cell; at most 20 splits per axis (lattice coordinates within 32 bits).
  while (std::max(lv.eu.back(), lv.ev.back()) > min_cell && lv.ku.back() < 20 && lv.kv.back() < 20) {
    const double most = std::max(lv.eu.back(), lv.ev.back());
    const bool su = lv.eu.back() >= kSplitRatio * most, sv = lv.ev.back() >= kSplitRatio * most;
    lv.ku.push_back(lv.ku.back() + su);
    lv.kv.push_back(lv.kv.back() + sv);
    lv.eu.push_back(lv.eu.back() / (su ? 2 : 1));
    lv.ev.push_back(lv.ev.back() / (sv ? 2 : 1));
  }
  return lv;
}

uint64_t cellKey(int l, int64_t i, int64_t j) { return (uint64_t(l) << 58) | (uint64_t(i) << 29) | uint64_t(j); }
uint64_t pointKey(int64_t x, int64_t y) { return (uint64_t(x) << 32) | uint64_t(y); }

struct Cell {
  int l;
  int64_t i, j;
};

}  // namespace

AoReceiverGrid buildAoReceiverGrid(const AoRectangle& r, const Vec3& anchor, int receiver,
                                   const std::vector<AoField>& fields, const Scene& scene,
                                   const AoGridOptions& options) {
  AoReceiverGrid grid;
  const Levels lv = levelsOf(r, options.min_cell_m);
  const int top = lv.top();
  const int64_t lattice_u = lv.cellsU(top) * 2, lattice_v = lv.cellsV(top) * 2;
  // A lattice point's plane coordinates, exact at the rectangle's far sides.
  auto st = [&](int64_t x, int64_t y) { return Vec2(r.width * double(x) / double(lattice_u), r.height * double(y) / double(lattice_v)); };
  const Vec3 world_origin = anchor + r.origin;
  std::unordered_map<uint64_t, std::array<double, 2>> values;
  auto value = [&](int64_t x, int64_t y) -> const std::array<double, 2>& {
    const auto [it, added] = values.try_emplace(pointKey(x, y));
    if (added) {
      const Vec2 p = st(x, y);
      it->second = aoTwoSided(fields, scene, receiver, world_origin + p.x * r.u + p.y * r.v, r.normal);
    }
    return it->second;
  };
  // The fields that count, where their objects are now: centre (world) and radius, reach.
  struct Near {
    Vec3 centre;
    double radius, reach;
  };
  std::vector<Near> near;
  for (const AoField& f : fields)
    if (f.occluder != receiver && !f.volume.empty())
      near.push_back({Vec3(occluderMotion(scene, f.occluder) * Vec4(f.centre, 1.0)), f.radius, f.reach});
  auto split = [&](const Cell& c) {
    if (c.l >= top) return false;
    const int64_t x0 = c.i * lv.stepU(c.l), y0 = c.j * lv.stepV(c.l), sx = lv.stepU(c.l), sy = lv.stepV(c.l);
    const double side = std::max(lv.eu[size_t(c.l)], lv.ev[size_t(c.l)]);
    const Vec2 lo = st(x0, y0), hi = st(x0 + sx, y0 + sy);
    for (const Near& f : near) {
      const Vec3 d = f.centre - world_origin;
      const Vec2 q(glm::dot(d, r.u), glm::dot(d, r.v));
      const Vec2 inside = glm::clamp(q, lo, hi);
      const double dist = std::sqrt(glm::dot(q - inside, q - inside) + std::pow(glm::dot(d, r.normal), 2));
      if (dist < f.reach && side > options.near * std::max(dist, f.radius)) return true;
    }
    const auto& c00 = value(x0, y0);
    const auto& c10 = value(x0 + sx, y0);
    const auto& c01 = value(x0, y0 + sy);
    const auto& c11 = value(x0 + sx, y0 + sy);
    const int64_t mx = x0 + sx / 2, my = y0 + sy / 2;
    for (size_t k = 0; k < 2; ++k) {
      const double err = std::max({std::abs(value(mx, y0)[k] - (c00[k] + c10[k]) / 2),
                                   std::abs(value(mx, y0 + sy)[k] - (c01[k] + c11[k]) / 2),
                                   std::abs(value(x0, my)[k] - (c00[k] + c01[k]) / 2),
                                   std::abs(value(x0 + sx, my)[k] - (c10[k] + c11[k]) / 2),
                                   std::abs(value(mx, my)[k] - (c00[k] + c11[k]) / 2)});
      if (err > options.tolerance) return true;
    }
    return false;
  };
  auto children = [&](const Cell& c, std::vector<Cell>& out) {
    const int l = c.l + 1;
    const int64_t nu = lv.splitsU(l) ? 2 : 1, nv = lv.splitsV(l) ? 2 : 1;
    for (int64_t a = 0; a < nu; ++a)
      for (int64_t b = 0; b < nv; ++b) out.push_back({l, c.i * nu + a, c.j * nv + b});
  };
  // Refinement.
  std::unordered_set<uint64_t> leaves;
  std::vector<Cell> stack;
  for (int i = 0; i < lv.nu; ++i)
    for (int j = 0; j < lv.nv; ++j) stack.push_back({0, i, j});
  std::vector<Cell> leaf_list;
  while (!stack.empty()) {
    const Cell c = stack.back();
    stack.pop_back();
    if (split(c)) {
      children(c, stack);
    } else {
      leaves.insert(cellKey(c.l, c.i, c.j));
      leaf_list.push_back(c);
    }
  }
  // The leaf that holds cell (l, i, j)'s region (its level, or -1 when the region is split finer or outside).
  auto holder = [&](int l, int64_t i, int64_t j) -> int {
    if (i < 0 || j < 0 || i >= lv.cellsU(l) || j >= lv.cellsV(l)) return -1;
    for (int a = l; a >= 0; --a) {
      const int64_t ia = i >> (lv.ku[size_t(l)] - lv.ku[size_t(a)]), ja = j >> (lv.kv[size_t(l)] - lv.kv[size_t(a)]);
      if (leaves.count(cellKey(a, ia, ja))) return a;
    }
    return -1;
  };
  const int64_t dirs[4][2] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}};
  // Balance: neighbours differ by one level at most.
  for (bool changed = true; changed;) {
    changed = false;
    std::vector<Cell> next;
    for (const Cell& c : leaf_list) {
      if (!leaves.count(cellKey(c.l, c.i, c.j))) continue;
      next.push_back(c);
      for (const auto& d : dirs) {
        const int64_t ni = c.i + d[0], nj = c.j + d[1];
        const int a = holder(c.l, ni, nj);
        if (a < 0 || a >= c.l - 1) continue;
        const Cell coarse{a, ni >> (lv.ku[size_t(c.l)] - lv.ku[size_t(a)]), nj >> (lv.kv[size_t(c.l)] - lv.kv[size_t(a)])};
        leaves.erase(cellKey(coarse.l, coarse.i, coarse.j));
        std::vector<Cell> kids;
        children(coarse, kids);
        for (const Cell& k : kids) {
          leaves.insert(cellKey(k.l, k.i, k.j));
          next.push_back(k);
        }
        changed = true;
      }
    }
    leaf_list.swap(next);
  }
  // Triangulation: two triangles per leaf (diagonal from its first corner), or, beside finer leaves, a fan
  // through the midpoints of the edges it shares with them.
  std::unordered_map<uint64_t, uint32_t> index;
  auto vertex = [&](int64_t x, int64_t y) {
    const auto [it, added] = index.try_emplace(pointKey(x, y), uint32_t(grid.positions.size()));
    if (added) {
      const Vec2 p = st(x, y);
      grid.positions.push_back(r.origin + p.x * r.u + p.y * r.v);
      grid.uvs.push_back(r.uv0 + p.x * r.uv_s + p.y * r.uv_t);
      const std::array<double, 2>& o = value(x, y);
      grid.occlusion.push_back({float(o[0]), float(o[1])});
    }
    return it->second;
  };
  auto triangle = [&](uint32_t a, uint32_t b, uint32_t c) {
    if (r.ccw) grid.indices.insert(grid.indices.end(), {a, b, c});
    else grid.indices.insert(grid.indices.end(), {a, c, b});
  };
  for (const Cell& c : leaf_list) {
    const int64_t x0 = c.i * lv.stepU(c.l), y0 = c.j * lv.stepV(c.l), sx = lv.stepU(c.l), sy = lv.stepV(c.l);
    auto finer = [&](int64_t di, int64_t dj) {
      const int64_t ni = c.i + di, nj = c.j + dj;
      return ni >= 0 && nj >= 0 && ni < lv.cellsU(c.l) && nj < lv.cellsV(c.l) && holder(c.l, ni, nj) < 0;
    };
    const bool more = c.l < top;
    const bool bottom = more && lv.splitsU(c.l + 1) && finer(0, -1), up = more && lv.splitsU(c.l + 1) && finer(0, 1);
    const bool left = more && lv.splitsV(c.l + 1) && finer(-1, 0), right = more && lv.splitsV(c.l + 1) && finer(1, 0);
    const uint32_t v00 = vertex(x0, y0), v10 = vertex(x0 + sx, y0), v11 = vertex(x0 + sx, y0 + sy), v01 = vertex(x0, y0 + sy);
    if (!bottom && !up && !left && !right) {
      triangle(v00, v10, v11);
      triangle(v00, v11, v01);
      continue;
    }
    // Counter-clockwise in (s, t) about the centre.
    std::vector<uint32_t> ring = {v00};
    if (bottom) ring.push_back(vertex(x0 + sx / 2, y0));
    ring.push_back(v10);
    if (right) ring.push_back(vertex(x0 + sx, y0 + sy / 2));
    ring.push_back(v11);
    if (up) ring.push_back(vertex(x0 + sx / 2, y0 + sy));
    ring.push_back(v01);
    if (left) ring.push_back(vertex(x0, y0 + sy / 2));
    // A fan from the first edge midpoint in the ring (never on the same side as a pair it joins, so no triangle
    // is degenerate): 2 + k triangles for k midpoints, 2 fewer than a fan about the centre (issue 24's cost:
    // llvmpipe pays per triangle; docs/performance.md "Ambient occlusion", seventh round).
    size_t apex = 0;
    while (ring[apex] == v00 || ring[apex] == v10 || ring[apex] == v11 || ring[apex] == v01) ++apex;
    for (size_t k = 1; k + 1 < ring.size(); ++k)
      triangle(ring[apex], ring[(apex + k) % ring.size()], ring[(apex + k + 1) % ring.size()]);
  }
  grid.leaves = int(leaf_list.size());
  grid.evaluations = int(values.size());
  return grid;
}

}  // namespace pvrr
