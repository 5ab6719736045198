#version 330 core
// Optical elements. Variants by prepended defines:
//   MODE_PVRR    the warped first-pass map (paper 3.4); CHANNELS 3 reads one map coordinate per colour
//   MODE_ENVMAP  the classic dynamic cube map from the element centre (lens: looked up along the
//                interpolated exact exit directions of the vertices, the 'refraction vectors' baseline)
//   MODE_PLAIN   a plain grey shaded surface (raster mode)
//   LENS         the element is a lens (transmission) rather than a mirror (reflection)
in vec3 v_pos;
in vec3 v_normal;
in vec3 v_st0;
in vec3 v_st1;
in vec3 v_st2;
in vec3 v_trans;
uniform vec3 u_view_origin;
uniform float u_element_id;      // index + 1
uniform bool u_metal;
uniform vec3 u_reflectance;
uniform vec3 u_metal_n;
uniform vec3 u_metal_k;
uniform vec3 u_seen_offset;      // (the map's camera origin) - (this pass's camera origin)
#if defined(MODE_PVRR)
uniform sampler2D u_map;         // first pass colour (linear)
uniform sampler2D u_seen_map;    // first pass seen points, relative to the map's camera origin (LINEAR)
#elif defined(MODE_ENVMAP)
uniform samplerCube u_cube;
uniform samplerCube u_seen_cube;
#endif
layout(location = 0) out vec4 o_color;
layout(location = 1) out vec4 o_seen;
layout(location = 2) out vec4 o_surface;
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
  o_color = vec4(shadeDiffuse(vec3(0.6), v_pos, nf), 1.0);
  o_seen = vec4(v_pos, 1.0);
#else
  vec3 weight;
#if defined(LENS)
  weight = v_trans;
#else
  if (cos_i <= 0.0) {  // the mirror's back: dark (tracer: kMirrorBackAlbedo)
    o_color = vec4(0.05 * shadeDiffuse(vec3(1.0), v_pos, -n), 1.0);
    o_seen = vec4(v_pos, 1.0);
    return;
  }
  weight = u_reflectance;
  if (u_metal)
    weight = vec3(fresnelConductor(cos_i, u_metal_n.r, u_metal_k.r), fresnelConductor(cos_i, u_metal_n.g, u_metal_k.g),
                  fresnelConductor(cos_i, u_metal_n.b, u_metal_k.b));
#endif
#if defined(MODE_PVRR)
#if CHANNELS == 3
  vec3 c = vec3(texture(u_map, v_st0.xy / v_st0.z).r, texture(u_map, v_st1.xy / v_st1.z).g,
                texture(u_map, v_st2.xy / v_st2.z).b);
  vec4 seen = texture(u_seen_map, v_st1.xy / v_st1.z);
#else
  vec3 c = texture(u_map, v_st0.xy / v_st0.z).rgb;
  vec4 seen = texture(u_seen_map, v_st0.xy / v_st0.z);
#endif
#else
#if defined(LENS)
  vec3 dir = normalize(v_st0);  // the exact exit direction at the vertices, interpolated
#else
  vec3 dir = reflect(view, n);
#endif
  vec3 c = texture(u_cube, dir).rgb;
  vec4 seen = texture(u_seen_cube, dir);
#endif
  o_color = vec4(weight * c, 1.0);
  o_seen = vec4(seen.xyz + u_seen_offset, seen.w);
#endif
}
