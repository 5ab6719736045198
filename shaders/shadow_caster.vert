#version 330 core
// A shadow map's casters (pvrr/gl/shadow_pass.h): environment meshes (relative to their anchor, u_offset =
// anchor - the light camera's origin) and element surfaces (element-local, u_offset = 0, the pose folded
// into u_view_proj in double).
layout(location = 0) in vec3 a_pos;
uniform mat4 u_view_proj;
uniform vec3 u_offset;
void main() { gl_Position = u_view_proj * vec4(a_pos + u_offset, 1.0); }
