// The environment shading model; keep in step with pvrr/shading.cpp (the reference tracer's copy).
//   colour = albedo(uv) * (sum ambient + sum_dir max(0, n.(-dir)) L + sum_point max(0, n.l) L / d^2)
// Positions are relative to the camera origin of the current pass (camera-relative rendering).
#define MAX_LIGHTS 8
uniform int u_num_lights;
uniform int u_light_type[MAX_LIGHTS];       // 0 ambient, 1 directional, 2 point
uniform vec3 u_light_vec[MAX_LIGHTS];       // directional: travel direction; point: position (relative)
uniform vec3 u_light_radiance[MAX_LIGHTS];

vec3 shadeDiffuse(vec3 albedo, vec3 p, vec3 n) {
  vec3 light = vec3(0.0);
  for (int i = 0; i < u_num_lights; ++i) {
    if (u_light_type[i] == 0) {
      light += u_light_radiance[i];
    } else if (u_light_type[i] == 1) {
      light += max(0.0, -dot(n, u_light_vec[i])) * u_light_radiance[i];
    } else {
      vec3 to = u_light_vec[i] - p;
      float d2 = dot(to, to);
      if (d2 > 0.0) light += max(0.0, dot(n, to) * inversesqrt(d2)) / d2 * u_light_radiance[i];
    }
  }
  return albedo * light;
}
