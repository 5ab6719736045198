#version 330 core
// Optical elements. Variants by prepended defines:
//   MODE_PVRR    the warped first-pass map (paper 3.4). CHANNELS 1: one texture-coordinate set; CHANNELS 3:
//                three sets (RGB dispersion, or three samples of a spectral set), colour = sum_i w_i * map(st_i).
//                RGB_CHANNELS (with CHANNELS 3): the sets are the R, G and B channels, whose weights are zero
//                but in their own component, and the map is three R32F planes (shaders/outputs.glsl, PLANES):
//                colour = (w_0.r R(st_0), w_1.g G(st_1), w_2.b B(st_2)), the same sum with two thirds of the
//                weights left uninterpolated and one float per texel read.
//                More than three channels: one additive draw per set of three (pvrr/gl/renderer.cpp).
//   MODE_ENVMAP  the classic dynamic cube map from the element centre (lens: looked up along the
//                interpolated exact exit directions of the vertices, the 'refraction vectors' baseline)
//   MODE_IMPOSTOR  distance impostors (Szirmay-Kalos et al., seeds 003): the envmap cube maps, whose seen
//                points give each direction's distance from the cube's origin, searched per fragment for the
//                point the exact reflected (or doubly refracted) ray meets. LENS: the ray through the glass is
//                traced per fragment in the lens's refractor height maps (pvrr/impostor/lens_height_map.h).
//                IMPOSTOR_ITERATIONS: the search's false-position steps; IMPOSTOR_CHANNELS 3: a lens's R, G
//                and B each refracted with its own index (u_index), else the middle one only (for a mirror:
//                through the scene's lens, LENS_IN_CUBES).
//                CUBE_ELEMENTS n (2 to 4): the scene's n elements each have cube maps in which the other
//                mirrors are drawn with their surface point, normal and index (distance-normal impostors,
//                seeds 000): a search that meets a mirror reflects there and goes on in that mirror's cubes
//                (followCubes); LENS_IN_CUBES: the other elements' cubes show the scene's one lens too, and a
//                search that meets it refracts through its height maps and goes on in the lens's cubes.
//                IMPOSTOR_LAYERS 2: each distance map has a second, depth-peeled layer (seeds 001), searched
//                where the first layer's search ends off a surface (layeredHit): the element's first draw
//                discards those pixels, LAYER_PROBE counts them, LAYER_MARCH draws them.
//                CUBE_GEOMETRY: an element drawn into another element's cube: a mirror's exact surface point
//                (a lens's mesh point) as the seen point, and its normal and element id in the surface output.
//   MODE_PLAIN   a plain grey shaded surface (raster mode); u_dark: black, an element met at the depth limit
//                inside another element's map (the tracer absorbs there)
//   LENS         the element is a lens (transmission) rather than a mirror (reflection)
//   NO_SEEN_POINTS  colour only: the seen-point maps are not read (RendererOptions::seen_points off)
in vec3 v_pos;
in vec3 v_normal;
in vec3 v_st0;
in vec3 v_st1;
in vec3 v_st2;
in vec3 v_w0;
in vec3 v_w1;
in vec3 v_w2;
in vec3 v_st_seen;
in vec4 v_tir;        // PVRR lens: the tracer's colour of totally reflected channels (their map weight is 0)
in vec3 v_tir_seen;
uniform vec3 u_view_origin;      // where the viewing rays start, relative to the camera origin
uniform float u_element_id;      // index + 1
uniform bool u_metal;
uniform vec3 u_reflectance;
uniform vec3 u_metal_n;
uniform vec3 u_metal_k;
uniform vec3 u_seen_offset;      // (the map's camera origin) - (this pass's camera origin)
uniform bool u_additive;         // the second or later of the additive draws of more than three channels
#if defined(MODE_PVRR)
uniform sampler2D u_map;         // first pass colour (linear)
uniform sampler2D u_seen_map;    // first pass seen points, relative to the map's camera origin (LINEAR)
#if defined(RGB_CHANNELS)
uniform sampler2D u_map_g;       // the G and B planes (u_map: the R plane)
uniform sampler2D u_map_b;
#endif
uniform vec2 u_st_scale;         // the map fills the lower-left (texels / texture size) of its texture
uniform vec2 u_st_max;           // half a texel inside that region's far edges
// A projective texture coordinate (s q, t q, q) of the volume's [0, 1]^2 to the map's region of its texture.
vec2 mapST(vec3 stq) { return min(stq.xy / stq.z * u_st_scale, u_st_max); }
#elif defined(MODE_ENVMAP)
uniform samplerCube u_cube;
uniform samplerCube u_seen_cube;
#elif defined(MODE_IMPOSTOR)
uniform samplerCube u_cube;       // the environment's colour from the element's origin (the envmap cube)
uniform samplerCube u_seen_cube;  // its seen points relative to that origin (u_seen_offset): the distances
uniform mat3 u_to_local;          // world directions -> the element's local frame (whose origin is the cube's)
#if IMPOSTOR_LAYERS > 1
uniform samplerCube u_cube1;      // the second layers (depth-peeled)
uniform samplerCube u_seen_cube1;
#endif
#if defined(CUBE_ELEMENTS)
// Per element (index): its cubes (colour; seen points, whose lengths are the distances; normal and index + 1
// of an element drawn in them, 0 elsewhere), their origin relative to the camera origin, and its mirror
// material.
uniform samplerCube u_cubes[CUBE_ELEMENTS];
uniform samplerCube u_seen_cubes[CUBE_ELEMENTS];
uniform samplerCube u_normal_cubes[CUBE_ELEMENTS];
#if IMPOSTOR_LAYERS > 1
uniform samplerCube u_cubes1[CUBE_ELEMENTS];  // the second layers (depth-peeled)
uniform samplerCube u_seen_cubes1[CUBE_ELEMENTS];
uniform samplerCube u_normal_cubes1[CUBE_ELEMENTS];
#endif
uniform vec3 u_cube_centre[CUBE_ELEMENTS];
uniform bool u_el_metal[CUBE_ELEMENTS];
uniform vec3 u_el_reflectance[CUBE_ELEMENTS];
uniform vec3 u_el_metal_n[CUBE_ELEMENTS];
uniform vec3 u_el_metal_k[CUBE_ELEMENTS];
uniform int u_self;               // this element's index
uniform int u_max_depth;          // render.max_depth: the tracer absorbs at an element met after that many events
#endif
#if !defined(LENS)
uniform sampler2D u_surf_p;       // surface maps over the parameter domain (pvrr/impostor/surface_map.h), local frame:
uniform sampler2D u_surf_du;      // position, first derivatives and unit normal
uniform sampler2D u_surf_dv;
uniform sampler2D u_surf_n;
uniform vec2 u_sm;                // texture coordinate = (s, t) * u_sm.x + u_sm.y ((s, t): normalised parameters)
#endif
#if defined(LENS) || defined(LENS_IN_CUBES)
// A lens's maps: this element's (LENS), or those of the scene's one lens, which other elements' cubes show
// (LENS_IN_CUBES: followCubes refracts through it).
uniform sampler2D u_lens_front;   // refractor height maps (pvrr/impostor/lens_height_map.h): z, outward unit normal
uniform sampler2D u_lens_back;
uniform sampler2D u_lens_mask;    // 1 inside the outline, 0 outside
uniform vec4 u_hm;                // the maps' x0, y0, 1 / width, 1 / height (lens local, metres)
uniform vec2 u_hm_z;              // the back surface's lowest z and the front surface's highest z
uniform float u_hm_reach;         // the maps' diagonal: no straight path inside the glass is longer
uniform float u_far;              // render.far_distance_m: where a ray absorbed at the rim puts its seen point
uniform vec3 u_index;             // the glass's index at the R, G and B wavelengths (.y: the d line)
uniform int u_seen_channel;       // IMPOSTOR_CHANNELS 3: the channel whose ray gives the seen point
#endif
#if defined(LENS)
uniform int u_max_events;         // the events inside the glass the tracer follows: render.max_depth - 1
#endif
#if defined(LENS_IN_CUBES)
uniform int u_cube_lens;          // the lens's element index
uniform mat3 u_lens_to_local;     // world directions -> the lens's local frame (whose origin is its cube's)
#endif
#elif defined(MODE_PLAIN)
uniform bool u_dark;
#endif
#include "outputs.glsl"
#include "shading.glsl"

