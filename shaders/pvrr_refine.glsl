// Per-fragment refinement of pvrr mode (render.refine; docs/method.md "Per-fragment refinement"), included by
// element_pvrr.frag; everything here only with REFINE (the number of secant steps). A lens fragment's exact
// exit rays (one per channel) are searched the same way: see "Lenses" below. A mirror fragment's exact
// reflected ray, from the exact surface point its view ray meets and the exact normal there, is searched in its
// patch's map: the map's depth gives, for each direction from the map's viewpoint, the depth along the map's
// forward of what it shows; the search takes secant steps on the difference between the ray point's depth and
// the map's depth in the ray point's direction ([Szirmay-Kalos et al.]'s Hit(), with the map's perspective depth
// in place of a cube's distance), starting from the ray point at the depth that the exact vertex hits give,
// interpolated. The map's viewpoint is fitted to the element's rays, so the search starts next to the answer and
// has little parallax to cross. Where it ends off the map's surface (no convergence, outside the map, a texel
// the pass left unread, or across a depth edge) the fragment keeps the interpolated coordinate.
// The exact surface point comes from each triangle's quadratic (P2) interpolant of the surface: the vertices and
// the exact surface at the edges' midpoints (pvrr/gl/pvrr_pass.cpp uploadRefinedPatch, in doubles), whose error
// falls with the cube of the vertex spacing where the flat triangle's falls with its square; the exact normal
// from the mirror's normal map (pvrr/impostor/surface_map.h) at that point's surface parameters. (A P2 normal
// as well, with no texture read, was measured: where a triangle straddles a knot line of a cubic NURBS or a
// subdivision surface the normal's third derivative jumps and the P2 normal errs by arcminutes, docs/accuracy.md.)
// The triangles' vertices are not shared: each carries its barycentric corner and its triangle's deviations at
// the three midpoints, in the channel sets a refined mirror's one channel leaves free (the aliases below).
// With REFINE_COUNT (the second pass's draws in frames whose counts are read: pvrr/gl/pvrr_refine.cpp), atomic
// counters count the fragments whose view ray missed the exact surface (the triangles' silhouette overhang) and
// those whose search failed; pvrr/gl/pvrr_pass.cpp counts the fragments drawn with a query and reads both into
// the second pass's note once the frame has finished. Without it the shader has no side effects: with them
// llvmpipe took 0.3 to 0.8 ms longer over a steady car-mirror frame (docs/performance.md "The counters only
// where they are read"), partly its late depth test, which a shader that writes memory gets unless it asks for
// early tests (as the counting variant does).
#if (defined(REFINE) || defined(REFINE_P2)) && CHANNELS != 1 && !defined(LENS)
#error "REFINE: a mirror's one channel only"
#endif
#if defined(REFINE_P2)
// A refined mirror's triangle whose exact rays the CPU found smooth enough (pvrr/gl/pvrr_pass.cpp
// refinedSplit): its texture coordinate is the quadratic (P2) interpolant, in the flat triangle's barycentric
// coordinates, of the exact rays' volume coordinates at its corners and at the points where the view rays
// through its edges' midpoints meet the exact surface; no search, no texture read beyond the unrefined ones.
// v_st0: the corner's volume coordinate (s, t, 1); v_st1.xy: its barycentric corner (b1, b2); v_st2, v_w1: the
// deviations D01, D12, D20 of the edges' midpoint nodes from the edges' means (the same at all three corners).
vec2 quadraticST() {
  vec2 b = v_st1.xy;
  float b0 = 1.0 - b.x - b.y;
  vec2 st = v_st0.xy + 4.0 * (b0 * b.x * v_st2.xy + b.x * b.y * vec2(v_st2.z, v_w1.x) + b.y * b0 * v_w1.yz);
  return min(st * u_st_scale, u_st_max);
}
#endif
#if defined(REFINE)
uniform bool u_refine;          // this patch view is refined (else the interpolated coordinate, as without REFINE)
uniform sampler2D u_map_depth;  // the map's depth attachment (window depth), with a linear sampler
uniform mat4 u_map_vp;          // the map's camera: positions relative to its viewpoint -> clip
uniform vec3 u_depth_lin;       // P[2][2], P[3][2] of its projection, and its near depth: the depth along the map's
                                // forward of NDC depth z is P[3][2] / (z + P[2][2])
