#version 330 core
// Optical elements in pvrr mode: the warped first-pass map (paper 3.4). Variants by prepended defines:
//   CHANNELS 1   one texture-coordinate set; CHANNELS 3: three sets (RGB dispersion, or three samples of a
//                spectral set), colour = sum_i w_i * map(st_i).
//                RGB_CHANNELS (with CHANNELS 3): the sets are the R, G and B channels, whose weights are zero
//                but in their own component, and the map is three R32F planes (shaders/outputs.glsl, PLANES):
//                colour = (w_0.r R(st_0), w_1.g G(st_1), w_2.b B(st_2)), the same sum with two thirds of the
//                weights left uninterpolated and one float per texel read.
//                More than three channels: one additive draw per set of three (pvrr/gl/pvrr_pass.cpp).
//   LENS         the element is a lens (transmission) rather than a mirror (reflection)
//   NO_SEEN_POINTS  colour only: the seen-point maps are not read (RendererOptions::seen_points off)
//   REFINE n     fragments that search their exact ray in the map, n secant steps (render.refine;
//                pvrr_refine.glsl): a mirror's reflected ray (CHANNELS 1), or a lens's exit ray per channel (LENS)
//   REFINE_P2    (a refined mirror's triangles that need no search; CHANNELS 1, without REFINE) the texture
//                coordinate from the triangle's quadratic interpolant through its exact rays (pvrr_refine.glsl)
#include "element_inputs.glsl"
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
#include "outputs.glsl"
#include "shading.glsl"
#include "optics.glsl"
#include "lens_march.glsl"
#include "pvrr_refine.glsl"

void main() {
#if defined(REFINE) && !defined(LENS)
  refineDerivatives();
#endif
  vec3 n = normalize(v_normal);
  vec3 view = normalize(v_pos - u_view_origin);
  float cos_i = -dot(view, n);
  o_surface = vec4(v_pos, u_element_id);
  vec3 weight = vec3(1.0);
#if !defined(LENS)
  if (cos_i <= 0.0) {  // the mirror's back: dark (as the tracer), once, not in each additive draw
    o_color = u_additive ? vec4(0.0) : vec4(MIRROR_BACK_ALBEDO * shadeDiffuse(vec3(1.0), v_pos, -n), 1.0);
    o_seen = vec4(v_pos, 1.0);
    return;
  }
  weight = u_reflectance;
  if (u_metal)
    weight = vec3(fresnelConductor(cos_i, u_metal_n.r, u_metal_k.r), fresnelConductor(cos_i, u_metal_n.g, u_metal_k.g),
                  fresnelConductor(cos_i, u_metal_n.b, u_metal_k.b));
#endif
#if defined(REFINE) && defined(LENS)
  // Each channel's exact exit ray searched in the map (pvrr_refine.glsl); the seen point follows u_seen_channel's.
  refineLensEntry(view);
  vec2 st0 = refinedLensST(0, mapST(v_st0));
#if CHANNELS == 3
  vec2 st1 = refinedLensST(1, mapST(v_st1)), st2 = refinedLensST(2, mapST(v_st2));
  vec2 st_seen = u_seen_channel == 0 ? st0 : u_seen_channel == 1 ? st1 : st2;
#if defined(RGB_CHANNELS)
  vec3 c = vec3(v_w0.r * texture(u_map, st0).r, v_w1.g * texture(u_map_g, st1).r, v_w2.b * texture(u_map_b, st2).r);
#else
  vec3 c = v_w0 * texture(u_map, st0).rgb + v_w1 * texture(u_map, st1).rgb + v_w2 * texture(u_map, st2).rgb;
#endif
#else
  vec2 st_seen = st0;
  vec3 c = v_w0 * texture(u_map, st0).rgb;
#endif
  refineLensCount();
#elif CHANNELS == 3 && defined(RGB_CHANNELS)
  vec3 c = vec3(v_w0.r * texture(u_map, mapST(v_st0)).r, v_w1.g * texture(u_map_g, mapST(v_st1)).r,
                v_w2.b * texture(u_map_b, mapST(v_st2)).r);
#else
#if defined(REFINE)
  vec2 st0 = refinedST(view, mapST(v_st0));  // the seen channel's too: a mirror has one
#elif defined(REFINE_P2)
  vec2 st0 = quadraticST();
#else
  vec2 st0 = mapST(v_st0);
#endif
  vec3 c = v_w0 * texture(u_map, st0).rgb;
#if CHANNELS == 3
  c += v_w1 * texture(u_map, mapST(v_st1)).rgb + v_w2 * texture(u_map, mapST(v_st2)).rgb;
#endif
#endif
#if !defined(REFINE_P2)  // the quadratic program's triangles have no traced vertex: v_tir is zero there
  c += v_tir.rgb;  // zero but near a totally reflected vertex: what the tracer shows there, interpolated
#endif
#if defined(NO_SEEN_POINTS)
  vec4 seen = vec4(0.0);
#else
#if defined(REFINE) && defined(LENS)
  // Where the seen channel's search succeeded on a surface (not the sky), its ray point there: it lies on the
  // map's depth surface within the search's tolerance, where the seen map's bilinear sample errs between texels
  // (positions are not affine across a perspective image: up to ~0.4' in the burning lens's 130-150 deg maps).
  vec4 seen = texture(u_seen_map, st_seen);
  if (refine_seen_ok && seen.w > 0.999) seen.xyz = refine_seen;
#elif defined(REFINE) || defined(REFINE_P2)
  vec4 seen = texture(u_seen_map, st0);
#else
  vec4 seen = texture(u_seen_map, mapST(v_st_seen));
#endif
  // Nearer a totally reflected vertex than the others: its traced seen point (relative to this camera).
#if !defined(REFINE_P2)
  if (v_tir.a > 0.5) seen = vec4(v_tir_seen / v_tir.a - u_seen_offset, 1.0);
#endif
#endif
  o_color = vec4(weight * c, 1.0);
  o_seen = vec4(seen.xyz + u_seen_offset, seen.w);
}
