#version 330 core
// Escaping rays: the background colour, and a seen point at u_far metres along the pixel's ray (the
// reference tracer's convention for escaping rays).
in vec2 v_ndc;
uniform mat4 u_inv_view_proj;  // inverse of the camera-relative projection * view
uniform vec3 u_background;
uniform float u_far;
#include "outputs.glsl"
void main() {
  vec4 a = u_inv_view_proj * vec4(v_ndc, -1.0, 1.0);
  vec4 b = u_inv_view_proj * vec4(v_ndc, 1.0, 1.0);
  vec3 dir = normalize(b.xyz / b.w - a.xyz / a.w);
  o_color = vec4(u_background, 1.0);
  o_seen = vec4(dir * u_far, 0.0);   // w = 0: an escaping ray
  o_surface = vec4(0.0);
}