uniform float u_edge;           // across a depth edge: the four texels' depths differ by more than this (relative)
#if defined(REFINE_COUNT)
// The depth test before the shader (the shader writes no depth and never discards: the same picture).
layout(early_fragment_tests) in;
layout(binding = 0, offset = 0) uniform atomic_uint u_count_failed;
layout(binding = 0, offset = 4) uniform atomic_uint u_count_missed;
#define REFINE_COUNTED(counter) atomicCounterIncrement(counter)
#else
#define REFINE_COUNTED(counter)
#endif

const float REFINE_TOL = 2e-5;     // converged: |depth difference| <= this * depth (the depth's float resolution)
const float REFINE_ACCEPT = 1e-3;  // on the map's surface: at most this, after the last step
const float REFINE_MAX_STEP = 0.25;  // of the triangle (barycentric): the surface step from the triangle's point

float linearDepth(float window_z) { return u_depth_lin.y / (2.0 * window_z - 1.0 + u_depth_lin.x); }
// The map's texture coordinate of volume coordinate st, half a texel inside its region (as mapST).
vec2 mapTexST(vec2 st) { return min(st * u_st_scale, u_st_max); }

// The linear depth of the map at texture coordinate tc, bilinear between the four texels' window depths (as
// GL_LINEAR filters them: exact between texels for a plane), and whether those texels lie on one surface: none
// left unread (at the near plane), no depth edge between them. One gather serves both.
float mapDepthChecked(vec2 tc, out bool on_surface) {
  vec4 z = textureGather(u_map_depth, tc);  // texels (0, 1), (1, 1), (1, 0), (0, 0) of the bilinear footprint
  vec2 w = fract(tc * vec2(textureSize(u_map_depth, 0)) - 0.5);
  float zb = mix(mix(z.w, z.z, w.x), mix(z.x, z.y, w.x), w.y);
  vec4 dz = u_depth_lin.y / (2.0 * z - 1.0 + u_depth_lin.x);
  float lo = min(min(dz.x, dz.y), min(dz.z, dz.w)), hi = max(max(dz.x, dz.y), max(dz.z, dz.w));
  on_surface = hi <= lo * (1.0 + u_edge) && lo > u_depth_lin.z * 1.001;
  return linearDepth(zb);
}

// The map's volume coordinate (s, t) in [0, 1]^2 where the ray x + t R (x relative to the map's viewpoint)
// meets what the map shows; false where the search ends off the map's surface. It starts at the depth
// hit_depth (along the map's forward) that the fragment's interpolated exact vertex hits give, and takes
// REFINE steps on the difference between the ray point's depth and the map's depth in its direction: the
// first to the depth the map shows there ([Szirmay-Kalos et al.]'s Hit()), then secant steps; the last
// point (or the first that converged) is read with its four texels, which also tell whether it lies on one
// surface.
float refine_t;  // the last search's ray parameter
bool refineSearch(vec3 x, vec3 R, float hit_depth, out vec2 st) {
  vec4 cx = u_map_vp * vec4(x, 1.0), cr = u_map_vp * vec4(R, 0.0);
  // The ray must move along the map's axis: forward (the forward is its rays' mean direction), or backward in a
  // zooming-region map (its rays pass its viewpoint and meet what lies behind it, its farthest depth first).
  if (abs(cr.w) <= 1e-3) return false;
  float t = (hit_depth - cx.w) / cr.w, t_prev = 0.0, f_prev = 0.0;
  for (int i = 0; i < REFINE; ++i) {
    vec4 c = cx + t * cr;
    if (c.w <= 0.0) return false;
    st = c.xy / c.w * 0.5 + 0.5;
    if (any(lessThan(st, vec2(0.0))) || any(greaterThan(st, vec2(1.0)))) return false;
    float d = linearDepth(texture(u_map_depth, mapTexST(st)).r), f = c.w - d;
    if (abs(f) <= REFINE_TOL * d) break;
    float t_next = i > 0 && f != f_prev ? t - f * (t - t_prev) / (f - f_prev) : (d - cx.w) / cr.w;
    t_prev = t;
    f_prev = f;
    t = t_next;
  }
  vec4 c = cx + t * cr;
  refine_t = t;
  if (c.w <= 0.0) return false;
  st = c.xy / c.w * 0.5 + 0.5;
  if (any(lessThan(st, vec2(0.0))) || any(greaterThan(st, vec2(1.0)))) return false;
  bool on_surface;
  float d = mapDepthChecked(mapTexST(st), on_surface);
  return on_surface && abs(c.w - d) <= REFINE_ACCEPT * d;
}

