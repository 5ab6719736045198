#include "pvrr/method/vertex_stage.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>

#include "cad/local_refine.h"
#include "pvrr/base/error.h"
#include "pvrr/base/format.h"
#include "pvrr/method/eye_side.h"
#include "pvrr/optics/optics.h"
#include "pvrr/optics/spectrum.h"
#include "pvrr/trace/tracer.h"

namespace pvrr {

Vec3 channelWeight(const std::vector<ChannelSpec>& channels, size_t c) {
  if (channels[c].rgb_weight) return *channels[c].rgb_weight;
  if (channels.size() == 3) {
    Vec3 w(0.0);
    w[int(c)] = 1.0;
    return w;
  }
  return Vec3(1.0);
}

std::vector<ChannelSpec> dispersionChannels(const Scene& scene, int element, DispersionMode dispersion,
                                            int spectral_samples) {
  const Element& el = scene.elements.at(size_t(element));
  if (dispersion == DispersionMode::Off || el.type != ElementType::Lens || !el.dispersion_on) return {ChannelSpec{}};
  const std::vector<SpectralSample> samples =
      dispersion == DispersionMode::Rgb ? rgbSamples() : spectralSamples(spectral_samples);  // throws for n < 3
  std::vector<ChannelSpec> out;
  for (const SpectralSample& s : samples) out.push_back(ChannelSpec{s.wavelength_nm, s.rgb_weight});
  return out;
}

std::vector<ChannelSpec> dispersionChannels(const Scene& scene, int element, const std::string& dispersion,
                                            int spectral_samples) {
  const std::optional<DispersionMode> mode = parseName<DispersionMode>(dispersion);
  if (!mode)
    throw Error("render.dispersion: expected one of " + nameList<DispersionMode>() + "; got \"" + dispersion + "\"");
  return dispersionChannels(scene, element, *mode, spectral_samples);
}

std::vector<ChannelSpec> dispersionChannels(const Scene& scene, int element) {
  return dispersionChannels(scene, element, scene.render.dispersion, scene.render.spectral_samples);
}

// The reference tracer for the vertices whose rays are totally reflected inside a lens (VertexRay::traced):
// none for a mirror or without a depth budget.
static std::optional<Tracer> tirTracer(const RayScene& rays, const ElementFrame& f) {
  if (f.tir_trace_depth <= 0 || rays.scene().elements[size_t(f.element)].type != ElementType::Lens) return std::nullopt;
  TraceOptions to;
  to.max_depth = f.tir_trace_depth;
  return Tracer(rays, to);
}

// What the tracer shows along a vertex's incoming ray (direction d_in, meeting lens `element` at its vertex
// p) at wavelength wl: traced from 0.1 mm before the vertex, so that its first event is the lens there. A
// rim vertex's ray may graze past the outline and miss the lens: then dark, its seen point the far point
// along the flagged ray (vr.hit), as the tracer absorbs the light that leaves through the edge band.
static void traceTir(const Tracer& tracer, int element, VertexRay& vr, const Vec3& p, const Vec3& d_in, double wl) {
  const TraceResult t = tracer.trace(p - 1e-4 * d_in, d_in, wl);
  vr.traced = true;
  const bool entered = t.first_element == element;
  vr.traced_color = entered ? t.color : Vec3(0.0);
  vr.traced_seen = entered ? t.seen : vr.hit;
}

// Whether world point p lies in the clip volume `clip` widened by a quarter across the view.
static bool nearlyInView(const Mat4& clip, const Vec3& p) {
  const Vec4 c = clip * Vec4(p, 1.0);
  const double m = 1.25 * c.w;
  return c.w > 0 && std::abs(c.x) <= m && std::abs(c.y) <= m;
}

// Both traceVertexRays: the incoming ray of vertex i starts at (*origins)[i], or at `eye` when null.
static void traceVertexRaysFrom(const RayScene& rays, ElementFrame& f, const Vec3& eye,
                                const std::vector<Vec3>* origins, const VertexStageOptions& opt);

namespace {
double msSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}
}  // namespace

namespace {
cad::Tessellation tessellateElement(const Element& el, int tess_u, int tess_v) {
  return cad::tessellateGrid(el.frontSurface(), tess_u, tess_v, el.has_outline ? &el.outline : nullptr,
                             cad::TessellationOptions{true});
}
cad::Tessellation tessellateElement(const Element& el) { return tessellateElement(el, el.tess_u, el.tess_v); }

}  // namespace

