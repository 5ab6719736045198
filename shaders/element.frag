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
#elif defined(MODE_PLAIN)
uniform bool u_dark;
#endif
#include "outputs.glsl"
#include "shading.glsl"

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
#if defined(MODE_PVRR)
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
