// Per-fragment refinement of pvrr mode (render.refine; docs/method.md "Per-fragment refinement"), included by
// element_pvrr.frag; everything here only with REFINE (the number of secant steps). A mirror fragment's exact
// reflected ray, from the exact surface point its view ray meets and the exact normal there (the surface maps
// of pvrr/impostor/surface_map.h, surface_maps.glsl), is searched in its patch's map: the map's depth gives,
// for each direction from the map's viewpoint, the depth along the map's forward of what it shows; the search
// takes secant steps on the difference between the ray point's depth and the map's depth in the ray point's
// direction ([Szirmay-Kalos et al.]'s Hit(), with the map's perspective depth in place of a cube's distance),
// starting from the ray point at the depth the interpolated texture coordinate shows. The map's viewpoint is
// fitted to the element's rays, so the search starts next to the answer and has little parallax to cross.
// Where it ends off the map's surface (no convergence, outside the map, a texel the pass left unread, or across
// a depth edge) the fragment keeps the interpolated coordinate. Atomic counters count the refined fragments,
// those whose view ray missed the exact surface (the triangles' silhouette overhang, or beyond the outline)
// and those whose search failed (pvrr/gl/pvrr_pass.cpp reads them into the second pass's note).
#include "surface_maps.glsl"
#if defined(REFINE) && (CHANNELS != 1 || defined(LENS))
#error "REFINE: a mirror's one channel only"
#endif
#if defined(REFINE)
uniform bool u_refine;          // this patch view is refined (else the interpolated coordinate, as without REFINE)
uniform sampler2D u_map_depth;  // the map's depth attachment (window depth, read with texelFetch)
uniform mat4 u_map_vp;          // the map's camera: positions relative to its viewpoint -> clip
uniform vec3 u_depth_lin;       // P[2][2], P[3][2] of its projection, and its near depth: the depth along the map's
                                // forward of NDC depth z is P[3][2] / (z + P[2][2])
uniform vec3 u_offset;          // the element's anchor - this pass's camera origin (element.vert)
uniform mat3 u_to_local;        // world directions -> the element's local frame (surface_maps.glsl's)
layout(binding = 0, offset = 0) uniform atomic_uint u_count_refined;
layout(binding = 0, offset = 4) uniform atomic_uint u_count_missed;
layout(binding = 0, offset = 8) uniform atomic_uint u_count_failed;

const float REFINE_TOL = 2e-5;     // converged: |depth difference| <= this * depth (the depth's float resolution)
const float REFINE_ACCEPT = 1e-3;  // on the map's surface: at most this, after the last step
const float REFINE_EDGE = 0.05;    // across a depth edge: the four texels' depths differ by more than this
                                   // (relative; a surface seen at 89 deg from a 1024 texel map differs by ~0.01)

// The depth along the map's forward at volume coordinate st: bilinear between its four texels' linearised
// depths (the texels of the map's region only); spread: their max / min - 1. False where one of them is a
// texel the pass left unread (its depth is the near plane's).
bool mapDepth(vec2 st, out float depth, out float spread) {
  ivec2 size = textureSize(u_map_depth, 0);
  ivec2 last = ivec2(u_st_scale * vec2(size) + 0.5) - 1;
  vec2 x = st * vec2(last + 1) - 0.5, f = floor(x), a = x - f;
  ivec2 i0 = clamp(ivec2(f), ivec2(0), last), i1 = clamp(ivec2(f) + 1, ivec2(0), last);
  vec4 z = vec4(texelFetch(u_map_depth, i0, 0).r, texelFetch(u_map_depth, ivec2(i1.x, i0.y), 0).r,
                texelFetch(u_map_depth, ivec2(i0.x, i1.y), 0).r, texelFetch(u_map_depth, i1, 0).r);
  vec4 d = u_depth_lin.y / (2.0 * z - 1.0 + u_depth_lin.x);
  float lo = min(min(d.x, d.y), min(d.z, d.w)), hi = max(max(d.x, d.y), max(d.z, d.w));
  spread = hi / lo - 1.0;
  depth = mix(mix(d.x, d.y, a.x), mix(d.z, d.w, a.x), a.y);
  return lo > u_depth_lin.z * 1.001;
}

// The map's volume coordinate (s, t) in [0, 1]^2 where the ray x + t R (x relative to the map's viewpoint)
// meets what the map shows, searched from the coordinate st0 that the interpolation gives; false where the
// search ends off the map's surface.
bool refineSearch(vec3 x, vec3 R, vec2 st0, out vec2 st) {
  vec4 cx = u_map_vp * vec4(x, 1.0), cr = u_map_vp * vec4(R, 0.0);
  float d, spread;
  // The ray must move along the map's forward (it does: the forward is its rays' mean direction).
  if (cr.w <= 1e-3 || !mapDepth(st0, d, spread)) return false;
  float t = (d - cx.w) / cr.w, t_prev = 0.0, f_prev = 0.0, f = 0.0;
  for (int i = 0; i <= REFINE; ++i) {
    vec4 c = cx + t * cr;
    if (c.w <= 0.0) return false;
    st = c.xy / c.w * 0.5 + 0.5;
    if (any(lessThan(st, vec2(0.0))) || any(greaterThan(st, vec2(1.0))) || !mapDepth(st, d, spread)) return false;
    f = c.w - d;
    if (abs(f) <= REFINE_TOL * d || i == REFINE) break;
    // The first step moves the ray point to the depth the map shows in its direction; then secant steps.
    float t_next = i > 0 && f != f_prev ? t - f * (t - t_prev) / (f - f_prev) : (d - cx.w) / cr.w;
    t_prev = t;
    f_prev = f;
    t = t_next;
  }
  return abs(f) <= REFINE_ACCEPT * d && spread <= REFINE_EDGE;
}

// This fragment's exact reflected ray: its origin relative to the map's viewpoint, and its direction, from the
// exact surface point on the view ray along `view` (unit, from u_view_origin) and the exact normal there; false
// where the view ray misses the surface within its outline.
bool exactReflection(vec3 view, out vec3 x, out vec3 R) {
  vec3 e = u_to_local * (u_view_origin - u_offset), vl = u_to_local * view;
  vec2 st = surfaceHit(v_st1.xy, e, vl) * u_sm.x + u_sm.y;
  vec4 sp = bilinear(u_surf_p, st);  // w: 1 inside the outline
  vec3 w = sp.xyz - e;
  if (sp.w < 0.5 || length(w - dot(w, vl) * vl) > 1e-5 * length(w)) return false;
  vec3 pos = u_offset + sp.xyz * u_to_local;  // relative to this pass's camera origin
  vec3 n = normalize(bilinear(u_surf_n, st).xyz * u_to_local);
  x = pos - u_seen_offset;
  R = reflect(normalize(pos - u_view_origin), n);
  return true;
}

// The texture coordinate (of the map's texture) this fragment reads: the refined one, or st_interpolated
// (mapST's) where the fragment is not refined or its refinement fails.
vec2 refinedST(vec3 view, vec2 st_interpolated) {
  if (!u_refine) return st_interpolated;
  vec3 x, R;
  if (!exactReflection(view, x, R)) {
    atomicCounterIncrement(u_count_missed);
    return st_interpolated;
  }
  vec2 st;
  if (!refineSearch(x, R, v_st0.xy / v_st0.z, st)) {
    atomicCounterIncrement(u_count_failed);
    return st_interpolated;
  }
  atomicCounterIncrement(u_count_refined);
  return min(st * u_st_scale, u_st_max);
}
#endif