const cad::Tessellation& ElementGridCache::get(const Scene& scene, int element) {
  const Element& el = scene.elements.at(size_t(element));
  if (entries_.size() <= size_t(element)) entries_.resize(size_t(element) + 1);
  Entry& e = entries_[size_t(element)];
  const cad::SurfacePtr surface = el.type == ElementType::Lens ? cad::SurfacePtr(el.lens.front) : el.surface;
  if (!e.surface || e.surface != surface || e.tess_u != el.tess_u || e.tess_v != el.tess_v ||
      e.has_outline != el.has_outline || (el.has_outline && e.outline != el.outline)) {
    e.grid = tessellateElement(el);
    e.surface = surface;
    e.tess_u = el.tess_u, e.tess_v = el.tess_v;
    e.refined_u = e.refined_v = 0;
    e.base = {};
    e.has_outline = el.has_outline;
    e.outline = el.outline;
  }
  return e.grid;
}

void ElementGridCache::refine(const Scene& scene, int element, int tess_u, int tess_v) {
  get(scene, element);  // the entry is current
  Entry& e = entries_[size_t(element)];
  if (tess_u == e.grid.grid_u && tess_v == e.grid.grid_v && !e.grid.locallyRefined()) return;
  e.grid = tessellateElement(scene.elements[size_t(element)], tess_u, tess_v);
  e.base = {};
  e.refined_u = tess_u, e.refined_v = tess_v;
}

void ElementGridCache::refineLocally(const Scene& scene, int element, const std::vector<uint8_t>& quad_levels) {
  get(scene, element);  // the entry is current
  Entry& e = entries_[size_t(element)];
  const cad::Tessellation& base = e.grid.locallyRefined() ? e.base : e.grid;
  const std::vector<uint8_t> levels = cad::balanceQuadLevels(base.grid_u, base.grid_v, quad_levels);
  if (e.grid.locallyRefined() ? levels == e.grid.quad_levels
                              : std::all_of(levels.begin(), levels.end(), [](uint8_t l) { return l == 0; }))
    return;
  if (std::all_of(levels.begin(), levels.end(), [](uint8_t l) { return l == 0; })) {
    e.grid = std::move(e.base);
    e.base = {};
    return;
  }
  const Element& el = scene.elements[size_t(element)];
  cad::Tessellation refined =
      cad::refineGridLocally(el.frontSurface(), base, levels, el.has_outline ? &el.outline : nullptr);
  if (!e.grid.locallyRefined()) e.base = std::move(e.grid);
  e.grid = std::move(refined);
}

ElementFrame prepareElement(const Scene& scene, int element, const cad::Tessellation* grid) {
  const Element& el = scene.elements[size_t(element)];
  ElementFrame f;
  f.element = element;
  f.grid = grid ? *grid : tessellateElement(el);
  f.world_pos.resize(f.grid.vertexCount());
  f.world_normal.resize(f.grid.vertexCount());
  for (size_t i = 0; i < f.grid.vertexCount(); ++i) {
    f.world_pos[i] = el.toWorldPoint(f.grid.positions[i]);
    f.world_normal[i] = glm::normalize(el.toWorldDir(f.grid.normals[i]));
  }
  f.patches_u = el.patches_u;
  f.patches_v = el.patches_v;
  return f;
}

void traceVertexRays(const RayScene& rays, ElementFrame& f, const Vec3& eye, const VertexStageOptions& opt) {
  traceVertexRaysFrom(rays, f, eye, nullptr, opt);
}

void traceVertexRays(const RayScene& rays, ElementFrame& f, const Vec3& eye, const std::vector<Vec3>& origins,
                     const VertexStageOptions& opt) {
  if (origins.size() != f.world_pos.size())
    throw Error("traceVertexRays: " + std::to_string(origins.size()) + " ray origins for " +
                std::to_string(f.world_pos.size()) + " vertices");
  traceVertexRaysFrom(rays, f, eye, &origins, opt);
}

