#include "pvrr/method/receiver_sheets.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <tuple>

namespace pvrr {

namespace {

// Planarity of a sheet: its normals within this of one another (1 - cos), its heights within this fraction of its
// extent of one plane (as the whole-mesh planar receivers, pvrr/method/caustic_mesh.cpp).
constexpr double kNormalTol = 1e-9, kPlaneTol = 1e-6;
// Vertices closer than this fraction of the mesh's extent are one (a sphere's seam, a box's shared corners).
constexpr double kWeldFraction = 1e-7;

// A triangle's normal, oriented by its vertex normals (a mesh's winding need not be consistent), twice its area
// long; its unit normal (zero for a degenerate triangle).
Vec3 orientedCross(const EnvMesh& mesh, const glm::u32vec3& t) {
  const Vec3 a(mesh.positions[t.x]), b(mesh.positions[t.y]), c(mesh.positions[t.z]);
  Vec3 n = glm::cross(b - a, c - a);
  const Vec3 shading = Vec3(mesh.normals[t.x]) + Vec3(mesh.normals[t.y]) + Vec3(mesh.normals[t.z]);
  if (glm::dot(n, shading) < 0) n = -n;
  return n;
}
Vec3 unitOf(const Vec3& n) {
  const double len = glm::length(n);
  return len > 0 ? n / len : Vec3(0);
}

struct UnionFind {
  std::vector<uint32_t> parent;
  explicit UnionFind(size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0u); }
  uint32_t find(uint32_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  }
  void unite(uint32_t a, uint32_t b) {
    a = find(a), b = find(b);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
  }
};

}  // namespace

std::optional<HeightFieldPlane> heightFieldPlane(const EnvMesh& mesh, const std::vector<uint32_t>* subset) {
  if (mesh.triangles.empty() || mesh.normals.size() != mesh.positions.size()) return std::nullopt;
  if (subset && subset->empty()) return std::nullopt;
  const size_t count = subset ? subset->size() : mesh.triangles.size();
  const auto triangle = [&](size_t k) { return mesh.triangles[subset ? (*subset)[k] : k]; };
  // The plane: normal to the sum of the triangles' normals weighted by twice their areas.
  std::vector<Vec3> tri_n(count);
  Vec3 sum(0);
  for (size_t k = 0; k < count; ++k) {
    const Vec3 cross = orientedCross(mesh, triangle(k));
    sum += cross;
    tri_n[k] = unitOf(cross);
  }
  if (!(glm::length(sum) > 0)) return std::nullopt;
  const Vec3 n = glm::normalize(sum);
  bool planar = true;
  for (const Vec3& t : tri_n) {
    if (t == Vec3(0)) continue;
    if (!(glm::dot(t, n) > kMinHeightFieldCos)) return std::nullopt;
    if (glm::dot(t, n) < 1 - kNormalTol) planar = false;
  }
  const glm::u32vec3 t0 = triangle(0);
  Vec3 u = Vec3(mesh.positions[t0.y]) - Vec3(mesh.positions[t0.x]);
  u = u - glm::dot(u, n) * n;
  if (!(glm::length(u) > 0)) u = std::abs(n.x) < 0.9 ? glm::cross(n, Vec3(1, 0, 0)) : glm::cross(n, Vec3(0, 1, 0));
  u = glm::normalize(u);
  const Vec3 v = glm::cross(n, u);  // u x v = n
  // The vertices that count: all of the mesh's, or those of the subset's triangles.
  std::vector<uint32_t> verts;
  if (subset) {
    for (uint32_t k : *subset)
      for (uint32_t i : {mesh.triangles[k].x, mesh.triangles[k].y, mesh.triangles[k].z}) verts.push_back(i);
    std::sort(verts.begin(), verts.end());
    verts.erase(std::unique(verts.begin(), verts.end()), verts.end());
  }
  const size_t nv = subset ? verts.size() : mesh.positions.size();
  const auto vertex = [&](size_t k) { return subset ? verts[k] : uint32_t(k); };
  // Projections onto the plane (relative to the first vertex) and heights over it.
  const Vec3 p0(mesh.positions[vertex(0)]);
  std::vector<Vec2> q(mesh.positions.size());
  double u0 = kInf, u1 = -kInf, v0 = kInf, v1 = -kInf, h0 = kInf, h1 = -kInf;
  for (size_t k = 0; k < nv; ++k) {
    const uint32_t i = vertex(k);
    const Vec3 d = Vec3(mesh.positions[i]) - p0;
    q[i] = Vec2(glm::dot(d, u), glm::dot(d, v));
    u0 = std::min(u0, q[i].x), u1 = std::max(u1, q[i].x), v0 = std::min(v0, q[i].y), v1 = std::max(v1, q[i].y);
    h0 = std::min(h0, glm::dot(d, n)), h1 = std::max(h1, glm::dot(d, n));
  }
  if (!(u1 > u0) || !(v1 > v0)) return std::nullopt;
  // One sheet over the plane: no triangle's centroid lies strictly inside another's projection (binned).
  constexpr int kBins = 64;
  const double bu = (u1 - u0) / kBins, bv = (v1 - v0) / kBins;
  std::vector<std::vector<uint32_t>> bins(size_t(kBins) * kBins);
  const auto binOf = [&](double x, double lo, double w) { return std::clamp(int((x - lo) / w), 0, kBins - 1); };
  for (size_t k = 0; k < count; ++k) {
    const glm::u32vec3 t = triangle(k);
    const double x0 = std::min({q[t.x].x, q[t.y].x, q[t.z].x}), x1 = std::max({q[t.x].x, q[t.y].x, q[t.z].x});
    const double y0 = std::min({q[t.x].y, q[t.y].y, q[t.z].y}), y1 = std::max({q[t.x].y, q[t.y].y, q[t.z].y});
    for (int j = binOf(y0, v0, bv); j <= binOf(y1, v0, bv); ++j)
      for (int i = binOf(x0, u0, bu); i <= binOf(x1, u0, bu); ++i) bins[size_t(j) * kBins + i].push_back(uint32_t(k));
  }
  const auto strictlyInside = [&](const glm::u32vec3& t, const Vec2& c) {
    const Vec2 a = q[t.x], b = q[t.y], d = q[t.z];
    const double area = (b.x - a.x) * (d.y - a.y) - (b.y - a.y) * (d.x - a.x);
    if (area == 0) return false;
    const double w0 = ((b.x - c.x) * (d.y - c.y) - (b.y - c.y) * (d.x - c.x)) / area;
    const double w1 = ((d.x - c.x) * (a.y - c.y) - (d.y - c.y) * (a.x - c.x)) / area;
    const double w2 = 1 - w0 - w1;
    constexpr double kEdge = 1e-6;  // on a shared edge or vertex is not over it
    return w0 > kEdge && w1 > kEdge && w2 > kEdge;
  };
  for (size_t k = 0; k < count; ++k) {
    const glm::u32vec3 t = triangle(k);
    const Vec2 c = (q[t.x] + q[t.y] + q[t.z]) / 3.0;
    for (uint32_t o : bins[size_t(binOf(c.y, v0, bv)) * kBins + binOf(c.x, u0, bu)])
      if (o != k && strictlyInside(triangle(o), c)) return std::nullopt;
  }
  HeightFieldPlane p;
  p.u = u, p.v = v, p.n = n;
  p.centre = mesh.anchor + p0 + 0.5 * (u0 + u1) * u + 0.5 * (v0 + v1) * v + 0.5 * (h0 + h1) * n;
  p.width_m = u1 - u0;
  p.height_m = v1 - v0;
  p.planar = planar && h1 - h0 <= kPlaneTol * std::max(u1 - u0, v1 - v0);
  return p;
}

