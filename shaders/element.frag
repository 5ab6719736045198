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
//                traced per fragment in the lens's refractor height maps (pvrr/lens_height_map.h).
//                IMPOSTOR_ITERATIONS: the search's false-position steps; IMPOSTOR_CHANNELS 3: a lens's R, G
//                and B each refracted with its own index (u_index), else the middle one only.
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
#if defined(LENS)
uniform sampler2D u_lens_front;   // refractor height maps (pvrr/lens_height_map.h): z, outward unit normal
uniform sampler2D u_lens_back;
uniform vec4 u_hm;                // the maps' x0, y0, 1 / width, 1 / height (lens local, metres)
uniform vec2 u_hm_z;              // the back surface's lowest z and the front surface's highest z
uniform mat3 u_to_local;          // world directions -> the lens's local frame (whose origin is the cube's)
uniform vec3 u_index;             // the glass's index at the R, G and B wavelengths (.y: the d line)
uniform int u_seen_channel;       // IMPOSTOR_CHANNELS 3: the channel whose ray gives the seen point
#endif
#elif defined(MODE_PLAIN)
uniform bool u_dark;
#endif
#include "outputs.glsl"
#include "shading.glsl"

#if defined(MODE_IMPOSTOR)
// The distance from the cube's origin to what it sees in direction dir (the sky's seen point lies u_far along
// its ray: a sure overshoot for every nearer point).
float envDistance(vec3 dir) { return length(texture(u_seen_cube, dir).xyz); }

// Seeds 003, section 2.2: the point of the ray x + d R (x relative to the cube's origin, R unit, d >= 0) at the
// distance the impostor holds for its own direction. The first guesses assume a surface perpendicular to R at
// the distance seen along R, then a plane through the two samples; then false position between the last
// undershooting (in front of the surface) and overshooting parameters, 0 while there is none (the direction
// R itself, at infinity, stands in for a missing overshoot, as in the paper).
vec3 impostorHit(vec3 x, vec3 R) {
  float r1 = envDistance(R);
  float dp = r1 - dot(x, R);
  vec3 p = x + R * dp;
  float ppp = length(p) / envDistance(p);
  float dun = 0.0, dov = 0.0, pun = ppp, pov = ppp;
  if (ppp < 1.0) dun = dp; else dov = dp;
  float dl = max(dp + r1 * (1.0 - ppp), 0.0);
  vec3 l = x + R * dl;
  for (int i = 0; i < IMPOSTOR_ITERATIONS; ++i) {
    float llp = length(l) / envDistance(l);
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
  return l;
}

#if defined(LENS)
// Exact unpolarised dielectric Fresnel reflectance from index n1 into n2 (pvrr/optics.cpp fresnelDielectric).
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
  return back ? texture(u_lens_back, st) : texture(u_lens_front, st);
}
// The ray p + t d inside the glass (lens local) to the surface ahead: the back when d.z < 0, else the front.
// h(t), the ray's height inside that surface, is positive at t = 0 and not positive at t1, where the ray
// passes the surface's extreme z: false position with the Illinois halving, on the bilinearly filtered
// heights. on_surface: p lies on that same surface (the ray was just reflected off it), where h(0) = 0 is a
// root the search must pass: it first steps out geometrically (t1 / 256, t1 / 128, ... t1) to the first
// point beyond the surface, and searches between it and the step before.
float glassExit(vec3 p, vec3 d, bool back, bool on_surface) {
  float s = back ? 1.0 : -1.0;
  float t0 = 0.0, t1 = ((back ? u_hm_z.x : u_hm_z.y) - p.z) / d.z;
  float h0 = s * (p.z - lensTexel(back, p.xy).x);
  vec3 q1 = p + t1 * d;
  float h1 = s * (q1.z - lensTexel(back, q1.xy).x);
  if (on_surface) {
    float t_end = t1;
    for (int k = 8; k >= 0; --k) {
      float t = t_end * exp2(-float(k));
      vec3 q = p + t * d;
      float h = s * (q.z - lensTexel(back, q.xy).x);
      if (h <= 0.0) {
        t1 = t, h1 = h;
        break;
      }
      t0 = t, h0 = h;
    }
  }
  h0 = max(h0, 0.0);
  h1 = min(h1, 0.0);
  if (h0 - h1 <= 0.0) return t0;
  float t = t1;
  int side = 0;
  for (int i = 0; i < 16; ++i) {
    t = (t0 * h1 - t1 * h0) / (h1 - h0);
    vec3 q = p + t * d;
    float h = s * (q.z - lensTexel(back, q.xy).x);
    if (abs(h) < 1e-9) break;  // a nanometre
    if (h > 0.0) {
      t0 = t, h0 = h;
      if (side == 1) h1 *= 0.5;
      side = 1;
    } else {
      t1 = t, h1 = h;
      if (side == -1) h0 *= 0.5;
      side = -1;
    }
  }
  return t;
}
// One wavelength's path through the lens from the front-surface point x (local) with the view direction v
// and front normal n (local, facing the viewer): up to three internal reflections, as the tracer follows
// them. Returns the exit point and direction (local) and the Fresnel transmittance (0 if the ray stays in).
vec3 throughLens(vec3 x, vec3 v, vec3 n, float eta, out vec3 dir, out float transmittance) {
  float cos_i = -dot(v, n);
  vec3 d = refract(v, n, 1.0 / eta);
  transmittance = 1.0 - fresnelDielectric(cos_i, 1.0, eta);
  vec3 p = x;
  bool on_back = false, on_front = true;  // the surface p lies on
  for (int bounce = 0; bounce < 4; ++bounce) {
    if (abs(d.z) < 1e-6) break;  // along the lens plane: out through the rim, which the lens has not
    bool back = d.z < 0.0;
    p += glassExit(p, d, back, back ? on_back : on_front) * d;
    on_back = back;
    on_front = !back;
    vec3 nout = normalize(lensTexel(back, p.xy).yzw);
    float c = dot(d, nout);
    vec3 out_dir = refract(d, -nout, eta);
    if (c > 0.0 && out_dir != vec3(0.0)) {
      dir = out_dir;
      transmittance *= 1.0 - fresnelDielectric(c, eta, 1.0);
      return p;
    }
    d = reflect(d, nout);  // total internal reflection
  }
  dir = d;
  transmittance = 0.0;
  return p;
}
#endif
#endif

