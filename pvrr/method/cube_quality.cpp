#include "pvrr/method/cube_quality.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "pvrr/base/error.h"
#include "pvrr/method/eye_side.h"
#include "pvrr/method/vertex_stage.h"
#include "pvrr/trace/ray_scene.h"

namespace pvrr {

namespace {

// The closest point of triangle abc to p (Ericson, Real-Time Collision Detection, 5.1.5).
Vec3 closestOnTriangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = glm::dot(ab, ap), d2 = glm::dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const Vec3 bp = p - b;
  const double d3 = glm::dot(ab, bp), d4 = glm::dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + ab * (d1 / (d1 - d3));
  const Vec3 cp = p - c;
  const double d5 = glm::dot(ab, cp), d6 = glm::dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + ac * (d2 / (d2 - d6));
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
  const double denom = 1.0 / (va + vb + vc);
  return a + ab * (vb * denom) + ac * (vc * denom);
}

std::string fixed(double v, int digits) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", digits, v);
  return buf;
}

std::string general(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.2g", v);
  return buf;
}

void addReason(std::string& reasons, const std::string& r) { reasons += (reasons.empty() ? "" : "; ") + r; }

// The point the cube of element e (centre c) shows in direction d: the first surface drawn in it (the
// environment, the elements of in_cube other than e), or the far point of the sky.
Vec3 cubeShows(const RayScene& rays, int e, const std::vector<char>& in_cube, const Vec3& c, const Vec3& d,
               double far_m) {
  double t0 = 0;
  for (int k = 0; k < 16; ++k) {
    const RayHit h = rays.intersect(c, d, t0);
    if (!h.hit()) break;
    const bool drawn = h.kind != HitKind::Element ||
                       (h.element != e && size_t(h.element) < in_cube.size() && in_cube[size_t(h.element)]);
    if (drawn) return h.point;
    t0 = h.t + rays.epsilon();
  }
  return c + far_m * d;
}

// Impostor mode: how many layers of element e's cube (centre c) lie in front of point p as seen from c: the drawn
// surfaces (the environment, the elements of in_cube other than e) the segment c -> p crosses before p. A closed
// convex mesh's back faces may be culled in the cube (RendererOptions::cull_back_faces), so only its faces turned
// to c count; any other surface is drawn from both sides. Up to 16 crossings.
int layersInFront(const RayScene& rays, int e, const std::vector<char>& in_cube, const Vec3& c, const Vec3& p) {
  const Scene& scene = rays.scene();
  const double len = glm::length(p - c);
  if (!(len > 0)) return 0;
  const Vec3 d = (p - c) / len;
  double t0 = 0;
  int n = 0;
  for (int k = 0; k < 16; ++k) {
    const RayHit h = rays.intersect(c, d, t0);
    if (!h.hit() || h.t >= len - 2 * rays.epsilon()) break;
    const bool drawn = h.kind != HitKind::Element ||
                       (h.element != e && size_t(h.element) < in_cube.size() && in_cube[size_t(h.element)]);
    if (drawn) {
      const bool culled_side = h.kind == HitKind::Environment && size_t(h.mesh) < scene.meshes.size() &&
                               scene.meshes[size_t(h.mesh)].closed_convex && glm::dot(h.normal, d) > 0;
      n += !culled_side;
    }
    t0 = h.t + rays.epsilon();
  }
  return n;
}

void flag(ElementFrame& f, const std::string& reasons) {
  f.quality.verdict = std::max(f.quality.verdict, QualityVerdict::kDegraded);
  std::string a = f.quality.action == "none" ? "" : f.quality.action;
  addReason(a, "flagged: " + reasons);
  f.quality.action = a;
}

}  // namespace

double nearestSurface(const Scene& scene, const Vec3& centre, const std::vector<const ElementFrame*>& elements) {
  double best = std::numeric_limits<double>::infinity();
  for (const EnvMesh& m : scene.meshes)
    for (const glm::u32vec3& t : m.triangles) {
      const Vec3 a = m.anchor + Vec3(m.positions[t.x]), b = m.anchor + Vec3(m.positions[t.y]),
                 c = m.anchor + Vec3(m.positions[t.z]);
      best = std::min(best, glm::length(closestOnTriangle(centre, a, b, c) - centre));
    }
  for (const ElementFrame* f : elements)
    for (const cad::Triangle& t : f->grid.triangles)
      best = std::min(best, glm::length(closestOnTriangle(centre, f->world_pos[t.x], f->world_pos[t.y],
                                                          f->world_pos[t.z]) - centre));
  return best;
}

