#version 330 core
// Escaping rays: the background colour, and a seen point at u_far metres along the pixel's ray (the
// reference tracer's convention for escaping rays).
in vec2 v_ndc;
uniform mat4 u_inv_view_proj;  // inverse of the camera-relative projection * view
uniform vec3 u_background;
uniform float u_far;
#include "outputs.glsl"
#if defined(FIRST_LAYER)
// The second layer of an impostor's distance map (with PEEL: u_peel holds the first layer's seen points) where
// nothing lies beyond the first layer: the first layer's own colour, seen point, normal and index there. The
// second layer is then the scene with the nearest occluders taken away, and it blends smoothly where what an
// occluder hides meets what it does not (a sky there would bleed its colour into the hidden surface's edge).
uniform samplerCube u_first_colour;
uniform samplerCube u_first_normal;  // unbound where the cubes have no normals: its zeros are not written
#endif
void main() {
  vec4 a = u_inv_view_proj * vec4(v_ndc, -1.0, 1.0);
  vec4 b = u_inv_view_proj * vec4(v_ndc, 1.0, 1.0);
  vec3 dir = normalize(b.xyz / b.w - a.xyz / a.w);
#if defined(FIRST_LAYER)
  o_color = texture(u_first_colour, dir);
  o_seen = texture(u_peel, dir);
  o_surface = texture(u_first_normal, dir);
  return;
#endif
  o_color = vec4(u_background, 1.0);
  o_seen = vec4(dir * u_far, 0.0);   // w = 0: an escaping ray
  o_surface = vec4(0.0);
}
