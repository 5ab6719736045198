#version 330 core
// Environment meshes. Vertices are relative to the mesh anchor; u_offset = anchor - camera origin (computed
// in double on the CPU), so world-space magnitudes never reach float.
// FACETED (a mesh whose triangles each have one normal at all three corners: quads, grounds, boxes): the
// face's normal, turned to the viewer, and its ambient + directional light are computed here once per vertex
// and passed flat; on a planar face they are the same at every point, so this equals the per-fragment
// result (env.frag) at a fraction of llvmpipe's cost.
layout(location = 0) in vec3 a_pos;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec2 a_uv;
uniform mat4 u_view_proj;  // projection * view, with the view's translation removed (camera at the origin)
uniform vec3 u_offset;
uniform vec4 u_clip_plane;  // camera-relative: clipped where dot(xyz, v_pos) + w < 0, while GL_CLIP_DISTANCE0 is on
#if defined(AMBIENT_OCCLUSION) && defined(AO_VALUES) && defined(FACETED) && !defined(SHADOWS) && !defined(AO_IMAGE)
#define AO_LIGHT  // the occlusion folded into the face's light per vertex (ambient_occlusion.glsl AO_VALUES)
#endif
#if defined(AMBIENT_OCCLUSION) && defined(AO_VALUES) && !defined(AO_LIGHT)
// The occlusion value rides in the position's spare component (shaders/ambient_occlusion.glsl AO_VALUES): no
// varying of its own (on llvmpipe within the noise of one: docs/performance.md "Ambient occlusion").
out vec4 v_pos_ao;
#define v_pos v_pos_ao.xyz
#else
out vec3 v_pos;            // relative to the camera origin
#endif
out vec3 v_normal;
out vec2 v_uv;
#include "shading.glsl"
#define AO_VERTEX  // the vertex half of ambient_occlusion.glsl (nothing without AMBIENT_OCCLUSION)
#include "ambient_occlusion.glsl"
#if defined(FACETED)
uniform vec3 u_view_origin;
flat out vec3 v_face_normal;  // facing the viewer
#if defined(AO_LIGHT)
out vec3 v_face_light;        // ambientAndDirectional(v_face_normal) less the occluded ambient, interpolated
#else
flat out vec3 v_face_light;   // ambientAndDirectional(v_face_normal)
#endif
#endif
void main() {
  v_pos = a_pos + u_offset;
  v_normal = a_normal;
  v_uv = a_uv;
#if defined(FACETED)
  vec3 n = normalize(a_normal);
  if (dot(n, v_pos - u_view_origin) > 0.0) n = -n;  // two-sided, as env.frag
  v_face_normal = n;
  v_face_light = ambientAndDirectional(n);
#if defined(AO_PER_VERTEX) && !defined(AO_GROUND)
  aoVertexNormal(n);
#endif
#if defined(AO_LIGHT)
  v_face_light -= u_ambient * aoValue(n, a_normal);
#elif defined(AMBIENT_OCCLUSION) && defined(AO_VALUES)
  v_pos_ao.w = aoValue(n, a_normal);
#endif
#endif
#if defined(AO_PER_VERTEX)
  aoVertex(v_pos);
#endif
  gl_Position = u_view_proj * vec4(v_pos, 1.0);
  gl_ClipDistance[0] = dot(u_clip_plane.xyz, v_pos) + u_clip_plane.w;
}