#if !defined(LENS)
// The triangle's P2 data (world frame, metres): the exact surface point at the midpoint of edge (i, j) of its
// corners less the edge's mean; v_bary: the fragment's barycentric coordinates (b1, b2) of corners 1 and 2, and
// the depth of the exact vertex hits along the map's forward; v_param: its normalised surface parameters (s, t).
#define v_bary v_st1
#define v_dp01 v_st2
#define v_dp12 v_w1
#define v_dp20 v_w2
#define v_param v_st_seen
uniform sampler2D u_surf_n;     // the mirror's unit normal over its parameter domain (local frame; surface_map.h)
uniform vec2 u_sm;              // its texture coordinate = (s, t) * u_sm.x + u_sm.y
uniform mat3 u_to_local;        // world directions -> the element's local frame (the normal map's)

// The triangle's edges S1 - S0, S2 - S0 and its parameters' (s, t)1 - (s, t)0, (s, t)2 - (s, t)0: from the
// screen derivatives of the fragment's position, parameters and barycentric coordinates, all affine on the
// triangle (so exact up to rounding; they only steer the step). Taken in main's uniform control flow, before
// any fragment returns.
mat2x3 refine_edges;
mat2 refine_param_edges;
bool refine_flat;  // the triangle is seen edge-on: no step
void refineDerivatives() {
  mat2 db = mat2(dFdx(v_bary.xy), dFdy(v_bary.xy));
  float det = determinant(db);
  refine_flat = !(abs(det) > 1e-20);
  mat2 inv = refine_flat ? mat2(1.0) : inverse(db);
  refine_edges = mat2x3(dFdx(v_pos), dFdy(v_pos)) * inv;
  refine_param_edges = mat2(dFdx(v_param.xy), dFdy(v_param.xy)) * inv;
}

