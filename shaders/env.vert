#version 330 core
// Environment meshes. Vertices are relative to the mesh anchor; u_offset = anchor - camera origin (computed
// in double on the CPU), so world-space magnitudes never reach float.
layout(location = 0) in vec3 a_pos;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec2 a_uv;
uniform mat4 u_view_proj;  // projection * view, with the view's translation removed (camera at the origin)
uniform vec3 u_offset;
out vec3 v_pos;            // relative to the camera origin
out vec3 v_normal;
out vec2 v_uv;
void main() {
  v_pos = a_pos + u_offset;
  v_normal = a_normal;
  v_uv = a_uv;
  gl_Position = u_view_proj * vec4(v_pos, 1.0);
}