static void traceVertexRaysFrom(const RayScene& rays, ElementFrame& f, const Vec3& eye,
                                const std::vector<Vec3>* origins, const VertexStageOptions& opt) {
  auto t0 = std::chrono::steady_clock::now();
  const Scene& scene = rays.scene();
  const Element& el = scene.elements[size_t(f.element)];
  const double eps = rays.epsilon();
  const double far = scene.render.far_distance_m;
  f.eye = eye;
  f.channels = opt.channels;
  f.tir_trace_depth = opt.tir_trace_depth;
  f.rays.assign(opt.channels.size(), std::vector<VertexRay>(f.world_pos.size()));
  const std::optional<Tracer> tracer = tirTracer(rays, f);
  // Where a mirror's rays cannot meet the mirror itself (RayScene::intersectBeside).
  std::shared_ptr<const RayScene::TangentClearance> clearance;
  if (el.type == ElementType::Mirror && opt.beside_own_mirror) {
    clearance = rays.tangentClearance(f.element, f.grid.positions, f.grid.normals);
    if (clearance->ahead.size() != f.world_pos.size()) clearance.reset();  // a mirror without candidates
  }
  // An eye exactly on a vertex of the element has no ray to it: say so in the scene's terms (otherwise the
  // fit later stops on a zero direction). An eye on the surface between vertices renders.
  if (!origins)
    for (size_t i = 0; i < f.world_pos.size(); ++i)
      if (!isFinite(glm::normalize(f.world_pos[i] - eye)))
        throw Error(scene.source_path + ": observer.eye lies on the surface of elements[" + std::to_string(f.element) +
                    "] (" + el.name + ") (at its vertex " + std::to_string(i) +
                    "), so no ray from the eye reaches it; move the eye off the surface");
  std::vector<char> beside(opt.channels.size() * f.world_pos.size(), 0);  // counted after the loops
  for (size_t c = 0; c < opt.channels.size(); ++c) {
    const double wl = opt.channels[c].wavelength_nm > 0 ? opt.channels[c].wavelength_nm : kLineD_nm;
    // Vertices are independent: one task per block of vertices.
    tbb::parallel_for(size_t(0), f.world_pos.size(), [&](size_t i) {
      VertexRay& vr = f.rays[c][i];
      const Vec3 p = f.world_pos[i], n = f.world_normal[i];
      const Vec3 d_in = glm::normalize(p - (origins ? (*origins)[i] : eye));
      if (el.type == ElementType::Mirror) {
        vr.origin = p;
        vr.dir = reflect(d_in, n);
      } else {
        const double n_glass = el.dispersion.index(wl);
        Refraction in = refract(d_in, n, 1.0, n_glass);
        if (in.tir) {  // cannot happen entering from air; kept for completeness
          vr.status = VertexStatus::Tir;
          vr.origin = p;
          vr.dir = d_in;
          vr.hit = p + far * d_in;
          return;
        }
        vr.internal_dir = in.direction;
        RayHit back = rays.intersectElementSurface(f.element, 1, p, in.direction, eps);
        // A rim vertex's internal ray may leave through the edge band within a fraction of a millimetre (the
        // vertex lies exactly on the rim). Continue it through the back surface's analytic extension, so the
        // rim triangles interpolate smoothly; the band where light truly leaves through the edge is then
        // thinner than the drift, usually below a pixel. A back surface from a CAD file is a NURBS sag graph
        // (cad::makeNurbsSag): its extension is the file's surface itself where it reaches past the outline
        // (a lens blank), then its second-order Taylor continuation.
        if (!back.hit()) back = rays.intersectElementSurface(f.element, 1, p, in.direction, eps, kInf, false);
        // A back point on the extension farther beyond the outline than a thin band as seen from the viewer
        // (a lens turned against the eye): the ray truly leaves through the edge, where the tracer stops it.
        // Only where the viewer sees the vertex or nearly (its clip volume widened by a quarter, as
        // cube_quality's): a rim vertex well out of view keeps its continuation, which steadies the fit.
        vr.edge_exit = back.hit() && el.has_outline && (!opt.viewer_clip || nearlyInView(*opt.viewer_clip, p)) &&
                       lensEdgeExit(el, back.point, glm::length(p - (origins ? (*origins)[i] : eye)));
        if (vr.edge_exit) vr.back_point = back.point;
        if (!back.hit() || vr.edge_exit) {
          // The internal ray leaves through the edge band: no back point (or one beyond the outline). Treated
          // like TIR: flagged, and with a depth budget it shows the tracer's answer for its ray (no map weight).
          vr.status = VertexStatus::Tir;
          vr.origin = p;
          vr.dir = in.direction;
          vr.hit = p + far * in.direction;
          // No map weight: with a tracer its own answer in place of the map's (whose far point says nothing
          // here); out through the edge dark even without one (envmap mode), as the tracer absorbs the light.
          if (tracer || vr.edge_exit) vr.transmittance = Vec3(0.0);
          if (tracer) traceTir(*tracer, f.element, vr, p, d_in, wl);
          return;
        }
        vr.back_point = back.point;
        vr.back_normal = back.normal;
        Refraction out = refract(in.direction, back.normal, n_glass, 1.0);
        const double cos_in = std::abs(glm::dot(d_in, n));
        const double cos_back = std::abs(glm::dot(in.direction, back.normal));
        const double trans = (1.0 - fresnelDielectric(cos_in, 1.0, n_glass)) *
                             (out.tir ? 0.0 : 1.0 - fresnelDielectric(cos_back, n_glass, 1.0));
        vr.transmittance = Vec3(trans);
        // A tinted lens's glass absorbs along the internal path, per channel (exactly 1 for clear glass).
        if (el.absorbing()) vr.transmittance *= el.internalTransmittance(glm::length(back.point - p));
        vr.origin = back.point;
        if (out.tir) {
          vr.status = VertexStatus::Tir;
          vr.dir = reflect(in.direction, back.normal);
          vr.hit = back.point + far * vr.dir;
          if (tracer) traceTir(*tracer, f.element, vr, p, d_in, wl);
          return;
        }
        vr.dir = out.direction;
      }
      bool leaves_clear = false;
      if (clearance) {
        const double dn = glm::dot(vr.dir, n);
        leaves_clear = (dn >= RayScene::kMinLeave && clearance->ahead[i] <= clearance->tolerance) ||
                       (dn <= -RayScene::kMinLeave && clearance->behind[i] >= -clearance->tolerance);
      }
      beside[c * f.world_pos.size() + i] = leaves_clear;
      const RayHit h = leaves_clear ? rays.intersectBeside(f.element, vr.origin, vr.dir, eps)
                                    : rays.intersect(vr.origin, vr.dir, eps);
      if (h.hit()) {
        vr.status = VertexStatus::Hit;
        vr.hit = h.point;
      } else {
        vr.status = VertexStatus::Escape;
        vr.hit = vr.origin + far * vr.dir;
      }
    });
  }
  f.rays_beside = int(std::count(beside.begin(), beside.end(), 1));
  f.rays_ms = msSince(t0);
}

