#version 330 core
// A shadow map's casters (pvrr/gl/shadow_pass.h): environment meshes (relative to their anchor, u_offset =
// anchor - the light camera's origin) and element surfaces (element-local, u_offset = 0, the pose folded
// into u_view_proj in double). A lens (LENS) also passes on each vertex's chord through its glass along the
// light (a tinted lens's caster; 0 for a clear one, whose absorption is 0).
layout(location = 0) in vec3 a_pos;
#if defined(LENS)
layout(location = 1) in float a_chord;
out float v_chord;
#endif
uniform mat4 u_view_proj;
uniform vec3 u_offset;
void main() {
#if defined(LENS)
  v_chord = a_chord;
#endif
  gl_Position = u_view_proj * vec4(a_pos + u_offset, 1.0);
}
