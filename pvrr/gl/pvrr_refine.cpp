// Pvrr mode's per-fragment refinement (render.refine; docs/method.md "Per-fragment refinement"): the refined
// elements' surface maps and counters, the refined mirror patches' vertex data (the P2 interpolant's edge
// midpoints; the quadratic split's exact rays at edge midpoints and triangle centres, and which triangles need
// the per-fragment search), the refinement's uniforms, and its part of the stage note. The draws themselves
// are pvrr_pass.cpp's drawPvrrElement.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>

#include "pvrr/gl/gl.h"
#include "pvrr/gl/impostor_maps.h"
#include "pvrr/gl/pvrr_pass.h"
#include "pvrr/method/map_footprint.h"
#include "pvrr/method/refine_plan.h"
#include "pvrr/optics/spectrum.h"

namespace pvrr::gl {

namespace {

// A refined lens's refractor height maps: the unit after its map's depth (impostor_maps.h's units; the RGB
// planes of pvrr_pass.cpp take kPlaneUnitG and the next).
constexpr int kRefineLensUnit = kRefineDepthUnit + 1;

}  // namespace

// A refined mirror's patch (one channel; shaders/pvrr_refine.glsl): every triangle with its own three vertices,
// each with the vertex's position, normal, texture coordinates, weight and traced fallback as uploadPatch gives
// them, its barycentric corner, exact hit depth along the map's forward and normalised surface parameters, and
// the triangle's P2 deviations: the exact surface point at each edge's midpoint (in the parameter domain) less
// the edge's mean, in the world frame.
void PvrrPass::uploadRefinedPatch(MeshBuffers& mb, const ElementFrame& f, const PatchView& pv, const Vec3& anchor,
                                  const std::vector<RefineTri>* tris) const {
  const cad::GridPatch& gp = f.grid_patches[size_t(pv.patch)];
  const Element& el = ctx.scene.elements[size_t(f.element)];
  const EdgeMidpoints& mids = edgeMidpoints(f);
  const cad::ParamDomain domain = el.frontSurface().domain();
  const Mat4 map_vp = relativeViewProj(pv.volume.projection, pv.volume.view, pv.volume.eye);
  const Vec3 weight = channelWeight(f.channels, 0);
  std::vector<float> data, corner;
  data.reserve(3 * gp.triangles.size() * kElementFloats);
  corner.reserve(3 * kElementFloats);
  auto put = [&](const Vec3& v) { corner.insert(corner.end(), {float(v.x), float(v.y), float(v.z)}); };
  const size_t n_tris = tris ? tris->size() : gp.triangles.size();
  for (size_t ti = 0; ti < n_tris; ++ti) {
    const auto& t = gp.triangles[tris ? (*tris)[ti].tri : ti];
    const uint32_t k[3] = {t.x, t.y, t.z}, vi[3] = {gp.vertices[t.x], gp.vertices[t.y], gp.vertices[t.z]};
    Vec3 dp[3];  // edges (0, 1), (1, 2), (2, 0)
    for (int e = 0; e < 3; ++e) {
      const uint32_t i = vi[e], j = vi[(e + 1) % 3];
      dp[e] = el.toWorldPoint(mids.at(edgeKey(i, j))) - 0.5 * (f.world_pos[i] + f.world_pos[j]);
    }
    corner.clear();
    for (int c = 0; c < 3; ++c) {
      const VertexRay& r = f.rays[0][vi[c]];
      put(f.world_pos[vi[c]] - anchor);
      put(f.world_normal[vi[c]]);
      const Vec2 st = pv.st[0][k[c]];
      const double q = pv.q[k[c]];
      put(Vec3(st.x * q, st.y * q, q));
      const double hit_depth = (map_vp * glm::dvec4(r.hit - pv.volume.eye, 1.0)).w;
      put(Vec3(c == 1 ? 1.0 : 0.0, c == 2 ? 1.0 : 0.0, hit_depth));
      put(dp[0]);
      put(pv.draw_traced ? Vec3(0.0) : weight * r.transmittance);
      put(dp[1]);
      put(dp[2]);
      const Vec2 uv = f.grid.params[vi[c]];
      put(Vec3((uv.x - domain.u0) / (domain.u1 - domain.u0), (uv.y - domain.v0) / (domain.v1 - domain.v0), 0.0));
      const bool traced = usesTraced(pv, r);
      const Vec3 colour = traced ? weight * r.traced_color : Vec3(0.0);
      corner.insert(corner.end(), {float(colour.x), float(colour.y), float(colour.z), traced ? 1.0f : 0.0f});
      put(traced ? r.traced_seen - anchor : Vec3(0.0));
    }
    if (!tris) {
      data.insert(data.end(), corner.begin(), corner.end());
      continue;
    }
    // A part: every attribute is affine on the triangle (the projective coordinate's three components too, as
    // they are interpolated before the division), so its corners take the triangle's at their barycentric
    // coordinates (a whole triangle's exactly its own).
    for (const Vec3& b : (*tris)[ti].b)
      for (size_t i = 0; i < kElementFloats; ++i)
        data.push_back(float(b.x * corner[i] + b.y * corner[kElementFloats + i] + b.z * corner[2 * kElementFloats + i]));
  }
  std::vector<uint32_t> idx(data.size() / kElementFloats);
  for (size_t i = 0; i < idx.size(); ++i) idx[i] = uint32_t(i);
  uploadMesh(mb, data, kElementLayout, idx);
}

// The quadratic split's tolerances. kQuadraticTolRad: a triangle whose quadratic interpolant misses the exact
// ray's coordinate at its centre by more than this angle (in the map, near its axis) is searched per fragment.
// The centre is where a smooth function's quadratic interpolant errs most; the misses above it are those of
// triangles across a knot line of the surface (its normal's third derivative jumps) or a depth edge, and of
// coarse grids. Measured on the car mirror (15 x 15, 392 triangles in view; docs/accuracy.md "Per-fragment
// refinement"), triangles searched and median / p95 at 640 x 480: 0.01' 180, 0.0090' / 0.074'; 0.1' 115,
// 0.0106' / 0.097'; 0.3' 97, 0.0112' / 0.118'; 1' 92, 0.0114' / 0.17' (all searched: 0.0084' / 0.074'). At
// 160 x 120 0.3' let the p95 reach 1.2' (0.1': 0.98'; all searched 0.61'). A test mirror's 9 x 9 grid
// (refine_test.cpp) misses by more than 0.1' nearly everywhere (121 to 125 of 128 searched), its 17 x 17 grid
// in 67 of 512.
// kQuadraticDepthTol: a node whose hit depth (along the map's forward) differs from its edge's or its
// triangle's corners' mean by more than this fraction lies across a depth edge, where no interpolant serves,
// whatever the centre says (a guard: on the car mirror the centre's test catches the same triangles).
constexpr double kQuadraticTolRad = 0.1 / 60.0 * kPi / 180.0;
constexpr double kQuadraticDepthTol = 0.3;
// How many times a triangle that fails is split in four, its parts tested alike (uploadQuadraticPatch).
constexpr int kQuadraticSplitLevels = 1;

// Two Gauss-Newton steps from the exact surface at parameters uv onto the view ray through the flat triangle's
// point `flat` (local frame), the exact normal there, and the reflected ray traced.
PvrrPass::RefineNode PvrrPass::traceRefineNode(const ElementFrame& f, Vec2 uv, Vec3 p, Vec3 du, Vec3 dv,
                                               const Vec3& flat) const {
  const Element& el = ctx.scene.elements[size_t(f.element)];
  const cad::Surface& surface = *el.surface;
  const cad::ParamDomain dom = surface.domain();
  const Vec3 eye = el.toLocalPoint(f.eye);
  RefineNode n;
  const Vec3 d = glm::normalize(flat - eye);
  for (int it = 0; it < 2; ++it) {
    const Vec3 w = p - eye, r = w - glm::dot(w, d) * d;
    const Vec3 a = du - glm::dot(du, d) * d, b = dv - glm::dot(dv, d) * d;
    const double aa = glm::dot(a, a), ab = glm::dot(a, b), bb = glm::dot(b, b), det = aa * bb - ab * ab;
    if (!(det > 1e-24 * aa * bb)) return n;
    const Vec2 g(glm::dot(a, r), glm::dot(b, r));
    uv -= Vec2(bb * g.x - ab * g.y, aa * g.y - ab * g.x) / det;
    if (!(uv.x >= dom.u0 && uv.x <= dom.u1 && uv.y >= dom.v0 && uv.y <= dom.v1)) return n;
    const cad::SurfaceDerivs e = surface.evaluate(uv.x, uv.y);
    p = e.p, du = e.du, dv = e.dv;
  }
  const Vec3 pw = el.toWorldPoint(p), nw = glm::normalize(el.toWorldDir(glm::cross(du, dv)));
  if (!isFinite(nw)) return n;
  const Vec3 view = glm::normalize(pw - f.eye), dir = view - 2.0 * glm::dot(view, nw) * nw;
  const RayHit h = ctx.rays.intersect(pw, dir, ctx.rays.epsilon());
  n.valid = true;
  n.escaped = !h.hit();
  n.hit = h.hit() ? h.point : pw + ctx.scene.render.far_distance_m * dir;
  return n;
}

const std::unordered_map<uint64_t, PvrrPass::RefineNode>& PvrrPass::refineNodes(const ElementFrame& f) const {
  edgeMidpoints(f);  // the cache entry of this surface and grid
  RefineMidpoints& c = refine_mids[size_t(f.element)];
  if (c.nodes_fresh) return c.nodes;
  const Element& el = ctx.scene.elements[size_t(f.element)];
  const cad::Surface& surface = *el.surface;
  const std::vector<Vec2>& params = f.grid.params;
  if (c.starts.empty()) {
    auto start = [&](uint64_t key, const Vec2& uv) {
      if (c.starts.count(key)) return;
      const cad::SurfaceDerivs d = surface.evaluate(uv.x, uv.y);
      c.starts[key] = {uv, d.p, d.du, d.dv};
    };
    for (const auto& t : f.grid.triangles) {
      const uint32_t v[3] = {t.x, t.y, t.z};
      for (int e = 0; e < 3; ++e) start(edgeKey(v[e], v[(e + 1) % 3]), 0.5 * (params[v[e]] + params[v[(e + 1) % 3]]));
      start(triangleKey(v[0], v[1], v[2]), (params[v[0]] + params[v[1]] + params[v[2]]) / 3.0);
    }
  }
  auto node = [&](const RefineMidpoints::Start& s, const Vec3& flat) {
    return traceRefineNode(f, s.uv, s.p, s.du, s.dv, flat);
  };
  c.nodes.clear();
  c.sub_nodes.clear();
  c.nodes.reserve(c.starts.size());
  const std::vector<Vec3>& pos = f.grid.positions;
  for (const auto& t : f.grid.triangles) {
    const uint32_t v[3] = {t.x, t.y, t.z};
    for (int e = 0; e < 3; ++e) {
      const uint64_t key = edgeKey(v[e], v[(e + 1) % 3]);
      if (!c.nodes.count(key)) c.nodes[key] = node(c.starts.at(key), 0.5 * (pos[v[e]] + pos[v[(e + 1) % 3]]));
    }
    const uint64_t key = triangleKey(v[0], v[1], v[2]);
    c.nodes[key] = node(c.starts.at(key), (pos[v[0]] + pos[v[1]] + pos[v[2]]) / 3.0);
  }
  c.nodes_fresh = true;
  c.generation = ++refine_generation;
  return c.nodes;
}

const PvrrPass::RefineNode& PvrrPass::refineSubNode(const ElementFrame& f, const uint32_t v[3], const Vec3& b) const {
  RefineMidpoints& c = refine_mids[size_t(f.element)];
  const uint64_t tri = uint64_t(v[0]) << 42 | uint64_t(v[1]) << 21 | v[2];
  const uint32_t q = uint32_t(std::lround(b.y * 48.0)) << 8 | uint32_t(std::lround(b.z * 48.0));
  auto [it, added] = c.sub_nodes.try_emplace({tri, q});
  if (added) {
    const Vec2 uv = b.x * f.grid.params[v[0]] + b.y * f.grid.params[v[1]] + b.z * f.grid.params[v[2]];
    const Vec3 flat = b.x * f.grid.positions[v[0]] + b.y * f.grid.positions[v[1]] + b.z * f.grid.positions[v[2]];
    const cad::SurfaceDerivs d = ctx.scene.elements[size_t(f.element)].surface->evaluate(uv.x, uv.y);
    it->second = traceRefineNode(f, uv, d.p, d.du, d.dv, flat);
  }
  return it->second;
}

size_t PvrrPass::uploadQuadraticPatch(MeshBuffers& mb, std::vector<RefineTri>* searched, RefineSplitCounts* counts,
                                      int levels, const ElementFrame& f, const PatchView& pv,
                                      const Vec3& anchor) const {
  const cad::GridPatch& gp = f.grid_patches[size_t(pv.patch)];
  const std::unordered_map<uint64_t, RefineNode>& nodes = refineNodes(f);
  const Mat4 map_vp = relativeViewProj(pv.volume.projection, pv.volume.view, pv.volume.eye);
  auto depth = [&](const Vec3& hit) { return (map_vp * glm::dvec4(hit - pv.volume.eye, 1.0)).w; };
  // Radians per unit of volume coordinate, at most (on the map's axis; less towards its edges).
  const double rad_per_st = 2.0 * longerExtentTan(pv.volume);
  const Vec3 weight = channelWeight(f.channels, 0);
  std::vector<float> data;
  auto put = [&](const Vec3& v) { data.insert(data.end(), {float(v.x), float(v.y), float(v.z)}); };
  searched->clear();
  *counts = RefineSplitCounts{};
  size_t count = 0;
  // A corner of a triangle or of a part: a vertex ray or a node, its volume coordinate and depth.
  struct Corner {
    bool valid = false, escaped = false;
    Vec2 st{0};
    double depth = 0;
  };
  for (uint32_t ti = 0; ti < gp.triangles.size(); ++ti) {
    const auto& t = gp.triangles[ti];
    const uint32_t k[3] = {t.x, t.y, t.z}, vi[3] = {gp.vertices[t.x], gp.vertices[t.y], gp.vertices[t.z]};
    bool vertices_ok = true;
    Corner vc[3];
    for (int c = 0; c < 3; ++c) {
      const VertexRay& r = f.rays[0][vi[c]];
      vc[c] = {true, r.status == VertexStatus::Escape, pv.st[0][k[c]], depth(r.hit)};
      vertices_ok = vertices_ok && r.status != VertexStatus::Tir && !usesTraced(pv, r);
    }
    if (!vertices_ok) {
      searched->push_back({ti});
      ++counts->whole_searched;
      continue;
    }
    // The node at barycentric b (of corners 0, 1, 2): the triangle's own at its edges' midpoints and centre.
    auto nodeAt = [&](const Vec3& b) -> const RefineNode& {
      for (int e = 0; e < 3; ++e)
        if (b[e] == 0.0 && b[(e + 1) % 3] == 0.5) return nodes.at(edgeKey(vi[(e + 1) % 3], vi[(e + 2) % 3]));
      if (b.x == b.y && b.y == b.z) return nodes.at(triangleKey(vi[0], vi[1], vi[2]));
      return refineSubNode(f, vi, b);
    };
    auto cornerAt = [&](const Vec3& b) {
      for (int c = 0; c < 3; ++c)
        if (b[c] == 1.0) return vc[c];
      const RefineNode& n = nodeAt(b);
      return Corner{n.valid, n.escaped, projectToTexture(pv.volume, n.hit), depth(n.hit)};
    };
    // A part with corners at b, tested; drawn quadratic if it passes, else split again or searched.
    auto part = [&](auto& self, const std::array<Vec3, 3>& b, int level) -> void {
      Corner C[3] = {cornerAt(b[0]), cornerAt(b[1]), cornerAt(b[2])};
      bool ok = C[0].valid && C[1].valid && C[2].valid && C[0].escaped == C[1].escaped && C[1].escaped == C[2].escaped;
      // A node on the corners' smooth surface: valid, of their kind, and (hits) at a depth near their mean.
      auto smooth = [&](const RefineNode& n, double mean, double least) {
        return n.valid && n.escaped == C[0].escaped &&
               (C[0].escaped || std::abs(depth(n.hit) - mean) <= kQuadraticDepthTol * least);
      };
      Vec2 D[3];  // edges (0, 1), (1, 2), (2, 0): the midpoint node's coordinate less the edge's mean
      Vec3 mid[3];
      for (int e = 0; e < 3; ++e) mid[e] = 0.5 * (b[e] + b[(e + 1) % 3]);
      for (int e = 0; e < 3 && ok; ++e) {
        const int e1 = (e + 1) % 3;
        const RefineNode& n = nodeAt(mid[e]);
        ok = smooth(n, 0.5 * (C[e].depth + C[e1].depth), std::min(C[e].depth, C[e1].depth));
        D[e] = projectToTexture(pv.volume, n.hit) - 0.5 * (C[e].st + C[e1].st);
      }
      if (ok) {
        const RefineNode& n = nodeAt((b[0] + b[1] + b[2]) / 3.0);
        ok = smooth(n, (C[0].depth + C[1].depth + C[2].depth) / 3.0, std::min({C[0].depth, C[1].depth, C[2].depth}));
        const Vec2 centre = (C[0].st + C[1].st + C[2].st) / 3.0 + 4.0 / 9.0 * (D[0] + D[1] + D[2]);
        const double miss = glm::length(centre - projectToTexture(pv.volume, n.hit)) * rad_per_st;
        ok = ok && miss <= kQuadraticTolRad;  // false for NaN
      }
      if (!ok && level < levels) {
        if (level == 0) ++counts->split;
        self(self, {b[0], mid[0], mid[2]}, level + 1);
        self(self, {mid[0], b[1], mid[1]}, level + 1);
        self(self, {mid[2], mid[1], b[2]}, level + 1);
        self(self, {mid[1], mid[2], mid[0]}, level + 1);
        return;
      }
      if (!ok) {
        searched->push_back({ti, b});
        if (level == 0) ++counts->whole_searched;
        else counts->searched_area += std::ldexp(1.0, -2 * level);
        return;
      }
      ++count;
      if (level == 0) ++counts->whole_quadratic;
      for (int c = 0; c < 3; ++c) {
        const Vec3& w = b[c];
        Vec3 pos(0.0), normal(0.0), transmittance(0.0);
        for (int i = 0; i < 3; ++i) {
          pos += w[i] * (f.world_pos[vi[i]] - anchor);
          normal += w[i] * f.world_normal[vi[i]];
          transmittance += w[i] * f.rays[0][vi[i]].transmittance;
        }
        put(pos);
        put(normal);
        put(Vec3(C[c].st, 1.0));
        put(Vec3(c == 1 ? 1.0 : 0.0, c == 2 ? 1.0 : 0.0, 0.0));
        put(Vec3(D[0], D[1].x));
        put(pv.draw_traced ? Vec3(0.0) : weight * transmittance);
        put(Vec3(D[1].y, D[2]));
        put(Vec3(0.0));
        put(Vec3(C[c].st, 1.0));
        data.insert(data.end(), {0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f});
      }
    };
    part(part, {Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)}, 0);
  }
  if (count == 0) return 0;
  std::vector<uint32_t> idx(data.size() / kElementFloats);
  for (size_t i = 0; i < idx.size(); ++i) idx[i] = uint32_t(i);
  uploadMesh(mb, data, kElementLayout, idx);
  return count;
}