#if defined(MODE_IMPOSTOR)
// GL_LINEAR with clamp-to-edge, computed with float weights from four texelFetch: a GPU's filter weights have
// about 8 fractional bits, which would quantise the surfaces' heights and normals between samples to 1/256 of
// their difference (~4e-6 rad of normal on the concave mirror's map). No mipmaps, so fetching inside the
// searches' loops, whose exits differ between neighbouring fragments, is well defined.
vec4 bilinear(sampler2D t, vec2 st) {
  ivec2 size = textureSize(t, 0);
  vec2 x = st * vec2(size) - 0.5, f = floor(x), a = x - f;
  ivec2 i0 = clamp(ivec2(f), ivec2(0), size - 1), i1 = clamp(ivec2(f) + 1, ivec2(0), size - 1);
  return mix(mix(texelFetch(t, i0, 0), texelFetch(t, ivec2(i1.x, i0.y), 0), a.x),
             mix(texelFetch(t, ivec2(i0.x, i1.y), 0), texelFetch(t, i1, 0), a.x), a.y);
}

// The distance from the cube's origin to what it sees in direction dir (the sky's seen point lies u_far along
// its ray: a sure overshoot for every nearer point).
float envDistance(samplerCube seen, vec3 dir) { return length(texture(seen, dir).xyz); }

