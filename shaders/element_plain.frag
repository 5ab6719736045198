#version 330 core
// Optical elements in raster mode (--mode raster): a plain grey shaded surface. u_dark: black, an element met
// at the depth limit inside another element's map (the tracer absorbs there).
#include "element_inputs.glsl"
uniform bool u_dark;
#include "outputs.glsl"
#include "shading.glsl"

void main() {
  vec3 n = normalize(v_normal);
  vec3 view = normalize(v_pos - u_view_origin);
  float cos_i = -dot(view, n);
  o_surface = vec4(v_pos, u_element_id);
  vec3 nf = cos_i < 0.0 ? -n : n;
  o_color = u_dark ? vec4(0.0, 0.0, 0.0, 1.0) : vec4(shadeDiffuse(vec3(0.6), v_pos, nf), 1.0);
  o_seen = vec4(v_pos, 1.0);
}
