#version 330 core
// Output 0: linear colour. Output 1: the shaded point relative to the camera origin (w = 1), which the
// accuracy reports read as the pixel's "seen point". Output 2: no element (w = 0).
#if defined(AMBIENT_OCCLUSION) && defined(AO_VALUES) && defined(FACETED) && !defined(SHADOWS) && !defined(AO_IMAGE)
#define AO_LIGHT  // the occlusion folded into v_face_light per vertex (env.vert)
#endif
#if defined(AMBIENT_OCCLUSION) && defined(AO_VALUES) && !defined(AO_LIGHT)
in vec4 v_pos_ao;  // the position, and the occlusion value in w (env.vert)
#define v_pos v_pos_ao.xyz
#else
in vec3 v_pos;
#endif
in vec3 v_normal;
in vec2 v_uv;
uniform vec3 u_albedo;
#if defined(TEXTURED)
uniform sampler2D u_texture;   // GL_SRGB8_ALPHA8: decoded to linear before filtering
#endif
uniform vec3 u_view_origin;    // the point rays come from (the camera, or the virtual viewpoint), relative
#include "outputs.glsl"
#include "shading.glsl"
#include "shadow_lookup.glsl"
#include "caustic_lookup.glsl"
#include "ambient_occlusion.glsl"
#if defined(FACETED)
flat in vec3 v_face_normal;
#if defined(AO_LIGHT)
in vec3 v_face_light;  // the occluded ambient already subtracted, interpolated
#else
flat in vec3 v_face_light;
#endif
#endif
void main() {
  peel(v_pos);
  vec3 albedo = u_albedo;
#if defined(TEXTURED)
  albedo *= texture(u_texture, v_uv).rgb;
#endif
#if defined(SHADOWS) && defined(FACETED)
  o_color = vec4(albedo * shadowedLight(v_pos, v_face_normal), 1.0);
#elif defined(SHADOWS)
  vec3 n = normalize(v_normal);
  if (dot(n, v_pos - u_view_origin) > 0.0) n = -n;
  o_color = vec4(albedo * shadowedLight(v_pos, n), 1.0);
#elif defined(FACETED)
  o_color = vec4(albedo * (v_face_light + pointLights(v_pos, v_face_normal)), 1.0);
#else
  vec3 n = normalize(v_normal);
  if (dot(n, v_pos - u_view_origin) > 0.0) n = -n;  // two-sided: face the viewer, as the tracer does
  o_color = vec4(shadeDiffuse(albedo, v_pos, n), 1.0);
#endif
#if defined(CAUSTICS)
  o_color.rgb += albedo * causticIrradiance(v_pos);
#endif
#if defined(AO_LIGHT)
  // (the occluded ambient was subtracted from v_face_light per vertex)
#elif defined(AMBIENT_OCCLUSION) && defined(FACETED)
  o_color.rgb -= albedo * u_ambient * ambientOcclusion(v_pos, v_face_normal);  // the ambient term's occluded part
#elif defined(AMBIENT_OCCLUSION)
  o_color.rgb -= albedo * u_ambient * ambientOcclusion(v_pos, n);
#endif
#if defined(AO_IMAGE) && defined(FACETED)
  o_color = vec4(ambientOcclusion(v_pos, v_face_normal), 0.0, 0.0, 1.0);  // the occlusion image alone
#elif defined(AO_IMAGE)
  o_color = vec4(ambientOcclusion(v_pos, n), 0.0, 0.0, 1.0);
#endif
  o_seen = vec4(v_pos, 1.0);
  o_surface = vec4(0.0);
}
