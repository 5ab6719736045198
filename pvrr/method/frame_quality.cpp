#include "pvrr/method/frame_quality.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "pvrr/method/eye_side.h"
#include "pvrr/method/vertex_stage.h"
#include "pvrr/trace/tracer.h"

namespace pvrr {

const char* toString(QualityVerdict v) {
  switch (v) {
    case QualityVerdict::kGood:
      return "good";
    case QualityVerdict::kDegraded:
      return "degraded";
    case QualityVerdict::kFallback:
      return "fallback";
  }
  return "?";
}

namespace {

void addReason(std::string& reasons, const std::string& r) { reasons += (reasons.empty() ? "" : "; ") + r; }

std::string fixed(double v, int digits) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", digits, v);
  return buf;
}

PatchQuality assessPatch(const ElementFrame& f, const PatchView& pv, const FrameQualityLimits& lim) {
  PatchQuality q;
  q.fov_deg = degrees(std::max(pv.volume.fov_x_rad, pv.volume.fov_y_rad));
  q.fit_rms_arcmin = arcminutes(pv.fit.rms_angle_rad);
  q.fit_max_arcmin = arcminutes(pv.fit.max_angle_rad);
  q.action = "none";
  if (!pv.in_view) return q;
  // A reversed volume (all hits behind the viewpoint, a concave mirror's zooming region) is exact in itself;
  // the trouble is a forward volume that leaves some of its patch's hits out.
  if (!pv.volume.backward && !pv.volume.zooming.empty() && pv.volume.hits_covered > 0)
    q.hits_behind = int(pv.volume.zooming.size());
  q.fov_limited = pv.volume.hits_outside > 0 || q.fov_deg >= lim.max_fov_deg - lim.fov_limit_tolerance_deg;
  const cad::GridPatch& gp = f.grid_patches[size_t(pv.patch)];
  size_t seen = 0, outside = 0;
  for (size_t k = 0; k < gp.vertices.size(); ++k) {
    const uint32_t vi = gp.vertices[k];
    if (!f.in_view.empty() && f.in_view[vi] != 2) continue;
    for (size_t c = 0; c < pv.st.size(); ++c) {
      if (f.rays[c][vi].status == VertexStatus::Tir) continue;  // drawn from the tracer, not the map
      const Vec2 st = pv.st[c][k];
      ++seen;
      const double t = lim.st_tolerance;
      outside += !(st.x >= -t && st.x <= 1 + t && st.y >= -t && st.y <= 1 + t);
    }
  }
  q.st_outside_share = seen ? double(outside) / double(seen) : 0.0;
  size_t tir = 0, seen_all = 0;
  for (size_t k = 0; k < gp.vertices.size(); ++k) {
    const uint32_t vi = gp.vertices[k];
    if (!f.in_view.empty() && f.in_view[vi] != 2) continue;
    for (size_t c = 0; c < f.rays.size(); ++c) {
      ++seen_all;
      tir += f.rays[c][vi].status == VertexStatus::Tir;
    }
  }
  q.tir_share = seen_all ? double(tir) / double(seen_all) : 0.0;
  // The middle channel stands for all: dispersion spreads the channels by far less than the triangles.
  const std::vector<VertexRay>& rays = f.rays[f.rays.size() / 2];
  for (const cad::Triangle& t : gp.triangles) {
    const uint32_t a = gp.vertices[t.x], b = gp.vertices[t.y], c = gp.vertices[t.z];
    if (!f.in_view.empty() && !(f.in_view[a] && f.in_view[b] && f.in_view[c])) continue;
    if (rays[a].status == VertexStatus::Tir || rays[b].status == VertexStatus::Tir ||
        rays[c].status == VertexStatus::Tir) {
      auto shown = [&](uint32_t v) {
        const VertexRay& r = rays[v];
        return glm::normalize((r.status == VertexStatus::Tir && r.traced ? r.traced_seen : r.hit) - f.world_pos[v]);
      };
      const Vec3 da = shown(a), db = shown(b), dc = shown(c);
      const auto edge_or_map = [&](uint32_t v) { return rays[v].status != VertexStatus::Tir || rays[v].edge_exit; };
      const bool edge = edge_or_map(a) && edge_or_map(b) && edge_or_map(c);
      double& spread = edge ? q.max_edge_spread_deg : q.max_traced_spread_deg;
      spread = std::max({spread, degrees(angleBetween(da, db)), degrees(angleBetween(db, dc)),
                         degrees(angleBetween(dc, da))});
      continue;
    }
    const std::vector<Vec3>& n = f.world_normal;
    q.max_normal_spread_deg = std::max({q.max_normal_spread_deg, degrees(angleBetween(n[a], n[b])),
                                        degrees(angleBetween(n[b], n[c])), degrees(angleBetween(n[c], n[a]))});
    q.max_ray_spread_deg =
        std::max({q.max_ray_spread_deg, degrees(angleBetween(rays[a].dir, rays[b].dir)),
                  degrees(angleBetween(rays[b].dir, rays[c].dir)), degrees(angleBetween(rays[c].dir, rays[a].dir))});
  }

  if (q.fov_limited)
    addReason(q.reasons, "map field of view limited to " + fixed(lim.max_fov_deg, 0) + " deg (" +
                             std::to_string(pv.volume.hits_outside) + " hit(s) outside the map)");
  if (q.hits_behind > 0)
    addReason(q.reasons, std::to_string(q.hits_behind) + " hit(s) behind the viewpoint among hits in front of it");
  if (q.st_outside_share > 0)
    addReason(q.reasons, fixed(100 * q.st_outside_share, 1) + " % of seen texture coordinates outside the map");
  if (q.fit_rms_arcmin > lim.max_fit_rms_arcmin)
    addReason(q.reasons, "viewpoint fit residual " + fixed(q.fit_rms_arcmin, 0) + "' RMS (limit " +
                             fixed(lim.max_fit_rms_arcmin, 0) + "')");
  if (q.max_normal_spread_deg > lim.max_normal_spread_deg)
    addReason(q.reasons, "triangles span up to " + fixed(q.max_normal_spread_deg, 1) +
                             " deg of surface normals (limit " + fixed(lim.max_normal_spread_deg, 1) +
                             " deg): rays interpolated coarsely");
  if (q.max_traced_spread_deg > lim.max_traced_spread_deg)
    addReason(q.reasons, fixed(100 * q.tir_share, 0) +
                             " % of seen rays totally reflected or out through the lens's edge, drawn from "
                             "traced colours whose " +
                             "seen directions differ by up to " + fixed(q.max_traced_spread_deg, 1) +
                             " deg across a triangle (limit " + fixed(lim.max_traced_spread_deg, 1) + " deg)");
  if (!pv.fit.accepted) addReason(q.reasons, "viewpoint fit not accepted: " + pv.fit.fallback);
  if (q.reasons.empty()) return q;
  // The map cannot hold the patch's rays, and no split can make it: hits on both sides of the viewpoint stay
  // so in every part of the patch that holds both, and a split that is exhausted has no finer part to offer.
  const bool map_cannot_hold = q.fov_limited || q.st_outside_share > 0 || q.hits_behind > 0;
  const bool split_cannot_help = q.hits_behind > 0 || f.split_exhausted;
  q.verdict = map_cannot_hold && split_cannot_help ? QualityVerdict::kFallback : QualityVerdict::kDegraded;
  q.action = "flagged";
  return q;
}

}  // namespace