// Seeds 003, section 2.2: the point of the ray x + d R (x relative to the cube's origin, R unit, d >= 0) at the
// distance the impostor holds for its own direction. The first guesses assume a surface perpendicular to R at
// the distance seen along R, then a plane through the two samples; then false position between the last
// undershooting (in front of the surface) and overshooting parameters, 0 while there is none (the direction
// R itself, at infinity, stands in for a missing overshoot, as in the paper).
// falsePosition: that search from parameter dl, with the last undershooting (dun, ratio |l| / distance pun) and
// overshooting (dov, pov) parameters so far (0: none); r1 the distance the impostor holds along R.
vec3 falsePosition(samplerCube seen, vec3 x, vec3 R, float r1, float dl, float dun, float pun, float dov, float pov) {
  vec3 l = x + R * dl;
  for (int i = 0; i < IMPOSTOR_ITERATIONS; ++i) {
    float llp = length(l) / envDistance(seen, l);
    if (abs(1.0 - llp) < 1e-6) break;  // as close as float distances resolve
    float ddl;
    if (llp < 1.0) {  // undershooting
      dun = dl, pun = llp;
      ddl = dov == 0.0 ? r1 * (1.0 - llp) : (dl - dov) * (1.0 - llp) / (llp - pov);
    } else {          // overshooting
      dov = dl, pov = llp;
      ddl = dun == 0.0 ? r1 * (1.0 - llp) : (dl - dun) * (1.0 - llp) / (llp - pun);
    }
    dl = max(dl + ddl, 0.0);
    l = x + R * dl;
  }
  return dot(l, l) > 0.0 ? l : R;  // x at the cube's origin and d = 0: the direction itself
}
vec3 impostorHit(samplerCube seen, vec3 x, vec3 R) {
  float r1 = envDistance(seen, R);
  float dp = r1 - dot(x, R);
  vec3 p = x + R * dp;
  float ppp = length(p) / envDistance(seen, p);
  float dun = 0.0, dov = 0.0, pun = ppp, pov = ppp;
  if (ppp < 1.0) dun = dp; else dov = dp;
  float dl = max(dp + r1 * (1.0 - ppp), 0.0);
  return falsePosition(seen, x, R, r1, dl, dun, pun, dov, pov);
}

#if IMPOSTOR_LAYERS > 1
// Seeds 001's layered distance maps, for what an occluder near the element hides from the cube's origin (seeds
// 003, Fig. 6): the second layer holds the nearest surfaces beyond the first (depth peeling).
//
// Whether l, found by a search on the ray from x along R, lies on a surface of the layer: the search came within
// 1e-3 of the distance there, and it did not end where the ray passes behind a depth edge. There the layer's
// distance jumps (1.5 texels to either side, across the ray's sweep, the farther more than 1.5 x the nearer),
// the filtered distance blends the two surfaces, and the search ends between them, at a point on neither:
// more than 1.25 x the nearer's distance and less than 0.8 x the farther's.
bool onSurface(samplerCube seen, vec3 l, vec3 R) {
  float len = length(l), d = envDistance(seen, l);
  if (!(abs(len - d) <= 1e-3 * d)) return false;
  vec3 u = l / len, t = R - dot(R, u) * u;
  float tl = length(t);
  if (tl < 1e-4) return true;  // the ray runs along the origin's line of sight: it sweeps no edge
  t *= 3.0 / (float(textureSize(seen, 0).x) * tl);  // 1.5 texels at a face's centre (2 / size a texel)
  float d0 = envDistance(seen, u - t), d1 = envDistance(seen, u + t);
  float dn = min(d0, d1), df = max(d0, d1);
  return !(df > 1.5 * dn && len > 1.25 * dn && len < 0.8 * df);
}

// |p| / the layer's distance in p's direction: below 1 in front of the layer, above behind it.
float rayRatio(samplerCube seen, vec3 p) {
  float len = length(p);
  return len > 0.0 ? len / envDistance(seen, p) : 0.0;
}

// A crossing of a layer between the march's parameters d0 (ratio r0 < 1) and d1 (ratio r1 >= 1; at_end: the
// ray's end at infinity), refined by false position; whether it lies on the layer's surface.
bool layerCrossing(samplerCube seen, vec3 x, vec3 R, float d0, float r0, float d1, float r1, bool at_end,
                   out vec3 l) {
  float rR = envDistance(seen, R);
  float dl = at_end ? max(d0 + rR * (1.0 - r0), d0) : d0 + (d1 - d0) * (1.0 - r0) / (r1 - r0);
  l = falsePosition(seen, x, R, rR, dl, d0, r0, at_end ? 0.0 : d1, r1);
  return onSurface(seen, l, R);
}

// The first hit of the ray x + d R (x relative to the cube's origin, R unit) in the two layers; `layer`: which
// holds it. The first layer's search as above; where its result is not on a surface, seeds 001's linear search:
// LAYER_STEPS steps over both layers, uniform in the direction from the origin (from x's to R's: d = |x| t /
// (1 - t)), each bracket of an undershooting and an overshooting sample refined by false position and kept if
// on a surface, the nearer of the two layers' first. Nothing kept: the first layer's result. The march starts
// a quarter step out (t = 1 / (4 LAYER_STEPS)), so that no bracket starts at d = 0, which falsePosition
// reads as no undershoot yet.
const int LAYER_STEPS = 16;
vec3 layeredHit(samplerCube seen0, samplerCube seen1, vec3 x, vec3 R, out int layer) {
  layer = 0;
  vec3 l0 = impostorHit(seen0, x, R);
  if (onSurface(seen0, l0, R)) return l0;
#if !defined(LAYER_MARCH)
  discard;  // the second draw, LAYER_MARCH, shades this pixel (pvrr/gl/renderer.cpp)
  return l0;
#else
  float a = length(x), t0 = 0.25 / float(LAYER_STEPS), d_prev = a * t0 / (1.0 - t0);
  vec3 p0 = x + R * d_prev;
  vec2 r_prev = vec2(rayRatio(seen0, p0), rayRatio(seen1, p0));
  for (int i = 1; i <= LAYER_STEPS; ++i) {
    bool at_end = i == LAYER_STEPS;
    float t = float(i) / float(LAYER_STEPS), d = at_end ? 0.0 : a * t / (1.0 - t);
    vec3 p = x + R * d;
    vec2 r = at_end ? vec2(2.0) : vec2(rayRatio(seen0, p), rayRatio(seen1, p));
    vec3 l, best = l0;
    float d_best = -1.0;
    if (r_prev.x < 1.0 && r.x >= 1.0 && layerCrossing(seen0, x, R, d_prev, r_prev.x, d, r.x, at_end, l))
      best = l, d_best = dot(l - x, R);
    if (r_prev.y < 1.0 && r.y >= 1.0 && layerCrossing(seen1, x, R, d_prev, r_prev.y, d, r.y, at_end, l) &&
        (d_best < 0.0 || dot(l - x, R) < d_best)) {
      layer = 1;
      return l;
    }
    if (d_best >= 0.0) return best;
    d_prev = d;
    r_prev = r;
  }
  return l0;
#endif
}
#endif

