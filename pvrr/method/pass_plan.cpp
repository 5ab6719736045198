#include "pvrr/method/pass_plan.h"

#include <algorithm>
#include <cmath>

#include "pvrr/base/format.h"
#include "pvrr/optics/spectrum.h"
#include "pvrr/method/view_volume.h"

namespace pvrr {

// Each patch's view volume is narrower, so its texels cover a smaller angle. At least 128: full-size maps for
// many patches cost memory and time without a visible gain (docs/method.md "Measurements behind the design").
int patchMapSize(int map_size, size_t patches) {
  if (patches <= 4 || map_size <= 128) return map_size;
  const double shrink = std::ceil(std::sqrt(double(patches) / 4.0));
  return std::max(128, int(double(map_size) / shrink));
}

size_t patchesInView(const ElementFrame& f) {
  return size_t(std::count_if(f.views.begin(), f.views.end(), [](const PatchView& v) { return v.in_view; }));
}

int topLevelMapSide(const Scene& scene, const ElementFrame& f, const PatchView& pv, const PassPlanOptions& options) {
  const int size = patchMapSize(options.map_size, std::max<size_t>(1, patchesInView(f)));
  if (!(options.map_texels_per_pixel > 0)) return size;
  const Observer& ob = scene.observer;
  const double pixels = patchScreenPixels(f, pv, ob.visibilityProjection() * ob.view(), ob.width, ob.height);
  return mapSideForPixels(pv.volume, pixels, options.map_texels_per_pixel, size);
}

// A nested element covers part of its parent's map, which covers part of the image, so half the parent's
// texels still exceed the pixels it covers in the shipped scenes (full-size nested maps: docs/method.md
// "Measurements behind the design").
int nestedMapSize(int parent) { return parent <= 128 ? parent : std::max(128, parent / 2); }

bool mayBeInVolume(const std::vector<Vec3>& points, const Mat4& m) {
  unsigned all = 0x3f;
  for (const Vec3& p : points) {
    all &= clipOutcode(m * Vec4(p, 1.0));
    if (!all) return true;
  }
  return all == 0;
}

int elementInterfaces(const Element& el) { return el.type == ElementType::Lens ? 2 : 1; }

bool beyondDepth(const Scene& scene, const ElementFrame& f) {
  return elementInterfaces(scene.elements[size_t(f.element)]) > scene.render.max_depth;
}

bool topLevelVisible(const Scene& scene, const ElementFrame& f, size_t v) {
  const Observer& ob = scene.observer;
  return f.views[v].in_view && mayBeInVolume(f.world_pos, ob.visibilityProjection() * ob.view()) &&
         !beyondDepth(scene, f);
}

bool rgbLens(const Element& el, const ElementFrame& f) {
  if (el.type != ElementType::Lens || f.rays.size() != 3 || f.channels.size() != 3) return false;
  for (size_t c = 0; c < 3; ++c)
    if (channelWeight(f.channels, c) != Vec3(c == 0, c == 1, c == 2)) return false;
  return true;
}

size_t PassPlan::visiblePasses() const {
  return size_t(std::count_if(passes.begin(), passes.end(), [](const MapPass& m) { return m.visible; }));
}

std::vector<Vec3> rayOrigins(const ElementFrame& owner, const PatchView& pv, const std::vector<Vec3>& points) {
  const cad::GridPatch& gp = owner.grid_patches[size_t(pv.patch)];
  const size_t fc = owner.rays.size() / 2;
  const std::vector<Vec2>& st = pv.st[fc];
  std::vector<Vec3> out(points.size(), pv.volume.eye);
  // A vertex out of the viewer's view or with a flagged ray (TIR, edge band) has placeholder texture
  // coordinates: its triangles say nothing about where the map shows a point.
  const auto usable = [&](uint32_t k) {
    const uint32_t vi = gp.vertices[k];
    return (owner.in_view.empty() || owner.in_view[vi]) && owner.rays[fc][vi].status != VertexStatus::Tir;
  };
  for (size_t i = 0; i < points.size(); ++i) {
    const Vec2 p = projectToTexture(pv.volume, points[i]);
    if (!std::isfinite(p.x) || !std::isfinite(p.y)) continue;
    double best = -kInf, l[3] = {0, 0, 0};
    const cad::Triangle* best_tri = nullptr;
    for (const cad::Triangle& t : gp.triangles) {
      if (!usable(t.x) || !usable(t.y) || !usable(t.z)) continue;
      const Vec2 a = st[t.x], e1 = st[t.y] - a, e2 = st[t.z] - a, r = p - a;
      const double den = e1.x * e2.y - e2.x * e1.y;
      if (!(std::abs(den) > 0)) continue;
      const double l1 = (r.x * e2.y - e2.x * r.y) / den, l2 = (e1.x * r.y - r.x * e1.y) / den, l0 = 1 - l1 - l2;
      const double m = std::min(l0, std::min(l1, l2));
      if (m > best) {
        best = m;
        l[0] = l0;
        l[1] = l1;
        l[2] = l2;
        best_tri = &t;
        if (m >= 0) break;
      }
    }
    if (!best_tri || best < -0.5) continue;
    const auto origin = [&](uint32_t k) { return owner.rays[fc][gp.vertices[k]].origin; };
    out[i] = l[0] * origin(best_tri->x) + l[1] * origin(best_tri->y) + l[2] * origin(best_tri->z);
  }
  return out;
}

PassPlan planPasses(const Scene& scene, const RayScene& rays, const std::vector<ElementFrame>& frames,
                    const std::vector<VertexStageOptions>& opts, const PassPlanOptions& options,
                    const std::vector<std::array<int, 2>>* top_size_side) {
  PassPlan plan;
  std::vector<MapPass>& passes = plan.passes;
  size_t slot = 0;
  for (const ElementFrame& f : frames)
    for (size_t v = 0; v < f.views.size(); ++v) {
      const bool given = top_size_side && slot < top_size_side->size();
      passes.push_back({&f, v, elementInterfaces(scene.elements[size_t(f.element)]), slot,
                        given ? (*top_size_side)[slot][0] : patchMapSize(options.map_size, std::max<size_t>(1, patchesInView(f))),
                        given ? (*top_size_side)[slot][1] : topLevelMapSide(scene, f, f.views[v], options), true, {}});
      ++slot;
    }
  plan.top = passes.size();
  // A top-level element outside the observer's view needs no map (its second-pass triangles are clipped).
  for (MapPass& mp : passes) mp.visible = topLevelVisible(scene, *mp.owner, mp.view);
  const int max_depth = scene.render.max_depth;
  for (size_t i = 0; i < passes.size(); ++i) {
    if (!passes[i].visible) continue;
    const ElementFrame& owner = *passes[i].owner;
    const PatchView& pv = owner.views[passes[i].view];
    const int depth = passes[i].depth;
    for (size_t b = 0; b < frames.size(); ++b) {
      if (int(b) == owner.element || !mayBeInVolume(frames[b].world_pos, pv.volume.projection * pv.volume.view)) continue;
      const Element& el = scene.elements[b];
      const size_t views_needed = size_t(std::max(1, el.patches_u * el.patches_v));
      // The tracer absorbs at an element event with depth >= max_depth; a lens's back surface is the
      // event after its front, so the element is dark unless all its interfaces come before the limit.
      const bool too_deep = depth + elementInterfaces(el) > max_depth;
      if (too_deep || plan.visiblePasses() + views_needed > kMaxFirstPasses) {
        plan.budget_hit = plan.budget_hit || !too_deep;
        ++plan.dark;
        passes[i].nested.push_back({int(b), nullptr, 0});
        continue;
      }
      // The element as the owner's patch sees it: the geometry is the top-level frame's; each vertex's
      // incoming ray comes from where the owner's rays that reach it leave the owner (rayOrigins), and
      // the fit gives its own viewpoints and maps.
      auto nf = std::make_unique<ElementFrame>();
      nf->element = int(b);
      nf->grid = frames[b].grid;
      nf->world_pos = frames[b].world_pos;
      nf->world_normal = frames[b].world_normal;
      nf->patches_u = el.patches_u;
      nf->patches_v = el.patches_v;
      VertexStageOptions nested_opt = opts[b];
      nested_opt.viewer_clip = pv.volume.projection * pv.volume.view;  // seen by the owner's map camera
      nested_opt.tir_trace_depth = max_depth - depth;  // the events before this element are spent
      traceVertexRays(rays, *nf, pv.volume.eye, rayOrigins(owner, pv, nf->world_pos), nested_opt);
      fitPatchViews(scene, *nf, nested_opt);
      if (plan.visiblePasses() + patchesInView(*nf) > kMaxFirstPasses) {  // an automatic split needed more maps
        plan.budget_hit = true;
        ++plan.dark;
        passes[i].nested.push_back({int(b), nullptr, 0});
        continue;
      }
      const size_t first = slot;
      // The texture at half the parent's texture (it never reallocates), the rendered side at half the
      // parent's rendered side.
      const int size = nestedMapSize(passes[i].size), side = std::min(size, nestedMapSize(passes[i].side));
      for (size_t v = 0; v < nf->views.size(); ++v)  // a patch the owner's map camera cannot see: no map
        passes.push_back({nf.get(), v, depth + elementInterfaces(el), slot++, size, side, nf->views[v].in_view, {}});
      passes[i].nested.push_back({int(b), nf.get(), first});
      plan.nested_frames.push_back(std::move(nf));
    }
  }
  return plan;
}

bool reuseMaps(const Scene& scene, std::vector<ElementFrame>& frames, const FrameCache& cache,
               const PassPlanOptions& options, uint64_t held_serial, const std::vector<bool>& planes_slots,
               std::string* note) {
  size_t slots = 0;
  for (const ElementFrame& f : frames) slots += f.views.size();
  if (cache.maps.empty() || cache.maps_serial != held_serial) {
    *note = cache.maps_serial != held_serial && !cache.maps.empty()
                ? "this renderer drew other maps since"
                : "no reusable maps (the last first pass was not widened: a first frame, or nested passes)";
    return false;
  }
  if (cache.maps.size() != slots) {
    *note = "the patches changed";
    return false;
  }
  double worst_parallax = 0, worst_move = 0;
  std::vector<char> visible(slots, 0);  // per slot: the observer sees it (the views to check and to move)
  size_t slot = 0;
  for (const ElementFrame& f : frames)
    for (size_t v = 0; v < f.views.size(); ++v, ++slot) {
      const FrameCache::Map& m = cache.maps[slot];
      if (m.element != f.element || m.view != v) {
        *note = "the patches changed";
        return false;
      }
      visible[slot] = topLevelVisible(scene, f, v);
      if (!visible[slot]) continue;
      const PatchView& pv = f.views[v];
      const ViewVolume &W = m.volume, &V = pv.volume;
      if (!m.rendered || V.backward || W.backward) {
        *note = !m.rendered ? "a patch came into view" : "a reversed (zooming) map is not reused";
        return false;
      }
      const bool planes = slot < planes_slots.size() && planes_slots[slot];
      if (planes != rgbLens(scene.elements[size_t(f.element)], f)) {
        *note = "the colour channels changed";
        return false;
      }
      if (!frustumContains(W, V)) {
        *note = "a view left its map's margin";
        return false;
      }
      const double need = topLevelMapSide(scene, f, pv, options) / longerExtentTan(V),
                   have = m.side / longerExtentTan(W);
      if (have < need / 1.15 || have > 2 * need) {
        *note = "the texel density needed changed";
        return false;
      }
      double nearest = kInf;
      const cad::GridPatch& gp = f.grid_patches[size_t(pv.patch)];
      for (const auto& channel : f.rays)
        for (uint32_t vi : gp.vertices)
          if ((f.in_view.empty() || f.in_view[vi]) && channel[vi].status == VertexStatus::Hit)
            nearest = std::min(nearest, glm::length(channel[vi].hit - V.eye));
      if (!std::isfinite(nearest)) {  // every ray escaped or was flagged: nothing bounds the parallax
        *note = "no hit point bounds the parallax";
        return false;
      }
      const double move = glm::length(V.eye - W.eye), parallax = move / nearest / minTexelAngle(W, m.side);
      if (!(parallax <= 0.25)) {
        *note = "the viewpoint moved too far (parallax " + fmt("%.2g", parallax) + " texel)";
        return false;
      }
      const Mat4 map_clip = W.projection * W.view;
      for (const ElementFrame& b : frames)
        if (b.element != f.element && mayBeInVolume(b.world_pos, map_clip)) {
          *note = "an element reaches into a map's volume";
          return false;
        }
      worst_parallax = std::max(worst_parallax, parallax);
      worst_move = std::max(worst_move, move);
    }
  slot = 0;
  for (ElementFrame& f : frames)
    for (size_t v = 0; v < f.views.size(); ++v, ++slot)
      if (visible[slot]) {
        f.views[v].volume = cache.maps[slot].volume;
        projectPatchMap(f, f.views[v]);
      }
  *note = "map reuse: every view lies inside the maps drawn " + std::to_string(cache.maps_age + 1) +
          " frame(s) ago with margins of up to " + fmt("%.3g", options.map_reuse_margin_deg) + " deg; viewpoints moved <= " +
          fmt("%.3g", 1e3 * worst_move) + " mm (parallax <= " + fmt("%.3g", worst_parallax) + " texel)";
  return true;
}

std::vector<std::array<int, 2>> widenMaps(const Scene& scene, std::vector<ElementFrame>& frames,
                                          const PassPlanOptions& options, int max_texture_size) {
  std::vector<std::array<int, 2>> out;
  for (ElementFrame& f : frames)
    for (PatchView& pv : f.views) {
      const int base = patchMapSize(options.map_size, std::max<size_t>(1, patchesInView(f)));
      const int size = std::min(32 * int(std::ceil(1.25 * base / 32.0)), std::max(base, max_texture_size)),
                side = topLevelMapSide(scene, f, pv, options);
      if (pv.volume.backward) {
        out.push_back({size, side});
        continue;
      }
      const ViewVolume narrow = pv.volume;
      double margin = radians(options.map_reuse_margin_deg);
      pv.volume = widenViewVolume(narrow, margin);
      double wider = longerExtentTan(pv.volume) / longerExtentTan(narrow);
      for (int i = 0; i < 8 && wider > kMaxWidening; ++i) {  // the extent grows about linearly with the margin
        margin *= 0.98 * (kMaxWidening - 1) / (wider - 1);
        pv.volume = widenViewVolume(narrow, margin);
        wider = longerExtentTan(pv.volume) / longerExtentTan(narrow);
      }
      out.push_back({size, std::min(size, 32 * int(std::ceil(side * wider / 32.0)))});
      projectPatchMap(f, pv);
    }
  return out;
}

}  // namespace pvrr