void assessFrameQuality(ElementFrame& f, const FrameQualityLimits& limits) {
  f.quality = ElementQuality{};
  int fallback = 0, degraded = 0;
  for (PatchView& pv : f.views) {
    pv.quality = assessPatch(f, pv, limits);
    pv.draw_traced = false;
    fallback += pv.quality.verdict == QualityVerdict::kFallback;
    degraded += pv.quality.verdict == QualityVerdict::kDegraded;
    f.quality.verdict = std::max(f.quality.verdict, pv.quality.verdict);
  }
  std::string a = f.split_note;
  if (degraded) addReason(a, std::to_string(degraded) + " patch(es) degraded, drawn from their maps and flagged");
  if (fallback) addReason(a, std::to_string(fallback) + " patch(es) that no split can fix");
  f.quality.action = a.empty() ? "none" : a;
}

constexpr double kRefineTarget = 0.9;

std::array<int, 2> refinedGridSize(const ElementFrame& f, int max_vertices, const FrameQualityLimits& limits) {
  const int u = f.grid.grid_u, v = f.grid.grid_v;
  // Each spread over its limit (1: at the limit): the normals', and the traced directions' across a triangle
  // with a totally reflected corner (a lens's TIR region, drawn from traced colours interpolated).
  double ratio = 0;
  for (const PatchView& pv : f.views)
    if (pv.in_view)
      ratio = std::max({ratio, pv.quality.max_normal_spread_deg / limits.max_normal_spread_deg,
                        pv.quality.max_traced_spread_deg / limits.max_traced_spread_deg,
                        pv.quality.max_edge_spread_deg / limits.max_traced_spread_deg});
  if (u < 2 || v < 2 || !(ratio > 1.0)) return {u, v};
  // Aimed 10 % below the limit: the spread falls a little less than in proportion on a surface whose
  // curvature varies across a triangle (the toric mirror: 6.1 deg at 31 x 31 where 12.5 deg at 15 x 15
  // predicted 5.9).
  double factor = ratio / kRefineTarget;
  // Within the budget: (1 + (u - 1) k)(1 + (v - 1) k) <= max_vertices.
  const double a = double(u - 1) * double(v - 1), b = double(u - 1) + double(v - 1), c = 1.0 - double(max_vertices);
  const double k_max = (-b + std::sqrt(b * b - 4 * a * c)) / (2 * a);
  factor = std::min(factor, k_max);
  int nu = std::max(u, 1 + int(std::ceil(double(u - 1) * factor - 1e-9)));
  int nv = std::max(v, 1 + int(std::ceil(double(v - 1) * factor - 1e-9)));
  if (double(nu) * double(nv) > double(max_vertices)) {  // rounded up past the budget: round down
    nu = std::max(u, 1 + int(std::floor(double(u - 1) * factor)));
    nv = std::max(v, 1 + int(std::floor(double(v - 1) * factor)));
  }
  return {nu, nv};
}

