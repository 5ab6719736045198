// The environment shading model; keep in step with pvrr/trace/shading.cpp (the reference tracer's copy).
//   colour = albedo(uv) * (sum ambient + sum_dir max(0, n.(-dir)) L + sum_point max(0, n.l) L / d^2)
// Positions are relative to the camera origin of the current pass (camera-relative rendering).
// Specialised to the scene's lights when the program is built (pvrr/gl/programs.cpp prepends
// NUM_DIR_LIGHTS and NUM_POINT_LIGHTS): constant loop bounds and no per-light branches, the ambient lights
// summed into one colour. A loop over a uniform light count with a type switch per light cost llvmpipe
// more than half of a 1280 x 720 raster frame.
#ifndef NUM_DIR_LIGHTS
#define NUM_DIR_LIGHTS 0
#endif
#ifndef NUM_POINT_LIGHTS
#define NUM_POINT_LIGHTS 0
#endif
uniform vec3 u_ambient;                                   // the sum of the ambient lights
#if NUM_DIR_LIGHTS > 0
uniform vec3 u_dir_light_dir[NUM_DIR_LIGHTS];             // the direction the light travels
uniform vec3 u_dir_light_radiance[NUM_DIR_LIGHTS];
#endif
#if NUM_POINT_LIGHTS > 0
uniform vec3 u_point_light_pos[NUM_POINT_LIGHTS];         // relative to the camera origin
uniform vec3 u_point_light_radiance[NUM_POINT_LIGHTS];
#endif

// The light that depends on the normal only: ambient and directional (constant over a planar face).
vec3 ambientAndDirectional(vec3 n) {
  vec3 light = u_ambient;
#if NUM_DIR_LIGHTS > 0
  for (int i = 0; i < NUM_DIR_LIGHTS; ++i) light += max(0.0, -dot(n, u_dir_light_dir[i])) * u_dir_light_radiance[i];
#endif
  return light;
}

// The light that depends on the point too: point lights.
vec3 pointLights(vec3 p, vec3 n) {
  vec3 light = vec3(0.0);
#if NUM_POINT_LIGHTS > 0
  for (int i = 0; i < NUM_POINT_LIGHTS; ++i) {
    vec3 to = u_point_light_pos[i] - p;
    float d2 = dot(to, to);
    if (d2 > 0.0) light += max(0.0, dot(n, to) * inversesqrt(d2)) / d2 * u_point_light_radiance[i];
  }
#endif
  return light;
}

vec3 shadeDiffuse(vec3 albedo, vec3 p, vec3 n) { return albedo * (ambientAndDirectional(n) + pointLights(p, n)); }