void PvrrPass::drawRefinedSplit(const Program& search, const Program& quadratic, const ElementFrame& f, size_t v,
                                const Vec3& anchor, const glm::vec3& seen_offset, const glm::vec2& st_scale,
                                const glm::vec2& st_max) const {
  refineNodes(f);
  const uint64_t generation = refine_mids[size_t(f.element)].generation;
  if (refine_split.size() < ctx.scene.elements.size()) refine_split.resize(ctx.scene.elements.size());
  std::vector<RefineSplitMesh>& views = refine_split[size_t(f.element)];
  if (views.size() < f.views.size()) views.resize(f.views.size());
  RefineSplitMesh& m = views[v];
  // The nodes are recomputed in every frame in which anything moved (the eye, the element, the scene), and the
  // meshes' other inputs (the vertex rays, the patch view's volume and coordinates) only change in such frames.
  const bool settled = refine_mids[size_t(f.element)].settled || !refine_continuing;
  if (m.generation != generation || m.settled != settled) {
    std::vector<RefineTri> searched;
    m.n_quadratic =
        uploadQuadraticPatch(m.quadratic, &searched, &m.counts, settled ? kQuadraticSplitLevels : 0, f, f.views[v], anchor);
    // The searched parts' triangles drawn whole, once each, behind the quadratic parts (drawn first, in the same
    // plane): the depth test leaves the search exactly the parts that failed, and llvmpipe shades each 4 x 4
    // block of a triangle's searched pixels once, where the parts drawn as triangles of their own shaded the
    // blocks along their shared edges once for each part (docs/performance.md "Per-fragment refinement", fourth
    // round: 0.02 of the unrefined frame).
    std::vector<RefineTri> whole;
    std::set<uint32_t> had;
    for (const RefineTri& t : searched)
      if (had.insert(t.tri).second) whole.push_back({t.tri});
    m.n_searched = whole.size();
    if (!whole.empty()) uploadRefinedPatch(m.searched, f, f.views[v], anchor, &whole);
    m.generation = generation;
    m.settled = settled;
  }
  refine_counts.whole_quadratic += m.counts.whole_quadratic;
  refine_counts.whole_searched += m.counts.whole_searched;
  refine_counts.split += m.counts.split;
  refine_counts.searched_area += m.counts.searched_area;
  if (m.n_quadratic > 0) {
    quadratic.use();
    quadratic.set("u_seen_offset", seen_offset);
    quadratic.set("u_st_scale", st_scale);
    quadratic.set("u_st_max", st_max);
    draw(m.quadratic);
    search.use();
  }
  if (m.n_searched > 0) {
    // Behind the quadratic parts of the same triangles by a few depth units, so that none of their pixels passes.
    glEnable(GL_POLYGON_OFFSET_FILL);
    glPolygonOffset(1.0f, 4.0f);
    draw(m.searched);
    glDisable(GL_POLYGON_OFFSET_FILL);
  }
}