#if !defined(CUBE_ELEMENTS)
// The element's own cubes: the colour and seen point (relative to the origin) where the ray x + d R meets them.
void envHit(vec3 x, vec3 R, out vec3 colour, out vec4 seen) {
#if IMPOSTOR_LAYERS > 1
  int layer;
  vec3 l = layeredHit(u_seen_cube, u_seen_cube1, x, R, layer);
  colour = layer == 1 ? texture(u_cube1, l).rgb : texture(u_cube, l).rgb;
  seen = layer == 1 ? texture(u_seen_cube1, l) : texture(u_seen_cube, l);
#else
  vec3 l = impostorHit(u_seen_cube, x, R);
  colour = texture(u_cube, l).rgb;
  seen = texture(u_seen_cube, l);
#endif
}
#endif

#if !defined(LENS)
// The normalised parameters of the surface point on the view ray from e with direction v (both local), from
// the fragment's interpolated ones: Gauss-Newton steps on the ray's distance from the map's point (the
// rasterised triangle lies within its sag of the surface, a few steps of its own size away), each at most a
// tenth of the domain, until the distance is below 1e-7 of the point's distance from e (float rounding) or
// the ray runs along the surface. The caller tests the distance left.
vec2 surfaceHit(vec2 uv, vec3 e, vec3 v) {
  for (int i = 0; i < 6; ++i) {
    vec2 st = uv * u_sm.x + u_sm.y;
    vec3 w = bilinear(u_surf_p, st).xyz - e;
    vec3 r = w - dot(w, v) * v;
    if (length(r) <= 1e-7 * length(w)) break;
    vec3 su = bilinear(u_surf_du, st).xyz, sv = bilinear(u_surf_dv, st).xyz;
    vec3 a = su - dot(su, v) * v, b = sv - dot(sv, v) * v;
    float aa = dot(a, a), ab = dot(a, b), bb = dot(b, b);
    // aa bb - ab^2 = ((su x sv) . v)^2 for vectors projected across v, computed without the cancellation.
    float c = dot(cross(su, sv), v), det = c * c;
    if (!(det > 1e-12 * aa * bb)) break;  // the ray runs along the surface
    vec2 g = vec2(dot(a, r), dot(b, r));
    vec2 delta = -vec2(bb * g.x - ab * g.y, aa * g.y - ab * g.x) / det;
    float len = length(delta);
    if (len > 0.1) delta *= 0.1 / len;
    uv = clamp(uv + delta, vec2(0.0), vec2(1.0));
  }
  return uv;
}
#endif
#if defined(LENS) || defined(LENS_IN_CUBES)
// Exact unpolarised dielectric Fresnel reflectance from index n1 into n2 (pvrr/optics/optics.cpp fresnelDielectric).
float fresnelDielectric(float cos_i, float n1, float n2) {
  float eta = n1 / n2, s2t = eta * eta * (1.0 - cos_i * cos_i);
  if (s2t >= 1.0) return 1.0;
  float cos_t = sqrt(1.0 - s2t);
  float rs = (n1 * cos_i - n2 * cos_t) / (n1 * cos_i + n2 * cos_t);
  float rp = (n2 * cos_i - n1 * cos_t) / (n2 * cos_i + n1 * cos_t);
  return 0.5 * (rs * rs + rp * rp);
}
vec4 lensTexel(bool back, vec2 xy) {
  vec2 st = (xy - u_hm.xy) * u_hm.zw;
  return back ? bilinear(u_lens_back, st) : bilinear(u_lens_front, st);
}
bool inOutline(vec2 xy) { return bilinear(u_lens_mask, (xy - u_hm.xy) * u_hm.zw).r >= 0.5; }
// The heights of q above the back surface and below the front one: both positive inside the glass.
vec2 insideHeights(vec3 q) { return vec2(q.z - lensTexel(true, q.xy).x, lensTexel(false, q.xy).x - q.z); }