int applyTracedFallback(const RayScene& rays, ElementFrame& f, int max_depth) {
  const Element& el = rays.scene().elements[size_t(f.element)];
  const auto from_eye = [&](uint32_t vi) { return f.tir_trace_depth > 0 && lensSeenFromBehind(el, f, vi); };
  std::vector<uint32_t> vertices;
  std::vector<PatchView*> patches;
  for (PatchView& pv : f.views)
    if (pv.quality.verdict == QualityVerdict::kFallback) {
      patches.push_back(&pv);
      const cad::GridPatch& gp = f.grid_patches[size_t(pv.patch)];
      vertices.insert(vertices.end(), gp.vertices.begin(), gp.vertices.end());
    }
  if (patches.empty()) return 0;
  std::sort(vertices.begin(), vertices.end());
  vertices.erase(std::unique(vertices.begin(), vertices.end()), vertices.end());
  if (max_depth <= 0 && !std::any_of(vertices.begin(), vertices.end(), from_eye)) return 0;
  TraceOptions to, eye_to;
  to.max_depth = max_depth;
  eye_to.max_depth = f.tir_trace_depth;
  const Tracer tracer(rays, to), eye_tracer(rays, eye_to);
  const double eps = rays.epsilon();
  for (size_t c = 0; c < f.rays.size(); ++c) {
    const double wl =
        c < f.channels.size() && f.channels[c].wavelength_nm > 0 ? f.channels[c].wavelength_nm : kLineD_nm;
    tbb::parallel_for(size_t(0), vertices.size(), [&](size_t k) {
      VertexRay& r = f.rays[c][vertices[k]];
      if (from_eye(vertices[k])) {  // the whole path from the eye: its first event is the lens's back
        const TraceResult t = eye_tracer.trace(f.eye, glm::normalize(f.world_pos[vertices[k]] - f.eye), wl);
        r.traced = true;
        r.traced_color = t.color;
        r.traced_seen = t.seen;
        return;
      }
      if (r.status == VertexStatus::Tir || max_depth <= 0)
        return;  // Tir: already the tracer's answer along the incoming ray
      // Started an epsilon along the ray, so that its first event is not the surface it leaves.
      const TraceResult t = tracer.trace(r.origin + eps * r.dir, r.dir, wl);
      r.traced = true;
      r.traced_color = r.transmittance * t.color;
      r.traced_seen = t.seen;
    });
  }
  for (PatchView* pv : patches) {
    pv->draw_traced = true;
    pv->quality.action = "drawn from traced vertex colours";
  }
  return int(patches.size());
}

}  // namespace pvrr
