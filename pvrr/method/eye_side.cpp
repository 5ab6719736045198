#include "pvrr/method/eye_side.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

#include "cad/sag.h"

#include "pvrr/method/vertex_stage.h"

namespace pvrr {

EyeSide eyeSide(const ElementFrame& f) {
  EyeSide s;
  for (size_t i = 0; i < f.world_pos.size() && i < f.world_normal.size(); ++i) {
    if (!f.in_view.empty() && f.in_view[i] != 2) continue;
    ++s.seen;
    s.back += glm::dot(f.eye - f.world_pos[i], f.world_normal[i]) < 0;
  }
  return s;
}

std::string eyeSideNote(const Scene& scene, const ElementFrame& f) {
  const EyeSide s = eyeSide(f);
  if (s.back == 0) return "";
  const Element& el = scene.elements[size_t(f.element)];
  const bool mirror = el.type == ElementType::Mirror;
  const std::string who = std::string(mirror ? "mirror '" : "lens '") + el.name + "'";
  if (s.back == s.seen)
    return mirror ? "the eye is behind " + who +
                        " (its back side faces the eye): nothing is reflected toward it; it is drawn as its dark back, "
                        "as the reference draws it"
                  : "the eye is behind " + who + " (its back surface faces the eye)";
  const std::string share = std::to_string(s.back) + " of " + std::to_string(s.seen) + " seen vertices";
  return mirror ? "the eye sees the back side of " + who + " at " + share +
                      " (the eye is near the mirror's plane or the mirror curves around it): those parts are drawn "
                      "as its dark back, as the reference draws them"
                : "the eye sees " + who + " from behind its front surface at " + share;
}

bool lensSeenFromBehind(const Element& el, const ElementFrame& f, size_t i) {
  return el.type == ElementType::Lens && i < f.world_normal.size() &&
         glm::dot(f.eye - f.world_pos[i], f.world_normal[i]) < 0;
}

double lensBeyondOutline(const Element& el, const Vec3& back_point) {
  if (!el.has_outline) return 0.0;
  const Vec3 q = el.toLocalPoint(back_point);
  const Vec2 d = Vec2(q.x, q.y) - el.outline.centre();
  return glm::length(d) - el.outline.boundaryRadius(std::atan2(d.y, d.x));
}

namespace {
// How wide (arcmin) the band of rays leaving through the edge near a vertex `distance` from the viewer looks:
// about as wide on the lens as its back point lies beyond the outline; 0 or less inside it.
double edgeBandArcmin(double beyond, double distance) { return arcminutes(beyond / std::max(distance, 1e-12)); }
}  // namespace

bool lensEdgeExit(const Element& el, const Vec3& back_point, double distance) {
  return edgeBandArcmin(lensBeyondOutline(el, back_point), distance) > kLensEdgeExitLimitArcmin;
}

LensEdgeExits lensEdgeExits(const Element& el, const ElementFrame& f, const cad::GridPatch* patch) {
  LensEdgeExits e;
  if (el.type != ElementType::Lens || !el.has_outline || f.rays.empty()) return e;
  const std::vector<VertexRay>& rays = f.rays[f.rays.size() / 2];  // the middle channel stands for all
  auto visit = [&](size_t i) {
    if (i >= rays.size() || (!f.in_view.empty() && f.in_view[i] != 2) || lensSeenFromBehind(el, f, i)) return;
    const VertexRay& r = rays[i];
    // Out through the edge band with no back point at all: flagged as TIR.
    if (!r.edge_exit && glm::length(r.back_normal) == 0.0) return;
    const double beyond = lensBeyondOutline(el, r.back_point);
    const double band_arcmin = edgeBandArcmin(beyond, glm::length(f.world_pos[i] - f.eye));
    if (r.edge_exit || band_arcmin > kLensEdgeExitLimitArcmin) {
      ++e.vertices;
      e.max_beyond_m = std::max(e.max_beyond_m, beyond);
      e.max_band_arcmin = std::max(e.max_band_arcmin, band_arcmin);
    }
  };
  if (patch)
    for (uint32_t vi : patch->vertices) visit(vi);
  else
    for (size_t i = 0; i < rays.size(); ++i) visit(i);
  return e;
}

namespace {

// Says how pvrr mode draws the seen vertex rays that leave a lens through its edge (vertex_stage marks them,
// VertexRay::edge_exit: their back points lie on the back surface's extension beyond the outline by more than
// a thin band as seen from the eye): from the reference tracer's colour along their incoming rays, the edge
// dark as the reference draws it, where the frame traces (tir_trace_depth), else dark; either way interpolated
// towards the neighbouring vertices across a triangle, which frame_quality's traced-spread check judges (and
// refines the grid for). They used to be continued through the extension and drawn from the map, showing the
// room where the reference is dark (hunt-spec-eye-turned-30.json: 6.0' median, p95 1384'; now 0.55' / 1.4').
void noteLensEdgeExits(const Element& el, ElementFrame& f) {
  const LensEdgeExits all = lensEdgeExits(el, f, nullptr);
  if (all.vertices == 0) return;
  char mm[96];
  std::snprintf(mm, sizeof mm, "%.1f mm beyond the outline, %.0f' as seen from the eye", 1e3 * all.max_beyond_m,
                all.max_band_arcmin);
  f.quality.note += std::string(f.quality.note.empty() ? "" : "; ") + std::to_string(all.vertices) +
                    " seen vertex ray(s) leave the glass through the edge of lens '" + el.name + "' (up to " + mm +
                    "): drawn " +
                    (f.tir_trace_depth > 0 ? "from the reference tracer's colours along their rays (the edge dark)"
                                           : "dark (the light leaves through the edge)") +
                    ", as the reference draws them";
}

// Whether world point h lies on element e's front surface within its outline. A sag surface is solved
// directly; any other (a CAD face, a subdivision surface) through a SurfaceProbe.
bool onSagElement(const Element& e, const cad::SagSurface& sag, const Vec3& h) {
  if (!e.has_outline) return false;
  const Vec3 q = e.toLocalPoint(h);
  const double size = std::max(e.outline.width(), e.outline.height());
  if (!e.outline.contains(Vec2(q.x, q.y), 1e-6 * size) || !sag.defined(q.x, q.y)) return false;
  return std::abs(q.z - (sag.zVertex() - sag.sag(q.x, q.y).z)) < 1e-6 * size + 1e-9;
}

// A front surface that is not a sag surface, sampled on a kProbeGrid x kProbeGrid grid over its parameter domain
// (local points): a point is on it when it lies in the samples' bounding box (padded by a tenth of its size, for
// the bulge between samples), and the closest surface point, found by Gauss-Newton from the nearest sample, is
// within `tol` of it and inside the outline (in the parameter plane, as Element::outline is for such surfaces).
constexpr int kProbeGrid = 16;
struct SurfaceProbe {
  const Element* el = nullptr;
  const cad::Surface* surface = nullptr;  // null: a sag surface (onSagElement)
  std::vector<Vec3> points;
  std::vector<Vec2> params;
  Vec3 lo{0}, hi{0};
  double tol = 0;
};

SurfaceProbe makeProbe(const Element& e) {
  SurfaceProbe p;
  p.el = &e;
  const cad::Surface& s = e.frontSurface();
  if (dynamic_cast<const cad::SagSurface*>(&s)) return p;
  p.surface = &s;
  const cad::ParamDomain d = s.domain();
  p.lo = Vec3(std::numeric_limits<double>::infinity());
  p.hi = -p.lo;
  for (int i = 0; i < kProbeGrid; ++i)
    for (int j = 0; j < kProbeGrid; ++j) {
      const Vec2 uv(d.u0 + (d.u1 - d.u0) * i / (kProbeGrid - 1), d.v0 + (d.v1 - d.v0) * j / (kProbeGrid - 1));
      const Vec3 q = s.evaluate(uv.x, uv.y).p;
      if (!std::isfinite(q.x) || !std::isfinite(q.y) || !std::isfinite(q.z)) continue;
      p.points.push_back(q);
      p.params.push_back(uv);
      p.lo = glm::min(p.lo, q);
      p.hi = glm::max(p.hi, q);
    }
  const double size = p.points.empty() ? 0.0 : glm::length(p.hi - p.lo);
  p.lo -= Vec3(0.1 * size);
  p.hi += Vec3(0.1 * size);
  p.tol = 1e-6 * size + 1e-9;  // as the sag test's: the tracer's hits are exact to far less
  return p;
}

bool onElement(const SurfaceProbe& p, const Vec3& h) {
  const Element& e = *p.el;
  if (!p.surface) return onSagElement(e, static_cast<const cad::SagSurface&>(e.frontSurface()), h);
  if (p.points.empty()) return false;
  const Vec3 q = e.toLocalPoint(h);
  if (q.x < p.lo.x || q.y < p.lo.y || q.z < p.lo.z || q.x > p.hi.x || q.y > p.hi.y || q.z > p.hi.z) return false;
  size_t best = 0;
  for (size_t k = 1; k < p.points.size(); ++k)
    if (glm::length(p.points[k] - q) < glm::length(p.points[best] - q)) best = k;
  const cad::ParamDomain d = p.surface->domain();
  Vec2 uv = p.params[best];
  for (int it = 0; it < 30; ++it) {
    const cad::SurfaceDerivs sd = p.surface->evaluate(uv.x, uv.y);
    const Vec3 r = q - sd.p;
    const double a = glm::dot(sd.du, sd.du), b = glm::dot(sd.du, sd.dv), c = glm::dot(sd.dv, sd.dv);
    const double det = a * c - b * b;
    if (!(std::abs(det) > 0)) break;
    const double ru = glm::dot(r, sd.du), rv = glm::dot(r, sd.dv);
    const Vec2 step((c * ru - b * rv) / det, (a * rv - b * ru) / det);
    const Vec2 next(std::clamp(uv.x + step.x, d.u0, d.u1), std::clamp(uv.y + step.y, d.v0, d.v1));
    const bool done = glm::length(next - uv) <= 1e-12 * (std::abs(d.u1 - d.u0) + std::abs(d.v1 - d.v0));
    uv = next;
    if (done) break;
  }
  if (!(glm::length(q - p.surface->evaluate(uv.x, uv.y).p) < p.tol)) return false;
  return !e.has_outline || e.outline.contains(uv, 1e-6 * std::max(e.outline.width(), e.outline.height()));
}

// A patch's map shows another mirror or lens as seen from the patch's viewpoint; a vertex ray that misses the
// viewpoint arrives at that element from another direction, and what the element shows turns with it. The
// angle at the hit between the ray and the direction from the viewpoint is the nested picture's error there
// (the concave mirror of the mirror pair turned to R -1 m: its rays converge and diverge again before the wall
// mirror; 27' here over its vertices, 63' median pixel error, and it was passed as good; docs/robustness.md,
// the hunt).
void applyNestedParallax(const Scene& scene, ElementFrame& f) {
  if (f.rays.empty()) return;
  const std::vector<VertexRay>& rays = f.rays[f.rays.size() / 2];
  std::vector<SurfaceProbe> others;
  for (size_t e = 0; e < scene.elements.size(); ++e)
    if (int(e) != f.element) others.push_back(makeProbe(scene.elements[e]));
  if (others.empty()) return;
  int marked = 0;
  for (PatchView& pv : f.views) {
    if (!pv.in_view || pv.volume.backward) continue;
    std::vector<double> ang;
    for (uint32_t vi : f.grid_patches[size_t(pv.patch)].vertices) {
      if ((!f.in_view.empty() && f.in_view[vi] != 2) || vi >= rays.size()) continue;
      const VertexRay& r = rays[vi];
      if (r.status != VertexStatus::Hit) continue;
      bool nested = false;
      for (size_t k = 0; k < others.size() && !nested; ++k) nested = onElement(others[k], r.hit);
      if (!nested) continue;
      const Vec3 from_viewpoint = r.hit - pv.fit.eye;
      if (!(glm::length(from_viewpoint) > 0)) continue;
      ang.push_back(arcminutes(angleBetween(r.dir, glm::normalize(from_viewpoint))));
    }
    if (ang.empty()) continue;
    std::nth_element(ang.begin(), ang.begin() + long(ang.size() / 2), ang.end());
    const double median = ang[ang.size() / 2];
    if (!(median > kNestedParallaxLimitArcmin)) continue;
    char buf[160];
    std::snprintf(buf, sizeof buf, "other elements seen in its map from %.0f' (median) off their rays' directions",
                  median);
    pv.quality.verdict = std::max(pv.quality.verdict, QualityVerdict::kDegraded);
    pv.quality.reasons += std::string(pv.quality.reasons.empty() ? "" : "; ") + buf;
    if (pv.quality.action == "none") pv.quality.action = "flagged";
    ++marked;
  }
  if (!marked) return;
  f.quality.verdict = std::max(f.quality.verdict, QualityVerdict::kDegraded);
  f.quality.action = (f.quality.action == "none" ? "" : f.quality.action + "; ") + std::to_string(marked) +
                     " patch(es) flagged: the mirrors or lenses its maps show are seen from the patch's viewpoint, " +
                     "more than " + std::to_string(int(kNestedParallaxLimitArcmin)) +
                     "' (median) off the directions its rays arrive from (the rays do not meet in one point)";
}

// Whether segment o + t d, t in (t0, t1), crosses triangle abc (Moller-Trumbore).
bool segmentCrosses(const Vec3& o, const Vec3& d, double t0, double t1, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 e1 = b - a, e2 = c - a, pv = glm::cross(d, e2);
  const double det = glm::dot(e1, pv);
  if (std::abs(det) < 1e-300) return false;
  const double inv = 1.0 / det;
  const Vec3 tv = o - a;
  const double u = glm::dot(tv, pv) * inv;
  if (u < 0 || u > 1) return false;
  const Vec3 qv = glm::cross(tv, e1);
  const double v = glm::dot(d, qv) * inv;
  if (v < 0 || u + v > 1) return false;
  const double t = glm::dot(e2, qv) * inv;
  return t > t0 && t < t1;
}

// A mirror patch whose near plane could not be placed at the mirror (ViewVolume::mirror_vertices_unclipped: a hit
// nearer the viewpoint than the farthest mirror vertex) holds, between its near plane and the mirror, what lies
// behind the mirror: the map shows it in place of the reflection wherever it is there. Found in the hunt
// (docs/robustness.md, "compare and the quality checks"): two cards 2 and 6 cm before a plane mirror moved its
// near plane 47 mm towards the viewpoint, and the wall 1 cm behind the mirror covered a triangle of the picture
// (p95 10800', good). Counted at the seen vertices: the segment from the near plane to the vertex along the
// viewpoint's line crosses an environment triangle. Where the volume has a clip plane (ViewVolume::clip_plane: the
// renderer clips what lies behind it in the map's environment pass), only the segment's part on its kept side
// counts; the plane is dropped where no segment crosses anything (the map is drawn as without it).
void applyBehindMirror(const Scene& scene, ElementFrame& f) {
  if (scene.elements[size_t(f.element)].type != ElementType::Mirror) return;
  int marked = 0, total = 0;
  for (PatchView& pv : f.views) {
    ViewVolume& vv = pv.volume;
    if (!pv.in_view || vv.backward || vv.mirror_vertices_unclipped == 0) continue;
    int behind = 0, hidden = 0;  // seen vertices whose segment crosses the environment: at all, on the kept side
    for (uint32_t vi : f.grid_patches[size_t(pv.patch)].vertices) {
      if ((!f.in_view.empty() && f.in_view[vi] != 2) || vi >= f.world_pos.size()) continue;
      const Vec3 to = f.world_pos[vi] - vv.eye;
      const double len = glm::length(to);
      const double along = glm::dot(to, vv.forward);
      if (!(len > 0) || !(along > vv.near_m)) continue;
      const Vec3 d = to / len;
      const double t_near = len * vv.near_m / along, t_end = len * (1 - 1e-9);
      auto crosses = [&](double t0, double t1) {
        for (const EnvMesh& m : scene.meshes)
          for (const glm::u32vec3& t : m.triangles)
            if (segmentCrosses(vv.eye, d, t0, t1, m.anchor + Vec3(m.positions[t.x]),
                               m.anchor + Vec3(m.positions[t.y]), m.anchor + Vec3(m.positions[t.z])))
              return true;
        return false;
      };
      if (!crosses(t_near, t_end)) continue;
      ++behind;
      if (vv.clip_plane) {  // only the part of the segment on the plane's kept side
        double t0 = t_near, t1 = t_end;
        const Vec3 n(*vv.clip_plane);
        const double s0 = glm::dot(n, vv.eye) + vv.clip_plane->w, ds = glm::dot(n, d);
        if (ds > 0) t0 = std::max(t0, -s0 / ds);
        else if (ds < 0) t1 = std::min(t1, -s0 / ds);
        else if (!(s0 > 0)) t1 = t0;
        if (!(t1 > t0) || !crosses(t0, t1)) continue;
      }
      ++hidden;
    }
    // The clip plane is drawn only where it removes something from the map's segments (shipped scenes: nowhere).
    if (behind == 0) vv.clip_plane.reset();
    if (hidden == 0) continue;
    pv.quality.verdict = std::max(pv.quality.verdict, QualityVerdict::kDegraded);
    pv.quality.reasons += std::string(pv.quality.reasons.empty() ? "" : "; ") + std::to_string(hidden) +
                          " seen vertices where what lies behind the mirror is inside its map (the near plane "
                          "could not be placed at the mirror)";
    if (pv.quality.action == "none") pv.quality.action = "flagged";
    ++marked;
    total += hidden;
  }
  if (!marked) return;
  f.quality.verdict = std::max(f.quality.verdict, QualityVerdict::kDegraded);
  f.quality.action = (f.quality.action == "none" ? "" : f.quality.action + "; ") + std::to_string(marked) +
                     " patch(es) flagged: at " + std::to_string(total) +
                     " seen vertices the map shows what lies behind the mirror in place of its reflection (a hit "
                     "nearer the viewpoint than the mirror moved the near plane off the mirror)";
}

}  // namespace

void applyEyeSide(const Scene& scene, ElementFrame& f) {
  if (f.eye != scene.observer.eye) return;
  f.quality.note = eyeSideNote(scene, f);
  const Element& el = scene.elements[size_t(f.element)];
  applyNestedParallax(scene, f);
  applyBehindMirror(scene, f);
  if (el.type != ElementType::Lens || f.quality.note.empty()) return noteLensEdgeExits(el, f);
  f.quality.note +=
      ": pvrr mode's vertex rays enter a lens through its front surface, so the patches seen from "
      "behind are drawn from the reference tracer's colours at their vertices";
  int marked = 0;
  for (PatchView& pv : f.views) {
    if (!pv.in_view) continue;
    int back = 0;
    for (uint32_t vi : f.grid_patches[size_t(pv.patch)].vertices)
      back += (f.in_view.empty() || f.in_view[vi] == 2) && lensSeenFromBehind(el, f, vi);
    if (back == 0) continue;
    pv.quality.verdict = QualityVerdict::kFallback;
    pv.quality.reasons += std::string(pv.quality.reasons.empty() ? "" : "; ") +
                          "the eye is behind the lens's front surface at " + std::to_string(back) + " seen vertices";
    pv.quality.action = "flagged";
    ++marked;
  }
  f.quality.verdict = std::max(f.quality.verdict, QualityVerdict::kFallback);
  f.quality.action = (f.quality.action == "none" ? "" : f.quality.action + "; ") + std::to_string(marked) +
                     " patch(es) seen from behind the lens";
  noteLensEdgeExits(el, f);
}

}  // namespace pvrr
