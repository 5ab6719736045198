// Shadows in the environment's shading (SHADOWS; pvrr/gl/shadow_pass.h): each directional and point light's
// term of shaders/shading.glsl times the fraction of its shadow map's filter taps that see the point lit,
// and times a lens's transmittance where the point lies behind the nearest lens (SHADOW_LENSES). The
// reference's counterpart is pvrr/trace/shadow_rays.h.
// Filter: 3 x 3 taps one texel apart, each a hardware 2 x 2 bilinear comparison (PCF over 4 x 4 texels).
// Receivers are moved off their surface along the normal by kShadowNormalOffset texels of their layer (in
// metres: the layer's texel size, times the distance for a point light), against self-shadowing.
// Positions are relative to the current pass's camera origin, as in shading.glsl.
#if defined(SHADOWS)
const float kShadowNormalOffset = 1.5;
uniform sampler2DArrayShadow u_shadow_depth;
#if defined(SHADOW_LENSES)
uniform sampler2DArrayShadow u_shadow_lens_depth;
uniform sampler2DArray u_shadow_lens_t;
#endif
uniform mat4 u_shadow_matrix[SHADOW_LAYERS];   // camera-relative position -> the layer's clip space
uniform float u_shadow_texel_m[SHADOW_LAYERS]; // a texel's size: metres (directional), per metre (point)
uniform float u_shadow_texel;                  // 1 / map side
#if NUM_DIR_LIGHTS > 0
uniform int u_dir_shadow_layer[NUM_DIR_LIGHTS];     // -1: no shadows
#endif
#if NUM_POINT_LIGHTS > 0
uniform int u_point_shadow_layer[NUM_POINT_LIGHTS]; // its first of six layers (+x, -x, +y, -y, +z, -z); -1: none
#endif

float shadowPcf(sampler2DArrayShadow s, vec3 uvz, float layer) {
  float sum = 0.0;
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx) sum += texture(s, vec4(uvz.xy + vec2(dx, dy) * u_shadow_texel, layer, uvz.z));
  return sum * (1.0 / 9.0);
}

// The fraction of the light reaching p through layer `layer`.
float shadowLayer(int layer, vec3 p) {
  vec4 c = u_shadow_matrix[layer] * vec4(p, 1.0);
  vec3 uvz = c.xyz / c.w * 0.5 + 0.5;
  uvz.z = min(uvz.z, 1.0);
  float lit = shadowPcf(u_shadow_depth, uvz, float(layer));
#if defined(SHADOW_LENSES)
  float behind_lens = 1.0 - shadowPcf(u_shadow_lens_depth, uvz, float(layer));
  lit *= mix(1.0, texture(u_shadow_lens_t, vec3(uvz.xy, float(layer))).r, behind_lens);
#endif
  return lit;
}

// shading.glsl's ambientAndDirectional(n) + pointLights(p, n), each light's term shadowed.
vec3 shadowedLight(vec3 p, vec3 n) {
  vec3 light = u_ambient;
#if NUM_DIR_LIGHTS > 0
  for (int i = 0; i < NUM_DIR_LIGHTS; ++i) {
    float c = -dot(n, u_dir_light_dir[i]);
    if (c <= 0.0) continue;
    int layer = u_dir_shadow_layer[i];
    float f = layer < 0 ? 1.0 : shadowLayer(layer, p + n * (kShadowNormalOffset * u_shadow_texel_m[layer]));
    light += c * f * u_dir_light_radiance[i];
  }
#endif
#if NUM_POINT_LIGHTS > 0
  for (int i = 0; i < NUM_POINT_LIGHTS; ++i) {
    vec3 to = u_point_light_pos[i] - p;
    float d2 = dot(to, to);
    if (!(d2 > 0.0)) continue;
    float c = dot(n, to) * inversesqrt(d2);
    if (c <= 0.0) continue;
    float f = 1.0;
    int layer = u_point_shadow_layer[i];
    if (layer >= 0) {
      vec3 v = -to, a = abs(v);  // from the light to the point; the face of its major axis
      int face = a.x >= a.y && a.x >= a.z ? (v.x > 0.0 ? 0 : 1) : (a.y >= a.z ? (v.y > 0.0 ? 2 : 3) : (v.z > 0.0 ? 4 : 5));
      float offset = kShadowNormalOffset * u_shadow_texel_m[layer + face] * max(a.x, max(a.y, a.z));
      f = shadowLayer(layer + face, p + n * offset);
    }
    light += c * f / d2 * u_point_light_radiance[i];
  }
#endif
  return light;
}
#endif