// The ray p + t d, leaving a point p of the glass's surface into the glass: where it meets a surface again,
// and which (back or front, the nearer crossing, as the tracer takes the nearer of its two surfaces). It steps
// out, doubling, to where it leaves the slab between the surfaces' extreme heights or the maps' reach; then
// false position with the Illinois halving on the crossed surface's filtered height, between the last step
// inside and the first outside (past the root at p itself, see below). The first step covers half the
// height of the surface ahead (in d.z's direction) above or below p, or 1 um when p lies on that surface
// (after a reflection off it). -1: no crossing.
float glassExit(vec3 p, vec3 d, out bool back) {
  float t_max = u_hm_reach;
  if (d.z < 0.0) t_max = min(t_max, (u_hm_z.x - p.z) / d.z);
  if (d.z > 0.0) t_max = min(t_max, (u_hm_z.y - p.z) / d.z);
  t_max = max(t_max, 1e-6);
  vec2 h0 = insideHeights(p);
  float ahead = d.z < 0.0 ? h0.x : h0.y;
  float t0 = 0.0, t1 = -1.0, t = min(max(1e-6, 0.5 * ahead / max(abs(d.z), 1e-3)), t_max);
  vec2 h1 = vec2(0.0);
  for (int k = 0; k < 32; ++k) {
    vec2 h = insideHeights(p + t * d);
    if (min(h.x, h.y) <= 0.0) {
      t1 = t, h1 = h;
      break;
    }
    t0 = t;
    if (t >= t_max) break;
    t = min(2.0 * t, t_max);
  }
  back = h1.x <= h1.y;
  if (t1 < 0.0) return -1.0;
  if (t0 > 0.0) h0 = insideHeights(p + t0 * d);
  float g0 = back ? h0.x : h0.y;
  // Outside already at the first step, from a point on the crossed surface itself (g0 below 1e-8 m: p's own
  // height, which the searches leave within ~1e-9 m of the surface; a reflection off it at a grazing angle):
  // halve the step until the ray is inside, so that false position does not return the root at p.
  for (int k = 0; k < 16 && t0 == 0.0 && g0 < 1e-8; ++k) {
    float th = 0.5 * t1;
    vec2 hh = insideHeights(p + th * d);
    if (min(hh.x, hh.y) > 0.0) {
      t0 = th, g0 = back ? hh.x : hh.y;
    } else {
      t1 = th, h1 = hh;
      back = h1.x <= h1.y;
      g0 = back ? h0.x : h0.y;
    }
  }
  if (t0 == 0.0 && g0 < 1e-8) return t1;  // outside within nanometres of p: that is the crossing
  float g1 = back ? h1.x : h1.y;
  g0 = max(g0, 0.0);
  if (g0 - g1 <= 0.0) return t1;
  int side = 0;
  for (int i = 0; i < 16; ++i) {
    t = (t0 * g1 - t1 * g0) / (g1 - g0);
    vec3 q = p + t * d;
    float zs = lensTexel(back, q.xy).x, g = back ? q.z - zs : zs - q.z;  // the crossed surface's only
    if (abs(g) < 1e-8) break;  // 10 nm: float heights at lens scale resolve ~1e-9 m, no finer
    if (g > 0.0) {
      t0 = t, g0 = g;
      if (side == 1) g1 *= 0.5;
      side = 1;
    } else {
      t1 = t, g1 = g;
      if (side == -1) g0 *= 0.5;
      side = -1;
    }
  }
  return t;
}

// Where the view ray through the fragment at x (lens local, direction v) meets the lens: the front surface
// near x (the rasterised triangle lies within its sag of the surface), or, for a lens seen from behind
// (back), the back surface between the eye and x. Secant steps on the ray's height above that surface.
vec3 entryPoint(vec3 x, vec3 v, bool back) {
  if (abs(v.z) < 1e-4) return x;
  float ta = 0.0, ga = x.z - lensTexel(back, x.xy).x;
  float tb = -ga / v.z;
  vec3 q = x + tb * v;
  float gb = q.z - lensTexel(back, q.xy).x;
  for (int i = 0; i < 6 && abs(gb) > 1e-8 && gb != ga; ++i) {  // to 10 nm, as glassExit
    float tc = tb - gb * (tb - ta) / (gb - ga);
    ta = tb, ga = gb, tb = tc;
    q = x + tb * v;
    gb = q.z - lensTexel(back, q.xy).x;
  }
  return x + tb * v;
}

// One wavelength's path through the lens (local frame) from the entry point x, where the view direction v
// meets the surface with outward normal n. It refracts in, then follows the events inside the glass as the
// tracer does up to its depth limit (max_events; render.max_depth is at most 64): each is an exit
// (refraction, exact Fresnel) or a total internal reflection. Returns the exit point and sets the exit
// direction, the transmittance and the tracer's events spent on the way (entry, inside, exit);
// transmittance 0: absorbed, at the returned point (the depth limit) or, with `rim`, where the ray left the
// outline (the tracer's lens has no rim surface: its seen point lies u_far along `dir`, the ray inside).
vec3 throughLens(vec3 x, vec3 v, vec3 n, float eta, int max_events, out vec3 dir, out float transmittance,
                 out bool rim, out int spent) {
  float cos_i = -dot(v, n);
  vec3 d = refract(v, n, 1.0 / eta);
  transmittance = 1.0 - fresnelDielectric(cos_i, 1.0, eta);
  rim = false;
  vec3 p = x;
  for (int event = 0; event < 64; ++event) {
    bool back;
    float t = glassExit(p, d, back);
    if (t < 0.0 || !inOutline((p + t * d).xy)) {
      rim = true;
      break;
    }
    p += t * d;
    if (event >= max_events) break;  // absorbed at p
    vec3 nout = normalize(lensTexel(back, p.xy).yzw);
    float c = dot(d, nout);
    if (c <= 0.0) break;  // met from outside: a path the maps cannot represent
    vec3 out_dir = refract(d, -nout, eta);
    if (out_dir != vec3(0.0)) {
      dir = out_dir;
      transmittance *= 1.0 - fresnelDielectric(c, eta, 1.0);
      spent = event + 2;  // the entry, the events inside, the exit
      return p;
    }
    d = reflect(d, nout);  // total internal reflection
  }
  dir = d;
  transmittance = 0.0;
  spent = 0;
  return p;
}
#endif
#endif