// This fragment's exact reflected ray: its origin relative to the map's viewpoint, and its direction, from the
// exact surface point on the view ray along `view` (unit, from u_view_origin) and the exact normal there; false
// where the view ray misses the surface (a longer step: it passes the surface's edge, or leaves its parameter
// domain). One Gauss-Newton step
// from the fragment's barycentric point on the P2 surface: the triangle lies within its sag of the surface, so
// one step leaves an error of the order of the sag squared over the radius of curvature.
bool exactReflection(vec3 view, out vec3 x, out vec3 R) {
  vec2 b = v_bary.xy;
  float b0 = 1.0 - b.x - b.y;
  vec3 p = v_pos + 4.0 * (b0 * b.x * v_dp01 + b.x * b.y * v_dp12 + b.y * b0 * v_dp20);
  vec3 su = refine_edges[0] + 4.0 * ((b0 - b.x) * v_dp01 + b.y * (v_dp12 - v_dp20));
  vec3 sv = refine_edges[1] + 4.0 * (b.x * (v_dp12 - v_dp01) + (b0 - b.y) * v_dp20);
  vec3 w = p - u_view_origin, r = w - dot(w, view) * view;
  vec3 a = su - dot(su, view) * view, c = sv - dot(sv, view) * view;
  float aa = dot(a, a), ac = dot(a, c), cc = dot(c, c);
  // aa cc - ac^2 = ((su x sv) . view)^2 for vectors projected across the view, without the cancellation.
  float k = dot(cross(su, sv), view), det = k * k;
  if (refine_flat || !(det > 1e-12 * aa * cc)) return false;
  vec2 g = vec2(dot(a, r), dot(c, r));
  vec2 delta = -vec2(cc * g.x - ac * g.y, aa * g.y - ac * g.x) / det;
  if (max(abs(delta.x), abs(delta.y)) > REFINE_MAX_STEP) return false;
  vec3 pos = p + su * delta.x + sv * delta.y;  // relative to this camera's origin
  vec2 st = v_param.xy + refine_param_edges * delta;
  if (any(lessThan(st, vec2(0.0))) || any(greaterThan(st, vec2(1.0)))) return false;
  vec3 n = normalize(texture(u_surf_n, st * u_sm.x + u_sm.y).xyz * u_to_local);
  x = pos - u_seen_offset;
  R = reflect(view, n);
  return true;
}

// The texture coordinate (of the map's texture) this fragment reads: the refined one, or st_interpolated
// (mapST's) where the fragment is not refined or its refinement fails.
vec2 refinedST(vec3 view, vec2 st_interpolated) {
  if (!u_refine) return st_interpolated;
  vec3 x, R;
  if (!exactReflection(view, x, R)) {
    REFINE_COUNTED(u_count_missed);
    return st_interpolated;
  }
  vec2 st;
  if (!refineSearch(x, R, v_bary.z, st)) {
    REFINE_COUNTED(u_count_failed);
    return st_interpolated;
  }
  return mapTexST(st);
}
#else  // LENS
// Lenses: the fragment's exact path through the glass, per channel (docs/method.md "Per-fragment refinement"):
// the view ray's entry point on the front surface, refraction in with the channel's index, the internal ray's
// crossing of the back surface, refraction out. A surface that is a sphere or a plane is met in closed form
// (SPHERE_FRONT, SPHERE_BACK); any other in the lens's refractor height maps (lens_march.glsl,
// pvrr/impostor/lens_height_map.h; impostor mode's, eye-independent, baked once), by secant steps on the ray's
// height above it: from the rasterised triangle's point for the front (entryPoint), from the entry point and the
// plane step for the back (backCrossing). The exit ray is then searched in the patch's map as a mirror's
// reflected ray is, starting at the depth the map shows at the channel's interpolated coordinate (every channel
// set is in use: no vertex attribute is left for the exact hits' depth, and the map's own depth there lies next
// to the answer); the seen channel's seen point is the search's ray point. A fragment whose exact path is not
// the vertex rays' kind keeps the interpolated coordinates: a view ray that meets the lens from behind, misses
// a surface or crosses outside the outline (missed, or failed at the rim), or whose internal ray meets the front
// first or is totally reflected at the back (u_count_tir); the totally reflected vertices' traced colours and
// seen points are added as without REFINE.
uniform vec3 u_offset;           // element.vert's: the lens's anchor (its local frame's origin) - camera origin
uniform mat3 u_to_local;         // world directions -> the lens's local frame (the height maps')
uniform vec3 u_channel_index;    // the glass's index at the wavelengths of this draw's channels 0, 1, 2
uniform int u_seen_channel;      // the channel (0 to 2) whose coordinate gives the seen point (v_st_seen's)
#if defined(REFINE_COUNT)
layout(binding = 0, offset = 8) uniform atomic_uint u_count_tir;
#endif