void PvrrPass::prepareRefinement(bool continuing) {
  const int steps = ctx.scene.render.refine;
  refine_counts = RefineSplitCounts{};
  // Nodes still fresh here (prepare clears them where anything moved) were computed in an earlier frame.
  for (RefineMidpoints& m : refine_mids) m.settled = m.nodes_fresh;
  refine_continuing = continuing;
  refine_skip.assign(frames.size(), "off");
  refine_lens = false;
  if (steps <= 0) return;
  bool any = false;
  for (size_t e = 0; e < frames.size(); ++e) {
    refine_skip[e] = refineSkipReason(ctx.scene, frames[e], steps);
    if (!refine_skip[e].empty()) continue;
    any = true;
    if (!surface_maps) surface_maps = std::make_unique<ImpostorMaps>(ctx.scene, ctx.options, ctx.max_texture_units);
    if (ctx.scene.elements[e].type == ElementType::Lens) {
      surface_maps->updateLensMaps(e);
      refine_lens = true;
    } else {
      surface_maps->updateMirrorMaps(e);
    }
  }
  if (!any) return;
  if (!refine_sampler) {
    glGenSamplers(1, &refine_sampler);
    glSamplerParameteri(refine_sampler, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glSamplerParameteri(refine_sampler, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glSamplerParameteri(refine_sampler, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glSamplerParameteri(refine_sampler, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  }
  if (refine_queries.size() < frames.size()) {
    const size_t had = refine_queries.size();
    refine_queries.resize(frames.size());
    glGenQueries(GLsizei(frames.size() - had), refine_queries.data() + had);
  }
  // The counters, zeroed before the frame's draws (allocated once; read after the frame: finishedNote).
  if (!refine_counters) {
    glGenBuffers(1, &refine_counters);
    glBindBuffer(GL_ATOMIC_COUNTER_BUFFER, refine_counters);
    glBufferData(GL_ATOMIC_COUNTER_BUFFER, 3 * sizeof(GLuint), nullptr, GL_DYNAMIC_READ);
  }
  glBindBuffer(GL_ATOMIC_COUNTER_BUFFER, refine_counters);
  glClearBufferData(GL_ATOMIC_COUNTER_BUFFER, GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, nullptr);
  glBindBufferBase(GL_ATOMIC_COUNTER_BUFFER, 0, refine_counters);
  checkGlError("zeroing the refinement's counters");
}

const PvrrPass::EdgeMidpoints& PvrrPass::edgeMidpoints(const ElementFrame& f) const {
  if (refine_mids.size() < ctx.scene.elements.size()) refine_mids.resize(ctx.scene.elements.size());
  RefineMidpoints& c = refine_mids[size_t(f.element)];
  const Element& el = ctx.scene.elements[size_t(f.element)];
  if (c.surface == el.surface && c.params == f.grid.params) return c.mids;
  c.surface = el.surface;
  c.params = f.grid.params;
  c.mids.clear();
  c.starts.clear();
  c.nodes.clear();
  c.sub_nodes.clear();
  c.nodes_fresh = false;
  for (const auto& t : f.grid.triangles) {
    const uint32_t v[3] = {t.x, t.y, t.z};
    for (int e = 0; e < 3; ++e) {
      const uint64_t key = edgeKey(v[e], v[(e + 1) % 3]);
      if (c.mids.count(key)) continue;
      const Vec2 uv = 0.5 * (c.params[v[e]] + c.params[v[(e + 1) % 3]]);
      c.mids[key] = el.surface->evaluate(uv.x, uv.y).p;
    }
  }
  return c.mids;
}

// A mirror: its surface maps on the impostor mode's units (ImpostorMaps::setMirrorMaps; only the normal is read),
// then the depth of the patch view's map; all filtered linearly. A lens: the map's depth there, its refractor
// height maps after it (read with texelFetch), the glass's index at each channel's wavelength and the channel
// that gives the seen point.
void PvrrPass::setRefinement(const Program& p, const ElementFrame& f, size_t seen_channel) const {
  const Element& el = ctx.scene.elements[size_t(f.element)];
  if (el.type == ElementType::Lens) {
    surface_maps->setLensMaps(p, size_t(f.element), kRefineLensUnit);
    glm::vec3 index(0.0f);
    for (size_t c = 0; c < 3 && c < f.channels.size(); ++c) {
      const double wl = f.channels[c].wavelength_nm > 0 ? f.channels[c].wavelength_nm : kLineD_nm;
      index[int(c)] = float(el.dispersion.index(wl));  // as the vertex stage refracts channel c
    }
    p.set("u_channel_index", index);
    p.set("u_seen_channel", int(seen_channel));
  } else {
    surface_maps->setMirrorMaps(p, size_t(f.element));
  }
  p.set("u_map_depth", kRefineDepthUnit);
}

void PvrrPass::unsetRefinement() const {
  for (int unit = kElementMapsUnit; unit <= kRefineDepthUnit; ++unit) glBindSampler(GLuint(unit), 0);
}

void PvrrPass::setRefinementView(const Program& p, int element, const PatchView& pv, const Framebuffer& map,
                                  int side) const {
  const bool on = refineViewSkipReason(pv).empty();
  p.set("u_refine", on ? 1 : 0);
  if (!on) return;
  glActiveTexture(GLenum(GL_TEXTURE0 + kRefineDepthUnit));
  glBindTexture(GL_TEXTURE_2D, map.depthTexture());
  // A lens's planes lie on the surface maps' units: only the depth takes the sampler.
  const bool lens = ctx.scene.elements[size_t(element)].type == ElementType::Lens;
  for (int unit = lens ? kRefineDepthUnit : kElementMapsUnit; unit <= kRefineDepthUnit; ++unit)
    glBindSampler(GLuint(unit), refine_sampler);
  p.set("u_map_vp", toFloat(relativeViewProj(pv.volume.projection, pv.volume.view, pv.volume.eye)));
  const Mat4& P = pv.volume.projection;
  p.set("u_depth_lin", glm::vec3(float(P[2][2]), float(P[3][2]), float(pv.volume.near_m)));
  // A depth edge: neighbouring texels' depths differ more than a surface's at 89 deg incidence would
  // (tan 89 deg ~ 57 times the texel's angle), and by at least 5 %.
  p.set("u_edge", float(std::max(0.05, 57.0 * longerExtentTan(pv.volume) / std::max(side, 1))));
}

bool PvrrPass::refineCountThisFrame(const PassCamera& eye, const Framebuffer& target) {
  std::vector<double> key;
  if (ctx.scene.render.refine <= 0) return false;
  key.push_back(ctx.scene.render.refine);
  key.push_back(double(first_pass_serial));
  key.push_back(target.width());
  key.push_back(target.height());
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) key.push_back(eye.view_proj[c][r]);
  for (int i = 0; i < 3; ++i) key.insert(key.end(), {eye.origin[i], eye.rays_from[i]});
  for (size_t e = 0; e < refine_skip.size(); ++e) {
    const bool refined = refine_skip[e].empty();
    // A refined mirror's split meshes follow its nodes (recomputed in this frame when not fresh) and whether
    // they are split (drawRefinedSplit).
    const bool fresh = e < refine_mids.size() && refine_mids[e].nodes_fresh;
    const bool settled = e < refine_mids.size() && (refine_mids[e].settled || !refine_continuing);
    key.push_back(refined ? 1 + 2 * fresh + 4 * settled : 0);
  }
  const bool count = !refine_nothing_moved || key != refine_count_key;
  if (count) refine_count_key = std::move(key);
  return count;
}

// The refinement's part of the second pass's note, read once the frame's draws have finished (the renderer's
// glFinish), so that no draw waits on the counts: the second pass's fragments of the refined elements, those
// that kept the interpolated coordinate, and the elements not refined with why. A frame that drew what the last
// counted frame drew (refineCountThisFrame) repeats its counts.
std::string PvrrPass::finishedNote(const std::string& note) const {
  const int steps = ctx.scene.render.refine;
  if (steps <= 0) return note;
  bool any = false;
  const std::string skipped = refinementSkips(&any);
  std::string refine = "refine (" + std::to_string(steps) + " steps):";
  if (any) {
    if (refine_count_frame) {
      GLuint n[3] = {0, 0, 0};
      glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT | GL_ATOMIC_COUNTER_BARRIER_BIT);
      glBindBuffer(GL_ATOMIC_COUNTER_BUFFER, refine_counters);
      glGetBufferSubData(GL_ATOMIC_COUNTER_BUFFER, 0, sizeof(n), n);
      uint64_t drawn = 0;
      for (size_t e = 0; e < refine_skip.size(); ++e) {
        if (!refine_skip[e].empty()) continue;
        GLuint samples = 0;
        glGetQueryObjectuiv(refine_queries[e], GL_QUERY_RESULT, &samples);
        drawn += samples;
      }
      refine_last_drawn = drawn;
      refine_last_n = {n[0], n[1], n[2]};
    }
    const uint64_t drawn = refine_last_drawn;
    const std::array<unsigned, 3>& n = refine_last_n;
    refine += " " + std::to_string(drawn) + " fragments drawn, " + std::to_string(n[0]) +
              " kept the interpolated coordinate (search ended off the map's surface), " + std::to_string(n[1]) +
              " kept it where the view ray missed the exact surface";
    if (refine_lens)
      refine += ", " + std::to_string(n[2]) + " kept it where a lens's exact path is totally reflected inside";
    const RefineSplitCounts& sc = refine_counts;
    if (sc.whole_quadratic + sc.whole_searched + sc.split > 0) {
      char area[32];
      std::snprintf(area, sizeof(area), "%.2f", sc.searched_area);
      refine += "; of " + std::to_string(sc.whole_quadratic + sc.whole_searched + sc.split) + " mirror triangles " +
                std::to_string(sc.whole_searched) + " searched whole and " + std::to_string(sc.split) +
                " split in four (parts searched: " + area +
                " triangles' area), the others quadratic (exact rays at their edges' midpoints)";
    }
  }
  if (!skipped.empty()) refine += std::string(any ? ";" : "") + " not refined:" + skipped;
  return note.empty() ? refine : note + "; " + refine;
}

// The elements not refined, with why ("" when none); *any: whether some element is refined.
std::string PvrrPass::refinementSkips(bool* any) const {
  std::string skipped;
  *any = false;
  for (size_t e = 0; e < refine_skip.size(); ++e) {
    if (refine_skip[e].empty())
      *any = true;
    else
      skipped += (skipped.empty() ? " " : "; ") + ctx.scene.elements[e].name + " (" + refine_skip[e] + ")";
  }
  return skipped;
}

}  // namespace pvrr::gl