double cubeNearPlane(double nearest) { return std::isfinite(nearest) ? std::max(kMinCubeNear_m, 0.5 * nearest) : kMinCubeNear_m; }

double cubeFarPlane(const Scene& scene, const Vec3& centre) {
  return 2.0 * (scene.boundsRadius() + glm::length(centre - scene.bounds_min)) + 1.0;
}

double relativeDepthResolution(double near_m, double far_m, double d) {
  // Window depth z = far / (far - near) (1 - near / d): dz/dd = far near / ((far - near) d^2); a float depth
  // near 1 resolves 2^-24.
  return std::ldexp(1.0, -24) * d * (far_m - near_m) / (far_m * near_m);
}

CubeQuality assessCubeQuality(const RayScene& rays, ElementFrame& f, RenderMode mode, const Vec3& eye, double near_m,
                              double far_m, const std::vector<char>& in_cube, const CubeQualityLimits& limits) {
  const Scene& scene = rays.scene();
  const Element& el = scene.elements[size_t(f.element)];
  f.quality = ElementQuality{};
  f.quality.action = "none";
  CubeQuality q;
  if (f.rays.empty()) {
    try {
      traceVertexRays(rays, f, eye, VertexStageOptions{});
    } catch (const Error& e) {  // e.g. the eye on a vertex: the cube modes draw such an element all the same
      f.rays.clear();
      f.quality.action = std::string("not assessed: ") + e.what();
      return q;
    }
  }
  const Vec3 centre = Vec3(el.local_to_world[3]);
  const std::vector<VertexRay>& vr = f.rays[f.rays.size() / 2];
  const int layers = std::max(1, scene.render.impostor_layers);
  const bool lens = el.type == ElementType::Lens;
  std::vector<double> parallax;
  // The vertices the observer sees (in its clip volume, with a margin for the triangles it sees in part).
  const Mat4 clip = scene.observer.visibilityProjection() * scene.observer.view();
  f.in_view.assign(vr.size(), 0);
  for (size_t i = 0; i < vr.size(); ++i) {
    const Vec4 c = clip * Vec4(f.world_pos[i], 1.0);
    const double m = 1.25 * c.w;
    f.in_view[i] = c.w > 0 && std::abs(c.x) <= m && std::abs(c.y) <= m ? 2 : 0;
  }
  for (size_t i = 0; i < vr.size(); ++i) {
    if (!f.in_view[i]) continue;
    const bool back = glm::dot(eye - f.world_pos[i], f.world_normal[i]) < 0;
    if (back && !lens) continue;  // a mirror's back: drawn dark, as the reference draws it
    ++q.seen;
    q.lens_back_vertices += back && lens;
    const VertexRay& r = vr[i];
    if (r.status == VertexStatus::Tir) continue;
    if (r.status == VertexStatus::Hit) q.max_hit_distance_m = std::max(q.max_hit_distance_m, glm::length(r.hit - centre));
    if (mode == RenderMode::Impostor && r.status == VertexStatus::Hit) {
      ++q.hit_vertices;
      q.behind_layers_vertices += layersInFront(rays, f.element, in_cube, centre, r.hit) >= layers;
    }
    if (mode != RenderMode::Envmap) continue;
    const Vec3 shown = cubeShows(rays, f.element, in_cube, centre, r.dir, far_m);
    parallax.push_back(arcminutes(angleBetween(r.hit - r.origin, shown - r.origin)));
  }
  for (const cad::Triangle& t : f.grid.triangles) {
    if (mode != RenderMode::Envmap || lens) break;
    const uint32_t a = t.x, b = t.y, c = t.z;
    if (!f.in_view[a] || !f.in_view[b] || !f.in_view[c]) continue;
    if (glm::dot(eye - f.world_pos[a], f.world_normal[a]) < 0 || glm::dot(eye - f.world_pos[b], f.world_normal[b]) < 0 ||
        glm::dot(eye - f.world_pos[c], f.world_normal[c]) < 0)
      continue;
    const std::vector<Vec3>& n = f.world_normal;
    q.max_normal_spread_deg = std::max({q.max_normal_spread_deg, degrees(angleBetween(n[a], n[b])),
                                        degrees(angleBetween(n[b], n[c])), degrees(angleBetween(n[c], n[a]))});
  }
  q.depth_relative = q.max_hit_distance_m > 0 ? relativeDepthResolution(near_m, far_m, q.max_hit_distance_m) : 0.0;
  if (!parallax.empty()) {
    std::sort(parallax.begin(), parallax.end());
    q.parallax_median_arcmin = parallax[parallax.size() / 2];
    q.parallax_max_arcmin = parallax.back();
  }
  std::string reasons;
  if (q.depth_relative > limits.max_depth_relative)
    addReason(reasons, "the cube's depth buffer resolves the hits " + fixed(q.max_hit_distance_m, 1) +
                           " m away only to " + general(100 * q.depth_relative) + " % of their distance (limit " +
                           general(100 * limits.max_depth_relative) + " %; near plane " + general(near_m) +
                           " m): what the cube shows there is unreliable");
  if (q.parallax_median_arcmin > limits.max_parallax_median_arcmin)
    addReason(reasons, "envmap mode looks every ray up from the cube's centre: the points it shows are off by " +
                           fixed(q.parallax_median_arcmin, 0) + "' median, " + fixed(q.parallax_max_arcmin, 0) +
                           "' max at the seen vertices (limit " + fixed(limits.max_parallax_median_arcmin, 0) +
                           "' median); impostor or pvrr mode traces them");
  if (q.max_normal_spread_deg > limits.max_normal_spread_deg)
    addReason(reasons, "triangles span up to " + fixed(q.max_normal_spread_deg, 1) + " deg of surface normals (limit " +
                           fixed(limits.max_normal_spread_deg, 1) +
                           " deg): envmap mode interpolates the normals between the vertices");
  if (mode == RenderMode::Envmap && q.lens_back_vertices > 0)
    addReason(reasons, "the eye is behind the lens's front surface at " + std::to_string(q.lens_back_vertices) +
                           " vertices: envmap mode's rays enter a lens through its front surface, so the lens is "
                           "drawn wrong there; impostor or pvrr mode draws it");
  if (mode == RenderMode::Envmap && lens && scene.render.max_depth < 2)
    addReason(reasons, "render.max_depth " + std::to_string(scene.render.max_depth) +
                           ": the reference ends every path through the lens at its back surface and draws it black, "
                           "envmap mode draws the scene through it; pvrr and impostor modes keep the depth limit");
  if (mode == RenderMode::Impostor && q.hit_vertices > 0 &&
      double(q.behind_layers_vertices) / double(q.hit_vertices) > limits.max_behind_layers_share)
    addReason(reasons, std::to_string(q.behind_layers_vertices) + " of " + std::to_string(q.hit_vertices) +
                           " seen vertex rays meet a surface that lies behind " + std::to_string(layers) +
                           " or more surfaces as seen from the cube's centre (limit " +
                           fixed(100 * limits.max_behind_layers_share, 0) + " %): the " + std::to_string(layers) +
                           " layer(s) of the distance maps (render.impostor_layers) do not hold it, and impostor "
                           "mode shows the sky there; pvrr mode or the reference traces those rays");
  f.eye = eye;
  if (mode == RenderMode::Envmap && lens) {
    // As pvrr mode's vertices (eye_side.h lensEdgeExits): envmap mode draws those vertices dark (no
    // transmittance: the reference absorbs them at the edge) but interpolates across the band per fragment.
    const LensEdgeExits e = lensEdgeExits(el, f, nullptr);
    if (e.vertices > 0)
      addReason(reasons, std::to_string(e.vertices) + " seen vertex ray(s) leave the glass through the lens's edge (up to " +
                             fixed(1e3 * e.max_beyond_m, 1) + " mm beyond the outline, " + fixed(e.max_band_arcmin, 0) +
                             "' as seen from the eye): envmap mode draws those vertices dark, as the reference "
                             "does, but blends them into their neighbours across the band; impostor mode traces the edge");
  }
  f.quality.note = eyeSideNote(scene, f);
  if (!reasons.empty()) flag(f, reasons);
  return q;
}

void noteUnresolvedSearches(ElementFrame& f, long unresolved, long pixels, const CubeQualityLimits& limits) {
  if (pixels <= 0 || unresolved <= 0) return;
  const double share = double(unresolved) / double(pixels);
  if (share <= limits.max_unresolved_share) return;
  flag(f, std::to_string(unresolved) + " of " + std::to_string(pixels) + " pixels (" + fixed(100 * share, 1) +
              " %) ended their impostor search off every layer of the distance maps (limit " +
              fixed(100 * limits.max_unresolved_share, 1) +
              " %): the maps do not hold what those rays meet (a surface hidden from the cube's centre, or the "
              "search ran out of steps); pvrr mode or the reference traces them");
}

}  // namespace pvrr