// Exact unpolarised conductor Fresnel reflectance, outside index 1 (pvrr/optics/optics.cpp fresnelConductor).
float fresnelConductor(float cos_i, float n, float k) {
  float c2 = cos_i * cos_i, s2 = 1.0 - c2;
  float a = n * n - k * k - s2;
  float b = sqrt(a * a + 4.0 * n * n * k * k);
  float a2b2 = b;
  float A = sqrt(max(0.0, 0.5 * (a2b2 + a)));
  float rs = (a2b2 + c2 - 2.0 * A * cos_i) / (a2b2 + c2 + 2.0 * A * cos_i);
  float rp = rs * (c2 * a2b2 + s2 * s2 - 2.0 * A * cos_i * s2) / (c2 * a2b2 + s2 * s2 + 2.0 * A * cos_i * s2);
  return 0.5 * (rs + rp);
}

#if defined(CUBE_ELEMENTS)
// Seeds 000 and 001's multi-bounce loop over distance-normal impostors. The ray from x (relative to the camera
// origin) along R, with `depth` of the tracer's events spent, is searched in the cubes of element `cur`; where
// it meets another mirror drawn there, it reflects at the found point with that mirror's normal and material
// (exact Fresnel) and goes on in that mirror's cubes, as the tracer does: absorbed at an element met after
// u_max_depth events, dark at a mirror's back. LENS_IN_CUBES: where it meets the scene's lens, it enters the
// lens's height maps where the ray meets the surface (a ray past its outline goes on in the lens's cubes,
// which do not show the lens), refracts through the glass (throughLens, with the index of `channel`: 0-2 R,
// G, B) and goes on from the exit in the lens's cubes. Returns the colour; `seen`: the last point, relative
// to the camera origin (w 0: escaping); `refracted`: whether the path met the lens (else no channel matters).
#if IMPOSTOR_LAYERS > 1
#define CUBE_LOOKUP(k)                                                                                              \
  if (cur == k) {                                                                                                  \
    centre = u_cube_centre[k];                                                                                     \
    int layer;                                                                                                     \
    l = layeredHit(u_seen_cubes[k], u_seen_cubes1[k], x - centre, R, layer);                                       \
    c = layer == 1 ? texture(u_cubes1[k], l).rgb : texture(u_cubes[k], l).rgb;                                     \
    s = layer == 1 ? texture(u_seen_cubes1[k], l) : texture(u_seen_cubes[k], l);                                   \
    nid = layer == 1 ? texture(u_normal_cubes1[k], l) : texture(u_normal_cubes[k], l);                             \
  }
#else
#define CUBE_LOOKUP(k)                                                                                              \
  if (cur == k) {                                                                                                  \
    centre = u_cube_centre[k];                                                                                     \
    l = impostorHit(u_seen_cubes[k], x - centre, R);                                                               \
    c = texture(u_cubes[k], l).rgb;                                                                                \
    s = texture(u_seen_cubes[k], l);                                                                               \
    nid = texture(u_normal_cubes[k], l);                                                                           \
  }