vec3 refine_entry;        // the view ray's entry point (lens frame), its direction and the inward surface normal
vec3 refine_dir;
vec3 refine_n;
int refine_state = 0;     // 0: not refined (u_refine off), 1: entered, 2: missed
bool refine_fell_back = false;  // some channel kept its interpolated coordinate (search failed)
bool refine_tir = false;        // some channel's exact path is totally reflected
vec3 refine_seen;               // the seen channel's ray point where its search ended (relative to the map's
bool refine_seen_ok = false;    // viewpoint), where it succeeded

// Where the ray p + t d inside the glass (p on the front surface, d downward: -z) meets the back surface:
// secant steps on its height above the back surface from p (the glass's thickness there) and the plane step
// that drops the ray by that height, to 10 nm as glassExit (a smooth surface's root in two to four steps, where
// glassExit's general march, which must find the first of two surfaces, costs several times more reads).
// -1: the ray does not run down, or the steps did not converge; the caller tests that the root lies inside the
// glass (below the front surface), else the ray meets the front first.
// texel: the back map's texel at the root (its height and outward normal).
float backCrossing(vec3 p, vec3 d, out vec4 texel) {
  texel = vec4(0.0);
  if (d.z > -1e-4) return -1.0;
  float ta = 0.0, ga = p.z - lensTexel(true, p.xy).x;
  float tb = ga / -d.z;
  vec3 q = p + tb * d;
  texel = lensTexel(true, q.xy);
  float gb = q.z - texel.x;
  for (int i = 0; i < 6 && abs(gb) > 1e-8 && gb != ga; ++i) {
    float tc = tb - gb * (tb - ta) / (gb - ga);
    ta = tb, ga = gb, tb = tc;
    q = p + tb * d;
    texel = lensTexel(true, q.xy);
    gb = q.z - texel.x;
  }
  return abs(gb) <= 1e-7 && tb > 0.0 ? tb : -1.0;
}

// SPHERE_FRONT, SPHERE_BACK: that surface is a sphere or a plane (cad::SagSurface::sphereCurvature), met in closed
// form with no texture read; the other surfaces in the height maps.
#if defined(SPHERE_FRONT) || defined(SPHERE_BACK)
uniform vec4 u_spheres;  // the front's curvature c = 1/R and vertex z, the back's (lens frame, metres)
#endif
// Where the ray o + t d meets the sphere (or plane, c = 0) of curvature c with its vertex at (0, 0, z0):
// c (x^2 + y^2 + Z^2) = 2 Z with Z = z0 - z, the sag graph's root (the one that stays finite as c -> 0, in the
// form without cancellation); its +z-side unit normal (c x, c y, 1 - c Z) / |.| in n. False where the ray
// misses it or meets its far half.
bool sphereHit(vec3 o, vec3 d, float c, float z0, out float t, out vec3 n) {
  float Z0 = z0 - o.z;
  float b = c * (dot(o.xy, d.xy) - Z0 * d.z) + d.z, q = c * (dot(o.xy, o.xy) + Z0 * Z0) - 2.0 * Z0;
  float disc = b * b - c * q;
  float den = -b - (b < 0.0 ? -1.0 : 1.0) * sqrt(max(disc, 0.0));
  t = q / den;
  vec3 p = o + t * d;
  float w = 1.0 - c * (z0 - p.z);
  n = normalize(vec3(c * p.xy, w));
  return disc >= 0.0 && den != 0.0 && w > 0.0;
}

// OUTLINE_ELLIPSE: the lens's outline is an ellipse or a circle, tested in closed form (as cad::Outline::contains)
// in place of the outline mask's bilinear read (two a fragment; the mask's threshold also rounds the outline to
// its texels).
#if defined(OUTLINE_ELLIPSE)
uniform vec4 u_ellipse;  // the outline's centre (lens frame xy, metres) and 1 / its half width and half height
bool inLensOutline(vec2 xy) {
  vec2 q = (xy - u_ellipse.xy) * u_ellipse.zw;
  return dot(q, q) <= 1.0;
}
#else
bool inLensOutline(vec2 xy) { return inOutline(xy); }
#endif