ReceiverSheets splitIntoSheets(const EnvMesh& mesh) {
  ReceiverSheets out;
  const size_t nt = mesh.triangles.size();
  out.sheet_of_triangle.assign(nt, -1);
  if (nt == 0 || mesh.normals.size() != mesh.positions.size()) {
    out.unassigned = int(nt);
    return out;
  }
  // Each triangle's direction: the nearest of +x, -x, +y, -y, +z, -z to its normal (-1: degenerate).
  std::vector<int> dir(nt, -1);
  for (size_t k = 0; k < nt; ++k) {
    const Vec3 n = unitOf(orientedCross(mesh, mesh.triangles[k]));
    if (n == Vec3(0)) continue;
    int axis = 0;
    for (int a = 1; a < 3; ++a)
      if (std::abs(n[a]) > std::abs(n[axis])) axis = a;
    dir[k] = 2 * axis + (n[axis] < 0 ? 1 : 0);
  }
  // Welded vertices: positions on a grid of kWeldFraction of the extent.
  Vec3 lo(kInf), hi(-kInf);
  for (const glm::vec3& p : mesh.positions) lo = glm::min(lo, Vec3(p)), hi = glm::max(hi, Vec3(p));
  const double cell = std::max(kWeldFraction * glm::length(hi - lo), 1e-12);
  std::map<std::tuple<long long, long long, long long>, uint32_t> welded;
  std::vector<uint32_t> weld(mesh.positions.size());
  for (size_t i = 0; i < mesh.positions.size(); ++i) {
    const Vec3 p = (Vec3(mesh.positions[i]) - lo) / cell;
    const auto key = std::make_tuple(std::llround(p.x), std::llround(p.y), std::llround(p.z));
    weld[i] = welded.emplace(key, uint32_t(welded.size())).first->second;
  }
  // Connected pieces of each direction's triangles: triangles of one direction sharing a welded vertex.
  UnionFind uf(nt);
  std::map<std::pair<uint32_t, int>, uint32_t> first;  // (welded vertex, direction) -> a triangle
  for (size_t k = 0; k < nt; ++k) {
    if (dir[k] < 0) continue;
    for (uint32_t i : {mesh.triangles[k].x, mesh.triangles[k].y, mesh.triangles[k].z}) {
      const auto [it, inserted] = first.emplace(std::make_pair(weld[i], dir[k]), uint32_t(k));
      if (!inserted) uf.unite(uint32_t(k), it->second);
    }
  }
  std::map<uint32_t, size_t> piece_of_root;
  std::vector<std::vector<uint32_t>> pieces;
  for (size_t k = 0; k < nt; ++k) {
    if (dir[k] < 0) {
      ++out.unassigned;
      continue;
    }
    const auto [it, inserted] = piece_of_root.emplace(uf.find(uint32_t(k)), pieces.size());
    if (inserted) pieces.emplace_back();
    pieces[it->second].push_back(uint32_t(k));
  }
  for (std::vector<uint32_t>& piece : pieces) {
    const std::optional<HeightFieldPlane> plane = heightFieldPlane(mesh, &piece);
    if (!plane) {
      out.unassigned += int(piece.size());
      continue;
    }
    for (uint32_t k : piece) out.sheet_of_triangle[k] = int(out.triangles.size());
    out.planes.push_back(*plane);
    out.triangles.push_back(std::move(piece));
  }
  return out;
}

}  // namespace pvrr