namespace {

// The patch's rays for the fit and the view volume: flagged rays (TIR, or out through the lens's edge
// band) say nothing about where the scene is seen from and are left out, unless too few remain.
std::vector<ViewpointRay> patchRays(const ElementFrame& f, const cad::GridPatch& gp, int* excluded) {
  const std::vector<VertexRay>& rs = f.rays[f.rays.size() / 2];  // the middle (green) channel, or the only one
  std::vector<ViewpointRay> kept, all;
  kept.reserve(gp.vertices.size());
  all.reserve(gp.vertices.size());
  for (uint32_t vi : gp.vertices) {
    all.push_back(ViewpointRay{rs[vi].origin, rs[vi].dir, rs[vi].hit});
    if (rs[vi].status != VertexStatus::Tir) kept.push_back(all.back());
  }
  if (excluded) *excluded = int(all.size() - kept.size());
  if (kept.size() >= 3) return kept;
  return all;
}

// The rays of what the viewer sees of a patch whose viewpoint pv.fit.eye is fitted (ElementFrame::in_view),
// for its view volume: the unflagged rays of the vertices inside the viewer's clip volume and, where the
// viewer's view cuts a triangle (PatchView::view_edge), a ray for each cut point. The cut point's ray leaves
// the surface there towards the viewpoint's blend of the corners' hits: the unit directions from the
// viewpoint to the corners' hits, weighted as the rasteriser weights the corners' texture coordinates (the
// corners' own depths in the map camera are about equal, so by the barycentric weights alone); blending
// the hit points themselves would lean towards the farthest (an escaping ray's far point). Fewer than 3:
// the unflagged rays of every vertex of a seen triangle, then patchRays. `*out_of_view`: the patch's
// vertices whose own rays are not taken.
std::vector<ViewpointRay> seenRays(const ElementFrame& f, const cad::GridPatch& gp, const PatchView& pv,
                                   int* out_of_view) {
  const std::vector<VertexRay>& rs = f.rays[f.rays.size() / 2];
  const Vec3 e = pv.fit.eye;
  std::vector<ViewpointRay> out;
  int taken = 0;
  // The unflagged rays of the vertices whose in_view is at least `level`.
  const auto takeVertices = [&](char level) {
    for (uint32_t vi : gp.vertices)
      if (f.in_view[vi] >= level && rs[vi].status != VertexStatus::Tir) {
        out.push_back(ViewpointRay{rs[vi].origin, rs[vi].dir, rs[vi].hit});
        ++taken;
      }
  };
  takeVertices(2);
  for (const PatchView::ViewEdgeSample& c : pv.view_edge) {
    Vec3 origin(0.0), toward(0.0);
    double dist = 0;
    bool flagged = false;
    for (int j = 0; j < 3; ++j) {
      const VertexRay& r = rs[gp.vertices[c.corners[j]]];
      if (!(c.weights[j] > 0)) continue;
      flagged = flagged || r.status == VertexStatus::Tir;
      const double d = glm::length(r.hit - e);
      origin += c.weights[j] * r.origin;
      if (d > 0) toward += c.weights[j] * (r.hit - e) / d;
      dist += c.weights[j] * d;
    }
    const double len = glm::length(toward);
    if (flagged || !(len > 0) || !(dist > 0)) continue;
    const Vec3 hit = e + dist * toward / len, d = hit - origin;
    if (glm::length(d) > 0 && std::isfinite(hit.x + hit.y + hit.z)) out.push_back(ViewpointRay{origin, glm::normalize(d), hit});
  }
  if (out.size() < 3) {
    out.clear();
    taken = 0;
    takeVertices(1);
  }
  if (out.size() < 3) {
    out = patchRays(f, gp, nullptr);
    taken = int(out.size());
  }
  if (out_of_view) *out_of_view = int(gp.vertices.size()) - taken;
  return out;
}

// View volume, projective weights and texture coordinates of a patch whose viewpoint is fitted.
// `rays`: what the viewer sees of the patch (buildSeenPatchMap).
void buildPatchMap(const Scene& scene, const ElementFrame& f, const Element& el, PatchView& pv,
                   const std::vector<ViewpointRay>& rays) {
  const cad::GridPatch& gp = f.grid_patches[size_t(pv.patch)];
  ViewVolumeOptions vo;
  vo.scene_radius_m = scene.boundsRadius();
  vo.scene_center = 0.5 * (scene.bounds_min + scene.bounds_max);
  // Saddle and cylindrical surfaces: align the map's up vector with a principal direction (paper 4.3).
  const size_t centre_vertex = gp.vertices[gp.vertices.size() / 2];
  if (!f.grid.curvatures.empty()) {
    const cad::Curvature& k = f.grid.curvatures[centre_vertex];
    if (k.k1 * k.k2 < 0 || std::abs(k.k2) < 1e-3 * std::abs(k.k1)) vo.up_hint = glm::normalize(el.toWorldDir(k.dir2));
  }
  pv.volume = buildViewVolume(pv.fit.eye, rays, vo);
  // Concave mirrors and convex lenses: when most hits lie between the surface and the viewpoint (the
  // zooming region), render the map looking back from the viewpoint with a reversed depth test (paper's
  // future work). A patch with both kinds keeps the majority's volume and reports the rest.
  const size_t zooming = pv.volume.zooming.size();
  if (2 * zooming > rays.size()) {
    pv.volume = buildReversedViewVolume(pv.fit.eye, rays, vo);
    if (zooming < rays.size())
      appendNote(pv.volume.note,
                 std::to_string(rays.size() - zooming) + " hit(s) beyond the viewpoint are not in this reversed map");
  }
  projectPatchMap(f, pv);
}

// Where the viewer's clip volume cuts the patch's triangles that it sees in part (PatchView::view_edge):
// each such triangle clipped in the viewer's clip space (Sutherland-Hodgman against x = +-w, y = +-w and
// z = +-w, the planes clipOutcode tests), the new corners kept as barycentric weights. `clip`: each vertex's clip position.
std::vector<PatchView::ViewEdgeSample> viewEdge(const cad::GridPatch& gp, const std::vector<Vec4>& clip) {
  std::vector<PatchView::ViewEdgeSample> out;
  struct Corner {
    Vec4 c;
    Vec3 w;
  };
  const auto plane = [](int p, const Vec4& c) {
    switch (p) {
      case 0: return c.w + c.x;
      case 1: return c.w - c.x;
      case 2: return c.w + c.y;
      case 3: return c.w - c.y;
      case 4: return c.w + c.z;
      default: return c.w - c.z;
    }
  };
  for (const cad::Triangle& t : gp.triangles) {
    const Vec4 c[3] = {clip[gp.vertices[t.x]], clip[gp.vertices[t.y]], clip[gp.vertices[t.z]]};
    const unsigned a = clipOutcode(c[0]), b = clipOutcode(c[1]), d = clipOutcode(c[2]);
    if ((a & b & d) != 0 || (a | b | d) == 0) continue;  // not seen, or wholly inside
    std::vector<Corner> poly = {{c[0], Vec3(1, 0, 0)}, {c[1], Vec3(0, 1, 0)}, {c[2], Vec3(0, 0, 1)}};
    for (int p = 0; p < 6 && !poly.empty(); ++p) {
      std::vector<Corner> next;
      for (size_t i = 0; i < poly.size(); ++i) {
        const Corner &P = poly[i], &Q = poly[(i + 1) % poly.size()];
        const double dp = plane(p, P.c), dq = plane(p, Q.c);
        if (dp >= 0) next.push_back(P);
        if ((dp >= 0) != (dq >= 0)) {
          const double s = dp / (dp - dq);
          next.push_back({P.c + s * (Q.c - P.c), P.w + s * (Q.w - P.w)});
        }
      }
      poly = std::move(next);
    }
    for (const Corner& k : poly)
      if (std::max({k.w.x, k.w.y, k.w.z}) < 1.0)  // a new corner, not one of the triangle's own
        out.push_back({glm::u32vec3(t.x, t.y, t.z), k.w});
  }
  return out;
}

// buildPatchMap with the rays of what the viewer sees (seenRays; all the patch's rays without a viewer).
// A corner of a triangle seen in part whose hit lies behind the narrowed map camera would get a placeholder
// texture coordinate and colour the seen part of its triangle: its own ray then goes into the volume too.
// `all_rays`: patchRays of the patch when the caller has them.
void buildSeenPatchMap(const Scene& scene, const ElementFrame& f, const Element& el, PatchView& pv,
                       const std::vector<ViewpointRay>* all_rays = nullptr) {
  const cad::GridPatch& gp = f.grid_patches[size_t(pv.patch)];
  pv.rays_out_of_view = 0;
  if (f.in_view.empty() && all_rays) return buildPatchMap(scene, f, el, pv, *all_rays);
  if (f.in_view.empty()) return buildPatchMap(scene, f, el, pv, patchRays(f, gp, nullptr));
  std::vector<ViewpointRay> rays = seenRays(f, gp, pv, &pv.rays_out_of_view);
  buildPatchMap(scene, f, el, pv, rays);
  const std::vector<VertexRay>& rs = f.rays[f.rays.size() / 2];
  bool again = false;
  for (uint32_t vi : gp.vertices) {
    if (f.in_view[vi] != 1 || rs[vi].status == VertexStatus::Tir) continue;
    const Vec2 st = projectToTexture(pv.volume, rs[vi].hit);
    if (std::isfinite(st.x) && std::isfinite(st.y)) continue;
    rays.push_back(ViewpointRay{rs[vi].origin, rs[vi].dir, rs[vi].hit});
    --pv.rays_out_of_view;
    again = true;
  }
  if (again) buildPatchMap(scene, f, el, pv, rays);
}

void fitOnePatch(const Scene& scene, const ElementFrame& f, size_t patch_index, const Element& el, PatchView& pv,
                 const ViewpointOptions& vopt, const std::vector<Vec4>& clip) {
  pv.patch = int(patch_index);
  // The viewpoint is fitted to all the patch's rays, the view volume to those the viewer sees. (Fitting the
  // viewpoint to the seen rays alone fits them better, but interpolates worse between the vertices: on the
  // spectacle lens at 640 x 480, 1.02' median against 0.68'.)
  const cad::GridPatch& gp = f.grid_patches[patch_index];
  const std::vector<ViewpointRay> all_rays = patchRays(f, gp, &pv.rays_excluded);
  pv.view_edge = f.in_view.empty() || clip.empty() ? std::vector<PatchView::ViewEdgeSample>{} : viewEdge(gp, clip);
  // Seen when one of its triangles has all three vertices in view (conservative: those vertices may owe it
  // to neighbouring triangles).
  pv.in_view = f.in_view.empty() || std::any_of(gp.triangles.begin(), gp.triangles.end(), [&](const cad::Triangle& t) {
                 return f.in_view[gp.vertices[t.x]] && f.in_view[gp.vertices[t.y]] && f.in_view[gp.vertices[t.z]];
               });
  pv.fit = fitViewpoint(all_rays, vopt);
  buildSeenPatchMap(scene, f, el, pv, &all_rays);
}

// The automatic split stops where a patch would have fewer quads a side than this.
constexpr int kMinPatchQuads = 4;

// ElementFrame::in_view from each vertex's clip position: the vertices of every grid triangle not entirely
// outside one clip plane (clipOutcode), 2 for those inside the clip volume, 1 for the others.
std::vector<char> verticesInView(const ElementFrame& f, const std::vector<Vec4>& clip) {
  std::vector<unsigned> code(f.world_pos.size());
  for (size_t i = 0; i < f.world_pos.size(); ++i) code[i] = clipOutcode(clip[i]);
  std::vector<char> in(f.world_pos.size(), 0);
  for (const cad::Triangle& t : f.grid.triangles)
    if ((code[t.x] & code[t.y] & code[t.z]) == 0)
      for (uint32_t v : {t.x, t.y, t.z}) in[v] = code[v] == 0 ? 2 : 1;
  return in;
}

}  // namespace