// The front surface's height at local xy.
float frontHeight(vec2 xy) {
#if defined(SPHERE_FRONT)
  float c = u_spheres.x, r2 = dot(xy, xy);
  return u_spheres.y - c * r2 / (1.0 + sqrt(max(1.0 - c * c * r2, 0.0)));
#else
  return lensTexel(false, xy).x;
#endif
}

// The fragment's entry into the glass; its state for refinedLensST (called once, before the channels).
void refineLensEntry(vec3 view) {
  if (!u_refine) return;
  refine_state = 2;
  if (dot(view, v_normal) >= 0.0) return;  // seen from behind
  vec3 x = u_to_local * (v_pos - u_offset), v = u_to_local * view;
#if defined(SPHERE_FRONT)
  float t;
  vec3 n;
  if (!sphereHit(x, v, u_spheres.x, u_spheres.y, t, n)) return;
  vec3 e = x + t * v;
  if (!inLensOutline(e.xy)) return;
#else
  vec3 e = entryPoint(x, v, false);
  if (!inLensOutline(e.xy)) return;
  vec3 n = normalize(lensTexel(false, e.xy).yzw);
#endif
  if (dot(v, n) >= 0.0) return;
  refine_entry = e;
  refine_dir = v;
  refine_n = n;
  refine_state = 1;
}

// Channel k's texture coordinate (of the map's texture): the refined one, or st_interpolated where the
// fragment is not refined or the channel's refinement fails.
vec2 refinedLensST(int k, vec2 st_interpolated) {
  if (refine_state != 1) return st_interpolated;
  float eta = u_channel_index[k];
  vec3 d = refract(refine_dir, refine_n, 1.0 / eta);
#if defined(SPHERE_BACK)
  float t;
  vec3 nout;
  if (!sphereHit(refine_entry, d, u_spheres.z, u_spheres.w, t, nout) || !(t > 0.0)) t = -1.0;
  nout = -nout;  // out of the glass: the -z side
#else
  vec4 back_texel;
  float t = backCrossing(refine_entry, d, back_texel);
#endif
  if (t < 0.0) {  // no crossing found
    refine_fell_back = true;
    return st_interpolated;
  }
  vec3 p = refine_entry + t * d;
  if (frontHeight(p.xy) < p.z) {  // above the front surface: the ray inside meets the front first
    refine_tir = true;
    return st_interpolated;
  }
  if (!inLensOutline(p.xy)) {  // through the rim: absorbed in the tracer
    refine_fell_back = true;
    return st_interpolated;
  }
#if !defined(SPHERE_BACK)
  vec3 nout = normalize(back_texel.yzw);
#endif
  vec3 out_dir = dot(d, nout) > 0.0 ? refract(d, -nout, eta) : vec3(0.0);
  if (out_dir == vec3(0.0)) {
    refine_tir = true;
    return st_interpolated;
  }
  vec3 x = p * u_to_local + u_offset - u_seen_offset, R = out_dir * u_to_local;
  vec2 st;
  if (!refineSearch(x, R, linearDepth(texture(u_map_depth, st_interpolated).r), st)) {
    refine_fell_back = true;
    return st_interpolated;
  }
  if (k == u_seen_channel) {
    refine_seen = x + refine_t * R;
    refine_seen_ok = true;
  }
  return mapTexST(st);
}

// Counts the fragment once (the second pass's draws): missed the glass, totally reflected, or some channel's
// search off the map's surface.
void refineLensCount() {
#if defined(REFINE_COUNT)
  if (refine_state == 0) return;
  if (refine_state == 2) atomicCounterIncrement(u_count_missed);
  else if (refine_tir) atomicCounterIncrement(u_count_tir);
  else if (refine_fell_back) atomicCounterIncrement(u_count_failed);
#endif
}
#endif  // LENS
#endif  // REFINE