// Exact unpolarised conductor Fresnel reflectance, outside index 1 (pvrr/optics.cpp fresnelConductor).
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

void main() {
  vec3 n = normalize(v_normal);
  vec3 view = normalize(v_pos - u_view_origin);
  float cos_i = -dot(view, n);
  o_surface = vec4(v_pos, u_element_id);
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
  vec3 c = vec3(0.0);
  vec4 seen = vec4(v_pos - u_seen_offset, 1.0);  // a ray that stays in the glass: the surface, dark
  if (cos_i > 0.0) {
    vec3 x = u_to_local * (v_pos - u_seen_offset), v = u_to_local * view, nl = u_to_local * n;
    for (int ch = 0; ch < IMPOSTOR_CHANNELS; ++ch) {
      int k = IMPOSTOR_CHANNELS == 3 ? ch : 1;
      vec3 dir;
      float tr;
      vec3 q = throughLens(x, v, nl, u_index[k], dir, tr);
      if (tr <= 0.0) continue;
      // Back to world axes: the local frame's origin is the cube's.
      vec3 l = impostorHit(q * u_to_local, dir * u_to_local);
      vec3 rgb = tr * texture(u_cube, l).rgb;
      if (IMPOSTOR_CHANNELS == 3) c[ch] = rgb[ch];
      else c = rgb;
      if (ch == (IMPOSTOR_CHANNELS == 3 ? u_seen_channel : 0)) seen = texture(u_seen_cube, l);
    }
  }
#else
  vec3 l = impostorHit(v_pos - u_seen_offset, reflect(view, n));
  vec3 c = texture(u_cube, l).rgb;
  vec4 seen = texture(u_seen_cube, l);
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
}