#endif
vec3 followCubes(int cur, vec3 x, vec3 R, int depth, int channel, out vec4 seen, out bool refracted) {
  vec3 throughput = vec3(1.0);
  refracted = false;
  seen = vec4(x, 1.0);  // 64 passes past the lens's outline without an event: no seen point of its own
  for (int bounce = 0; bounce < 64; ++bounce) {
    vec3 centre = vec3(0.0), l = R, c = vec3(0.0);
    vec4 s = vec4(0.0), nid = vec4(0.0);
    CUBE_LOOKUP(0)
    CUBE_LOOKUP(1)
#if CUBE_ELEMENTS > 2
    CUBE_LOOKUP(2)
#endif
#if CUBE_ELEMENTS > 3
    CUBE_LOOKUP(3)
#endif
    // The normal and index are filtered like the rest, and the texels of the environment hold zero: where an
    // element's texels blend with those of what lies behind it, |normal| is the element's weight, the larger
    // weight decides, and the index divided by it is the element's.
    float weight = length(nid.xyz);
    int hit = weight >= 0.5 ? int(floor(nid.w / weight + 0.5)) - 1 : -1;
    if (hit < 0 || hit >= CUBE_ELEMENTS || hit == cur) {
      seen = vec4(s.xyz + centre, s.w);
      return throughput * c;
    }
    vec3 p = centre + l, n = nid.xyz / weight;
#if defined(LENS_IN_CUBES)
    if (hit == u_cube_lens) {
      // The lens's frame: its origin is its cube's. The cube holds the front mesh's outward normal: a ray
      // along it meets the lens from behind (as the second pass decides).
      vec3 lens_centre = u_cube_centre[hit];
      vec3 xl = u_lens_to_local * (p - lens_centre), vl = u_lens_to_local * R;
      bool from_back = dot(R, n) >= 0.0;
      vec3 entry = entryPoint(xl, vl, from_back);
      // Past the outline (the cube's texels blend the lens's rim with what lies behind it): the ray misses
      // the lens and goes on, unchanged, in its cubes.
      if (!inOutline(entry.xy)) {
        x = p;
        cur = hit;
        continue;
      }
      seen = vec4(lens_centre + entry * u_lens_to_local, 1.0);
      if (depth >= u_max_depth) return vec3(0.0);  // the tracer's depth limit: absorbed at the surface
      vec3 n_in = normalize(lensTexel(from_back, entry.xy).yzw);
      if (dot(vl, n_in) >= 0.0) return vec3(0.0);  // along the surface: nothing to refract
      vec3 dir;
      float tr;
      bool rim;
      int spent;
      vec3 q = throughLens(entry, vl, n_in, u_index[channel], u_max_depth - 1 - depth, dir, tr, rim, spent);
      refracted = true;
      if (tr <= 0.0) {  // absorbed inside the glass, or at its rim
        seen = rim ? vec4(lens_centre + (q + u_far * dir) * u_lens_to_local, 0.0)
                   : vec4(lens_centre + q * u_lens_to_local, 1.0);
        return vec3(0.0);
      }
      throughput *= tr;
      depth += spent;
      x = lens_centre + q * u_lens_to_local;
      R = dir * u_lens_to_local;
      cur = hit;
      continue;
    }
#endif
    seen = vec4(p, 1.0);
    if (depth >= u_max_depth) return vec3(0.0);  // the tracer's depth limit: absorbed
    float cos_i = -dot(R, n);
    if (cos_i <= 0.0) return throughput * 0.05 * shadeDiffuse(vec3(1.0), p, -n);  // the mirror's back
    throughput *= u_el_metal[hit] ? vec3(fresnelConductor(cos_i, u_el_metal_n[hit].r, u_el_metal_k[hit].r),
                                         fresnelConductor(cos_i, u_el_metal_n[hit].g, u_el_metal_k[hit].g),
                                         fresnelConductor(cos_i, u_el_metal_n[hit].b, u_el_metal_k[hit].b))
                                  : u_el_reflectance[hit];
    R = reflect(R, n);
    x = p;
    cur = hit;
    ++depth;
  }
  return vec3(0.0);
}
#endif

