#include "pvrr/method/local_split.h"

#include <algorithm>
#include <cmath>
#include <unordered_map>

#include <tbb/parallel_for.h>

#include "cad/local_refine.h"
#include "pvrr/method/vertex_stage.h"
#include "pvrr/optics/material.h"
#include "pvrr/trace/tracer.h"

namespace pvrr {

std::vector<double> quadSpreadRatios(const ElementFrame& f, const FrameQualityLimits& limits) {
  const int gu = f.grid.grid_u, gv = f.grid.grid_v;
  std::vector<double> ratio(size_t(std::max(gu - 1, 0)) * size_t(std::max(gv - 1, 0)), 0.0);
  if (gu < 2 || gv < 2 || f.rays.empty()) return ratio;
  const size_t n_grid = size_t(gu) * size_t(gv);
  // The middle channel stands for all, as in assessFrameQuality.
  const std::vector<VertexRay>& rays = f.rays[f.rays.size() / 2];
  const std::vector<Vec3>& n = f.world_normal;
  for (size_t t = 0; t < f.grid.triangles.size(); ++t) {
    const cad::Triangle& tri = f.grid.triangles[t];
    const uint32_t a = tri.x, b = tri.y, c = tri.z;
    if (!f.in_view.empty() && !(f.in_view[a] && f.in_view[b] && f.in_view[c])) continue;
    size_t q;
    if (f.grid.locallyRefined()) {
      q = f.grid.triangle_quads[t];
    } else {
      if (std::max({a, b, c}) >= n_grid) continue;
      q = f.grid.gridQuadOf(a, b, c);
    }
    double r;
    if (rays[a].status == VertexStatus::Tir || rays[b].status == VertexStatus::Tir ||
        rays[c].status == VertexStatus::Tir) {
      auto shown = [&](uint32_t v) {
        const VertexRay& vr = rays[v];
        return glm::normalize((vr.status == VertexStatus::Tir && vr.traced ? vr.traced_seen : vr.hit) - f.world_pos[v]);
      };
      const Vec3 da = shown(a), db = shown(b), dc = shown(c);
      r = degrees(std::max({angleBetween(da, db), angleBetween(db, dc), angleBetween(dc, da)})) /
          limits.max_traced_spread_deg;
    } else {
      r = degrees(std::max({angleBetween(n[a], n[b]), angleBetween(n[b], n[c]), angleBetween(n[c], n[a])})) /
          limits.max_normal_spread_deg;
    }
    if (std::isfinite(r)) ratio[q] = std::max(ratio[q], r);
  }
  return ratio;
}

namespace {
// The levels for per-quad ratios that halve with each level (see chooseLocalSplit); `trigger`: some quad is over
// its limit.
LocalSplit chooseLevels(const ElementFrame& f, const std::vector<double>& ratio, bool trigger, int max_vertices,
                        double target) {
  const int gu = f.grid.grid_u, gv = f.grid.grid_v;
  LocalSplit out;
  const std::vector<uint8_t> now =
      f.grid.quad_levels.empty() ? std::vector<uint8_t>(ratio.size(), 0) : f.grid.quad_levels;
  out.levels = now;
  auto finish = [&]() -> LocalSplit& {
    out.changed = out.levels != now;
    std::vector<double> seen;
    for (double r : ratio)
      if (r > 0) seen.push_back(r);
    out.quads_seen = int(seen.size());
    if (!seen.empty()) {
      std::sort(seen.begin(), seen.end());
      out.ratio_max = seen.back();
      out.ratio_median = seen[seen.size() / 2];
    }
    for (uint8_t l : out.levels) {
      out.quads_split += l > 0;
      out.max_level = std::max(out.max_level, int(l));
    }
    out.vertices = out.quads_split ? cad::locallyRefinedVertexCount(gu, gv, out.levels) : f.grid.vertexCount();
    return out;
  };
  if (gu < 2 || gv < 2 || !trigger)
    return finish();
  // The levels that bring every quad to tau: each level halves its ratio.
  auto levelsFor = [&](double tau, bool* capped) {
    std::vector<uint8_t> l = now;
    for (size_t q = 0; q < ratio.size(); ++q) {
      if (!(ratio[q] > tau)) continue;
      const int more = int(std::ceil(std::log2(ratio[q] / tau) - 1e-9));
      const int want = int(now[q]) + std::max(more, 0);
      if (want > cad::kMaxLocalLevel && capped) *capped = true;
      l[q] = uint8_t(std::min(want, cad::kMaxLocalLevel));
    }
    return cad::balanceQuadLevels(gu, gv, l);
  };
  bool capped = false;
  std::vector<uint8_t> best = levelsFor(target, &capped);
  out.target_vertices = cad::locallyRefinedVertexCount(gu, gv, best);
  {
    const double s = std::max(1.0, *std::max_element(ratio.begin(), ratio.end()) / target);
    out.uniform_vertices = size_t(std::ceil((1 + (gu - 1) * s) * (1 + (gv - 1) * s)));
  }
  if (out.target_vertices > size_t(max_vertices)) {
    // Over the budget: the lowest tau above target whose levels fit, by bisection on log(tau); the quads above
    // it (the worst) are refined, the others not.
    out.budget_limited = true;
    const double r_max = *std::max_element(ratio.begin(), ratio.end());
    double lo = std::log(target), hi = std::log(std::max(r_max, target) * 1.000001);
    best = now;
    for (int it = 0; it < 40; ++it) {
      const double mid = 0.5 * (lo + hi);
      std::vector<uint8_t> l = levelsFor(std::exp(mid), nullptr);
      if (cad::locallyRefinedVertexCount(gu, gv, l) <= size_t(max_vertices)) {
        hi = mid;
        best = std::move(l);
      } else {
        lo = mid;
      }
    }
  }
  out.budget_limited = out.budget_limited || capped;
  out.levels = std::move(best);
  return finish();
}

}  // namespace

LocalSplit chooseLocalSplit(const ElementFrame& f, int max_vertices, const FrameQualityLimits& limits, double target) {
  const std::vector<double> ratio = quadSpreadRatios(f, limits);
  const bool trigger = std::any_of(ratio.begin(), ratio.end(), [](double r) { return r > 1.0; });
  return chooseLevels(f, ratio, trigger, max_vertices, target);
}

std::vector<double> quadMapErrors(const RayScene& rays, const ElementFrame& f, size_t max_probes) {
  const int gu = f.grid.grid_u, gv = f.grid.grid_v;
  std::vector<double> err(size_t(std::max(gu - 1, 0)) * size_t(std::max(gv - 1, 0)), 0.0);
  if (gu < 2 || gv < 2 || f.rays.empty()) return err;
  const size_t n_grid = size_t(gu) * size_t(gv);
  const size_t ch = f.rays.size() / 2;
  const std::vector<VertexRay>& vr = f.rays[ch];
  const double wl = ch < f.channels.size() && f.channels[ch].wavelength_nm > 0 ? f.channels[ch].wavelength_nm : kLineD_nm;
  struct Probe {
    const PatchView* pv;
    uint32_t k[3];
    size_t quad;
  };
  // Each patch's triangles with their base quads (a patch holds its quads' triangles in the grid's order).
  std::vector<size_t> quad_of_tri;
  std::vector<Probe> probes;
  for (const PatchView& pv : f.views) {
    if (!pv.in_view || pv.draw_traced || pv.st.size() <= ch) continue;
    const cad::GridPatch& gp = f.grid_patches[size_t(pv.patch)];
    for (const cad::Triangle& t : gp.triangles) {
      const uint32_t a = gp.vertices[t.x], b = gp.vertices[t.y], c = gp.vertices[t.z];
      if (!f.in_view.empty() && !(f.in_view[a] && f.in_view[b] && f.in_view[c])) continue;
      if (vr[a].status == VertexStatus::Tir || vr[b].status == VertexStatus::Tir || vr[c].status == VertexStatus::Tir)
        continue;
      size_t q;
      if (a < n_grid && b < n_grid && c < n_grid) {
        q = f.grid.gridQuadOf(a, b, c);
      } else {
        continue;  // set below from triangle_quads
      }
      probes.push_back({&pv, {t.x, t.y, t.z}, q});
    }
  }
  if (f.grid.locallyRefined()) {
    // Triangles with appended corners: their base quads from the tessellation (matched by their corners).
    std::unordered_map<uint64_t, uint32_t> quad_of;
    auto key = [](uint32_t a, uint32_t b, uint32_t c) {
      uint32_t v[3] = {a, b, c};
      std::sort(v, v + 3);
      return (uint64_t(v[0]) * 2654435761u) ^ (uint64_t(v[1]) << 21) ^ (uint64_t(v[2]) << 42);
    };
    for (size_t t = 0; t < f.grid.triangles.size(); ++t)
      quad_of[key(f.grid.triangles[t].x, f.grid.triangles[t].y, f.grid.triangles[t].z)] = f.grid.triangle_quads[t];
    for (const PatchView& pv : f.views) {
      if (!pv.in_view || pv.draw_traced || pv.st.size() <= ch) continue;
      const cad::GridPatch& gp = f.grid_patches[size_t(pv.patch)];
      for (const cad::Triangle& t : gp.triangles) {
        const uint32_t a = gp.vertices[t.x], b = gp.vertices[t.y], c = gp.vertices[t.z];
        if (a < n_grid && b < n_grid && c < n_grid) continue;  // done above
        if (!f.in_view.empty() && !(f.in_view[a] && f.in_view[b] && f.in_view[c])) continue;
        if (vr[a].status == VertexStatus::Tir || vr[b].status == VertexStatus::Tir || vr[c].status == VertexStatus::Tir)
          continue;
        const auto it = quad_of.find(key(a, b, c));
        if (it != quad_of.end()) probes.push_back({&pv, {t.x, t.y, t.z}, it->second});
      }
    }
  }
  if (max_probes > 0 && probes.size() > max_probes) {
    const size_t stride = (probes.size() + max_probes - 1) / max_probes;
    size_t kept = 0;
    for (size_t i = stride / 2; i < probes.size(); i += stride) probes[kept++] = probes[i];
    probes.resize(kept);
  }
  TraceOptions to;
  to.max_depth = f.tir_trace_depth > 0 ? f.tir_trace_depth : to.max_depth;
  const Tracer tracer(rays, to);
  std::vector<double> angle(probes.size(), 0.0);
  tbb::parallel_for(size_t(0), probes.size(), [&](size_t i) {
    const Probe& p = probes[i];
    const PatchView& pv = *p.pv;
    const cad::GridPatch& gp = f.grid_patches[size_t(pv.patch)];
    Vec3 centroid(0.0);
    double wq = 0;
    Vec2 st(0.0);
    for (uint32_t k : p.k) {
      centroid += f.world_pos[gp.vertices[k]] / 3.0;
      const double q = pv.q.size() > k ? pv.q[k] : 1.0;
      st += q * pv.st[ch][k];
      wq += q;
    }
    st /= wq;
    const TraceResult r = tracer.trace(f.eye, glm::normalize(centroid - f.eye), wl);
    if (r.first_element != f.element) return;
    const ViewVolume& v = pv.volume;
    const Vec2 exact = projectToTexture(v, r.seen);
    if (!(std::isfinite(exact.x) && std::isfinite(exact.y) && std::isfinite(st.x) && std::isfinite(st.y))) return;
    auto dir = [&](Vec2 s) {
      return v.near_m * v.forward + (v.left + s.x * (v.right_ - v.left)) * v.right + (v.bottom + s.y * (v.top - v.bottom)) * v.up;
    };
    angle[i] = arcminutes(angleBetween(dir(exact), dir(st)));
  });
  for (size_t i = 0; i < probes.size(); ++i)
    if (std::isfinite(angle[i])) err[probes[i].quad] = std::max(err[probes[i].quad], angle[i]);
  return err;
}

LocalSplit chooseLocalSplitByMapError(const RayScene& rays, const ElementFrame& f, int max_vertices,
                                      const FrameQualityLimits& limits, double target, bool refined,
                                      double broad_limit_arcmin) {
  const std::vector<double> spread = quadSpreadRatios(f, limits);
  const bool trigger = refined || std::any_of(spread.begin(), spread.end(), [](double r) { return r > 1.0; });
  double sampled_median = 0;
  if (!trigger && !f.grid.locallyRefined() && std::isfinite(broad_limit_arcmin)) {
    // No spread limit sees it: a sample of the quads' map errors, the trigger if their median is over the limit.
    std::vector<double> sample = quadMapErrors(rays, f, kBroadMapErrorProbes);
    sample.erase(std::remove_if(sample.begin(), sample.end(), [](double e) { return !(e > 0); }), sample.end());
    if (!sample.empty()) {
      std::nth_element(sample.begin(), sample.begin() + ptrdiff_t(sample.size() / 2), sample.end());
      sampled_median = sample[sample.size() / 2];
    }
  }
  if (!trigger && !(sampled_median > broad_limit_arcmin)) {
    LocalSplit ls = chooseLevels(f, spread, false, max_vertices, target);
    ls.sampled_median_arcmin = sampled_median;
    return ls;
  }
  const std::vector<double> err = quadMapErrors(rays, f);
  // The error a quad may keep: kLocalSplitMapErrorArcmin, or where a broad error triggered the split, its limit
  // (the quads over it are what the median measured).
  const double quad_limit = trigger ? kLocalSplitMapErrorArcmin : broad_limit_arcmin;
  // As a ratio that halves with each level (the map error falls 4 x): sqrt. Quads without a map error (TIR
  // triangles, drawn from traced colours) keep their spread ratio, which is the traced spread's there.
  std::vector<double> ratio(err.size(), 0.0);
  for (size_t q = 0; q < err.size(); ++q)
    ratio[q] = err[q] > 0 ? std::sqrt(err[q] / quad_limit) : 0.0;
  std::vector<uint8_t> has_tir(err.size(), 0);
  const std::vector<VertexRay>& vr = f.rays[f.rays.size() / 2];
  for (size_t t = 0; t < f.grid.triangles.size(); ++t) {
    const cad::Triangle& tri = f.grid.triangles[t];
    if (vr[tri.x].status != VertexStatus::Tir && vr[tri.y].status != VertexStatus::Tir && vr[tri.z].status != VertexStatus::Tir)
      continue;
    const size_t q = f.grid.locallyRefined() ? f.grid.triangle_quads[t] : f.grid.gridQuadOf(tri.x, tri.y, tri.z);
    if (q < has_tir.size()) has_tir[q] = 1;
  }
  for (size_t q = 0; q < ratio.size(); ++q)
    if (has_tir[q]) ratio[q] = std::max(ratio[q], spread[q]);
  LocalSplit ls = chooseLevels(f, ratio, true, max_vertices, target);
  ls.sampled_median_arcmin = sampled_median;
  ls.broad_map_error = !trigger;
  return ls;
}

}  // namespace pvrr
