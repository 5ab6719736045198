#version 330 core
// Optical elements, in the second pass or drawn inside another element's first pass. Per vertex: position
// relative to the element anchor, the exact surface normal, and (PVRR) the projective texture coordinates
// (s q, t q, q) of the exact hit point of up to three channels in the patch's map, each channel's RGB weight
// (its colour weight times its transmittance), and the coordinates that give the pixel's seen point.
// Envmap lens: a_st0 is the exact exit direction and a_w0 the transmittance.
layout(location = 0) in vec3 a_pos;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec3 a_st0;
layout(location = 3) in vec3 a_st1;
layout(location = 4) in vec3 a_st2;
layout(location = 5) in vec3 a_w0;
layout(location = 6) in vec3 a_w1;
layout(location = 7) in vec3 a_w2;
layout(location = 8) in vec3 a_st_seen;
layout(location = 9) in vec4 a_tir;       // rgb: the traced colour of totally reflected channels; a: 1 where the
layout(location = 10) in vec3 a_tir_seen; // seen channel is, with its traced seen point (relative to the anchor)
uniform mat4 u_view_proj;
uniform vec3 u_offset;                  // element anchor - camera origin
out vec3 v_pos;
out vec3 v_normal;
out vec3 v_st0;
out vec3 v_st1;
out vec3 v_st2;
out vec3 v_w0;
out vec3 v_w1;
out vec3 v_w2;
out vec3 v_st_seen;
out vec4 v_tir;
out vec3 v_tir_seen;   // a_tir.a * the traced seen point relative to the camera origin
// The channel sets of one patch are drawn one after the other with the same vertices (additively, depth
// test LEQUAL): their depths must be bit-identical.
invariant gl_Position;
void main() {
  v_pos = a_pos + u_offset;
  v_normal = a_normal;
  v_st0 = a_st0;
  v_st1 = a_st1;
  v_st2 = a_st2;
  v_w0 = a_w0;
  v_w1 = a_w1;
  v_w2 = a_w2;
  v_st_seen = a_st_seen;
  v_tir = a_tir;
  // Weighted by the traced flag: interpolated, v_tir_seen / v_tir.a is the mean of the traced vertices' seen
  // points alone (the others carry 0), relative to the camera origin.
  v_tir_seen = a_tir.a * (a_tir_seen + u_offset);
  gl_Position = u_view_proj * vec4(v_pos, 1.0);
}