void main() {
#if defined(LAYER_PROBE) && defined(LENS)
  return;  // the probe counts the pixels the first draw left (pvrr/gl/renderer.cpp)
#endif
  vec3 n = normalize(v_normal);
  vec3 view = normalize(v_pos - u_view_origin);
  float cos_i = -dot(view, n);
  o_surface = vec4(v_pos, u_element_id);
#if defined(CUBE_GEOMETRY) && defined(LENS)
  // A lens in another element's cube: where the ray from the cube's origin meets its mesh, its outward normal
  // (the texel's weight, and the side the search enters, which then refracts in the lens's own height maps)
  // and its index.
  peel(v_pos);
  o_color = vec4(0.0);
  o_seen = vec4(v_pos, 1.0);
  o_surface = vec4(n, u_element_id);
#else
#if defined(MODE_IMPOSTOR) && !defined(LENS)
  // The exact surface point on this fragment's view ray (relative to the camera origin) and the exact normal
  // there, from the surface maps, in place of the triangle's point and the interpolated vertex normals.
  // A view ray that misses the surface within its outline (at the silhouette, where the triangles reach past
  // the surface, or past the trimmed outline) sees past the mirror, as in the tracer: the fragment is dropped
  // and the environment drawn after the elements fills the pixel. So is one whose search did not come within
  // 1e-5 of its distance (counted by the tests as holes: none in the shipped mirrors).
  vec3 e = u_to_local * (u_view_origin - u_seen_offset), vl = u_to_local * view;
  vec2 st = surfaceHit(v_st1.xy, e, vl) * u_sm.x + u_sm.y;
  vec4 sp = bilinear(u_surf_p, st);  // w: 1 inside the outline
  vec3 w = sp.xyz - e;
  if (sp.w < 0.5 || length(w - dot(w, vl) * vl) > 1e-5 * length(w)) discard;
#if defined(LAYER_PROBE)
  return;  // the probe counts the pixels the first draw left (pvrr/gl/renderer.cpp), not the mirror's misses
#endif
  vec3 pos = u_seen_offset + sp.xyz * u_to_local;
  n = normalize(bilinear(u_surf_n, st).xyz * u_to_local);
  view = normalize(pos - u_view_origin);
  cos_i = -dot(view, n);
  o_surface = vec4(pos, u_element_id);
#if defined(CUBE_GEOMETRY)
  peel(pos);
  o_color = vec4(0.0);
  o_seen = vec4(pos, 1.0);
  o_surface = vec4(n, u_element_id);
  return;
#endif
#endif
#if defined(MODE_PLAIN)
  vec3 nf = cos_i < 0.0 ? -n : n;
  o_color = u_dark ? vec4(0.0, 0.0, 0.0, 1.0) : vec4(shadeDiffuse(vec3(0.6), v_pos, nf), 1.0);
  o_seen = vec4(v_pos, 1.0);
#else
  vec3 weight = vec3(1.0);
#if !defined(LENS)
  if (cos_i <= 0.0) {  // the mirror's back: dark (tracer: kMirrorBackAlbedo), once, not in each additive draw
    o_color = u_additive ? vec4(0.0) : vec4(0.05 * shadeDiffuse(vec3(1.0), v_pos, -n), 1.0);
    o_seen = vec4(v_pos, 1.0);
    return;
  }
  weight = u_reflectance;
  if (u_metal)
    weight = vec3(fresnelConductor(cos_i, u_metal_n.r, u_metal_k.r), fresnelConductor(cos_i, u_metal_n.g, u_metal_k.g),
                  fresnelConductor(cos_i, u_metal_n.b, u_metal_k.b));
#endif
#if defined(MODE_IMPOSTOR)
#if defined(LENS)
  // In the lens's frame (its origin is the cube's). Seen from behind (the front mesh faces away), the view
  // ray enters through the back surface, between the eye and this fragment.
  vec3 x = u_to_local * (v_pos - u_seen_offset), v = u_to_local * view;
  bool from_back = cos_i <= 0.0;
  vec3 entry = entryPoint(x, v, from_back);
  vec3 c = vec3(0.0);
  vec4 seen = vec4(entry * u_to_local, 1.0);
  if (inOutline(entry.xy)) {
    vec3 n_in = normalize(lensTexel(from_back, entry.xy).yzw);
    if (dot(v, n_in) < 0.0) {
      for (int ch = 0; ch < IMPOSTOR_CHANNELS; ++ch) {
        int k = IMPOSTOR_CHANNELS == 3 ? ch : 1;
        vec3 dir;
        float tr;
        bool rim;
        int spent;
        vec3 q = throughLens(entry, v, n_in, u_index[k], u_max_events, dir, tr, rim, spent);
        bool seen_here = ch == (IMPOSTOR_CHANNELS == 3 ? u_seen_channel : 0);
        if (tr <= 0.0) {  // absorbed, as in the tracer: dark
          if (seen_here) seen = rim ? vec4((q + u_far * dir) * u_to_local, 0.0) : vec4(q * u_to_local, 1.0);
          continue;
        }
        // Back to world axes: the local frame's origin is the cube's.
#if defined(CUBE_ELEMENTS)
        vec4 s;
        bool again;  // met the lens once more, through a mirror: with this channel's index already
        vec3 rgb = tr * followCubes(u_self, q * u_to_local + u_seen_offset, dir * u_to_local, spent, k, s, again);
        if (seen_here) seen = vec4(s.xyz - u_seen_offset, s.w);
#else
        vec3 rgb;
        vec4 s;
        envHit(q * u_to_local, dir * u_to_local, rgb, s);
        rgb *= tr;
        if (seen_here) seen = s;
#endif
        if (IMPOSTOR_CHANNELS == 3) c[ch] = rgb[ch];
        else c = rgb;
      }
    }
  }
#else
#if defined(CUBE_ELEMENTS)
  vec4 seen;
  bool refracted;
  vec3 c = followCubes(u_self, pos, reflect(view, n), 1, 1, seen, refracted);
#if defined(LENS_IN_CUBES) && IMPOSTOR_CHANNELS == 3
  // The scene's lens disperses: a path that met it is followed again for R and B with their own indices
  // (paths that did not are the same in every channel).
  if (refracted) {
    for (int ch = 0; ch < 3; ch += 2) {
      vec4 s;
      vec3 rgb = followCubes(u_self, pos, reflect(view, n), 1, ch, s, refracted);
      c[ch] = rgb[ch];
      if (ch == u_seen_channel) seen = s;
    }
  }
#endif
  seen.xyz -= u_seen_offset;
#else
  vec3 c;
  vec4 seen;
  envHit(pos - u_seen_offset, reflect(view, n), c, seen);
#endif
#endif
#elif defined(MODE_PVRR)
#if CHANNELS == 3 && defined(RGB_CHANNELS)
  vec3 c = vec3(v_w0.r * texture(u_map, mapST(v_st0)).r, v_w1.g * texture(u_map_g, mapST(v_st1)).r,
                v_w2.b * texture(u_map_b, mapST(v_st2)).r);
#else
  vec3 c = v_w0 * texture(u_map, mapST(v_st0)).rgb;
#if CHANNELS == 3
  c += v_w1 * texture(u_map, mapST(v_st1)).rgb + v_w2 * texture(u_map, mapST(v_st2)).rgb;
#endif
#endif
  c += v_tir.rgb;  // zero but near a totally reflected vertex: what the tracer shows there, interpolated
#if defined(NO_SEEN_POINTS)
  vec4 seen = vec4(0.0);
#else
  vec4 seen = texture(u_seen_map, mapST(v_st_seen));
  // Nearer a totally reflected vertex than the others: its traced seen point (relative to this camera).
  if (v_tir.a > 0.5) seen = vec4(v_tir_seen / v_tir.a - u_seen_offset, 1.0);
#endif
#else
#if defined(LENS)
  vec3 dir = normalize(v_st0);  // the exact exit direction at the vertices, interpolated
  weight = v_w0;
#else
  vec3 dir = reflect(view, n);
#endif
  vec3 c = texture(u_cube, dir).rgb;
#if defined(NO_SEEN_POINTS)
  vec4 seen = vec4(0.0);
#else
  vec4 seen = texture(u_seen_cube, dir);
#endif
#endif
  o_color = vec4(weight * c, 1.0);
  o_seen = vec4(seen.xyz + u_seen_offset, seen.w);
#endif
#endif  // CUBE_GEOMETRY && LENS
}
