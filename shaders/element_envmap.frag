#version 330 core
// Optical elements in envmap mode: the classic dynamic cube map from the element centre (lens: looked up along
// the interpolated exact exit directions of the vertices, the 'refraction vectors' baseline). Variants by
// prepended defines:
//   LENS         the element is a lens (transmission) rather than a mirror (reflection)
//   NO_SEEN_POINTS  colour only: the seen-point maps are not read (RendererOptions::seen_points off)
#include "element_inputs.glsl"
uniform samplerCube u_cube;
uniform samplerCube u_seen_cube;
#include "outputs.glsl"
#include "shading.glsl"
#include "optics.glsl"

void main() {
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
  o_color = vec4(weight * c, 1.0);
  o_seen = vec4(seen.xyz + u_seen_offset, seen.w);
}