void fitPatchViews(const Scene& scene, ElementFrame& f, const VertexStageOptions& opt) {
  auto t0 = std::chrono::steady_clock::now();
  f.in_view.clear();
  std::vector<Vec4> clip;
  if (opt.viewer_clip) {
    clip.resize(f.world_pos.size());
    for (size_t i = 0; i < f.world_pos.size(); ++i) clip[i] = *opt.viewer_clip * Vec4(f.world_pos[i], 1.0);
    f.in_view = verticesInView(f, clip);
    if (std::all_of(f.in_view.begin(), f.in_view.end(), [](char c) { return c == 2; })) f.in_view.clear();
  }
  const Element& el = scene.elements[size_t(f.element)];
  const double max_fov = opt.max_patch_fov_rad > 0 ? opt.max_patch_fov_rad : el.max_patch_fov_rad;
  int pu = el.patches_u, pv = el.patches_v;
  f.split_note.clear();
  f.split_exhausted = false;
  for (int round = 0;; ++round) {
    f.grid_patches = cad::splitGrid(f.grid, pu, pv);
    f.views.clear();
    f.views.resize(f.grid_patches.size());
    for (size_t p = 0; p < f.grid_patches.size(); ++p) fitOnePatch(scene, f, p, el, f.views[p], opt.viewpoint, clip);
    if (max_fov <= 0) break;
    double worst_x = 0, worst_y = 0;
    for (const PatchView& v : f.views) {
      if (!v.in_view) continue;  // not drawn: its field of view does not matter
      worst_x = std::max(worst_x, v.volume.fov_x_rad);
      worst_y = std::max(worst_y, v.volume.fov_y_rad);
    }
    if (std::max(worst_x, worst_y) <= max_fov) break;
    if (round >= opt.max_patch_splits) {
      f.split_exhausted = true;
      break;
    }
    // Split along the grid directions whose patches still have room: every patch keeps at least
    // kMinPatchQuads quads a side (a patch of one or two quads fits its viewpoint to a handful of rays and
    // costs a first pass of its own).
    // A locally refined grid counts as the uniform grid of its vertex count (its patches hold that many rays),
    // within one base quad a patch.
    const double density =
        f.grid.locallyRefined()
            ? std::sqrt(double(f.grid.vertexCount()) / (double(f.grid.grid_u) * double(f.grid.grid_v)))
            : 1.0;
    const int max_u = std::max(pu, std::min(f.grid.grid_u - 1, int(double(f.grid.grid_u - 1) * density) / kMinPatchQuads)),
              max_v = std::max(pv, std::min(f.grid.grid_v - 1, int(double(f.grid.grid_v - 1) * density) / kMinPatchQuads));
    const int next_u = std::min(pu * 2, max_u), next_v = std::min(pv * 2, max_v);
    if (next_u == pu && next_v == pv) {
      f.split_note = "patch field of view still above " + std::to_string(int(std::lround(degrees(max_fov)))) +
                     " deg at the finest split the grid allows (" + std::to_string(pu) + "x" + std::to_string(pv) + ")";
      f.split_exhausted = true;
      break;
    }
    f.split_note = "split to " + std::to_string(next_u) + "x" + std::to_string(next_v) +
                   " patches: a view volume's field of view exceeded " + std::to_string(degrees(max_fov)) + " deg";
    pu = next_u;
    pv = next_v;
  }
  f.patches_u = pu;
  f.patches_v = pv;
  assessFrameQuality(f);
  applyEyeSide(scene, f);
  f.fit_ms = msSince(t0);
}

}  // namespace pvrr

