#version 330 core
// Optical elements in the second pass. Per vertex: position relative to the element anchor, the exact
// surface normal, and (PVRR) the projective texture coordinates (s q, t q, q) of the exact hit point in each channel's map.
layout(location = 0) in vec3 a_pos;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec3 a_st0;
layout(location = 3) in vec3 a_st1;
layout(location = 4) in vec3 a_st2;
layout(location = 5) in vec3 a_trans;   // lens: Fresnel transmittance per channel
uniform mat4 u_view_proj;
uniform vec3 u_offset;                  // element anchor - camera origin
out vec3 v_pos;
out vec3 v_normal;
out vec3 v_st0;
out vec3 v_st1;
out vec3 v_st2;
out vec3 v_trans;
void main() {
  v_pos = a_pos + u_offset;
  v_normal = a_normal;
  v_st0 = a_st0;
  v_st1 = a_st1;
  v_st2 = a_st2;
  v_trans = a_trans;
  gl_Position = u_view_proj * vec4(v_pos, 1.0);
}