namespace pvrr {

void projectPatchMap(const ElementFrame& f, PatchView& pv) {
  const cad::GridPatch& gp = f.grid_patches[size_t(pv.patch)];
  // Vertices out of view (their triangles are clipped away by the viewer) take no part in the choice of
  // projective weights.
  auto counts = [&](uint32_t vi) { return f.in_view.empty() || !pv.in_view || f.in_view[vi]; };
  pv.q.assign(gp.vertices.size(), 1.0);
  bool all_in_front = true;
  const Mat4 world_to_clip = pv.volume.projection * pv.volume.view;
  for (size_t k = 0; k < gp.vertices.size(); ++k) {
    const Vec4 clip = world_to_clip * Vec4(f.world_pos[gp.vertices[k]], 1.0);
    pv.q[k] = clip.w;
    if (counts(gp.vertices[k])) all_in_front = all_in_front && clip.w > 0;
    else if (!(clip.w > 0)) pv.q[k] = 1.0;
  }
  if (!all_in_front) pv.q.assign(gp.vertices.size(), 1.0);
  const size_t channels = f.rays.size();
  pv.st.assign(channels, std::vector<Vec2>(gp.vertices.size()));
  for (size_t c = 0; c < channels; ++c)
    for (size_t k = 0; k < gp.vertices.size(); ++k) {
      // Finite always: a vertex out of view, or with a flagged ray (TIR: dark, transmittance 0) whose far
      // point lies behind the map camera, gets the map centre rather than NaN.
      Vec2 st = projectToTexture(pv.volume, f.rays[c][gp.vertices[k]].hit);
      if (!(std::isfinite(st.x) && std::isfinite(st.y))) st = Vec2(0.5);
      pv.st[c][k] = st;
    }
}

void moveRigidly(ElementFrame& f, const Mat4& motion) {
  auto point = [&](Vec3& p) { p = Vec3(motion * Vec4(p, 1.0)); };
  auto dir = [&](Vec3& d) { d = Vec3(motion * Vec4(d, 0.0)); };
  point(f.eye);
  for (Vec3& p : f.world_pos) point(p);
  for (Vec3& n : f.world_normal) dir(n);
  for (auto& channel : f.rays)
    for (VertexRay& r : channel) {
      point(r.origin);
      dir(r.dir);
      point(r.hit);
      dir(r.internal_dir);
      point(r.back_point);
      dir(r.back_normal);
      point(r.traced_seen);
    }
  for (PatchView& pv : f.views) {
    point(pv.fit.eye);
    point(pv.fit.closed_form_eye);
  }
}

void updateTextureCoordinates(const RayScene& rays, ElementFrame& f) {
  auto t0 = std::chrono::steady_clock::now();
  const Scene& scene = rays.scene();
  const double eps = rays.epsilon(), far = scene.render.far_distance_m;
  const std::optional<Tracer> tracer = tirTracer(rays, f);
  for (size_t c = 0; c < f.rays.size(); ++c) {
    std::vector<VertexRay>& channel = f.rays[c];
    const double wl = c < f.channels.size() && f.channels[c].wavelength_nm > 0 ? f.channels[c].wavelength_nm : kLineD_nm;
    tbb::parallel_for(size_t(0), channel.size(), [&](size_t i) {
      VertexRay& r = channel[i];
      if (r.status == VertexStatus::Tir) {
        r.hit = r.origin + far * r.dir;
        // The same incoming ray in the lens's frame; what lies beyond it has moved.
        if (r.traced && tracer) traceTir(*tracer, f.element, r, f.world_pos[i], glm::normalize(f.world_pos[i] - f.eye), wl);
        return;
      }
      const RayHit h = rays.intersect(r.origin, r.dir, eps);
      r.status = h.hit() ? VertexStatus::Hit : VertexStatus::Escape;
      r.hit = h.hit() ? h.point : r.origin + far * r.dir;
    });
  }
  const Element& el = scene.elements[size_t(f.element)];
  for (PatchView& pv : f.views) buildSeenPatchMap(scene, f, el, pv);
  f.rays_ms = msSince(t0);
}

double patchScreenPixels(const ElementFrame& f, const PatchView& pv, const Mat4& world_to_clip, int width, int height) {
  const cad::GridPatch& gp = f.grid_patches[size_t(pv.patch)];
  std::vector<Vec2> px(gp.vertices.size());
  std::vector<char> front(gp.vertices.size());
  for (size_t k = 0; k < gp.vertices.size(); ++k) {
    const Vec4 c = world_to_clip * Vec4(f.world_pos[gp.vertices[k]], 1.0);
    front[k] = c.w > 0;
    if (front[k])
      px[k] = Vec2((glm::clamp(c.x / c.w, -1.0, 1.0) + 1) * 0.5 * width, (glm::clamp(c.y / c.w, -1.0, 1.0) + 1) * 0.5 * height);
  }
  double area = 0;
  for (const auto& t : gp.triangles) {
    const int n_front = front[t.x] + front[t.y] + front[t.z];
    if (n_front == 0) continue;
    if (n_front < 3) return double(width) * double(height);  // reaches behind the eye: the whole image at most
    const Vec2 a = px[t.y] - px[t.x], b = px[t.z] - px[t.x];
    area += 0.5 * std::abs(a.x * b.y - a.y * b.x);
  }
  return area;
}

}  // namespace pvrr
