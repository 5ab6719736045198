// Shadows in the environment's shading (SHADOWS; pvrr/gl/shadow_pass.h): each directional and point light's
// term of shaders/shading.glsl times the fraction of its shadow map's filter taps that see the point lit,
// and times a lens's transmittance where the point lies behind the nearest lens (SHADOW_LENSES). The
// reference's counterpart is pvrr/trace/shadow_rays.h.
// Filter: 3 x 3 bilinear comparisons one texel apart (PCF over 4 x 4 texels), read by four gathers (shadowPcf).
// Receivers are moved off their surface along the normal by kShadowNormalOffset texels of their layer (in
// metres: the layer's texel size, times the distance for a point light), against self-shadowing.
// Positions are relative to the current pass's camera origin, as in shading.glsl. Every per-light uniform is
// indexed by the light loop's counter only (a point light's face is projected in closed form, not by a
// matrix chosen per fragment): llvmpipe gathers a uniform array indexed by a per-fragment value lane by lane.
#if defined(SHADOWS)
const float kShadowNormalOffset = 1.5;
uniform sampler2DArrayShadow u_shadow_depth;
#if defined(SHADOW_LENSES)
uniform sampler2DArrayShadow u_shadow_lens_depth;
uniform sampler2DArray u_shadow_lens_t;
#endif
uniform float u_shadow_texel;                        // 1 / map side
#if NUM_DIR_LIGHTS > 0
uniform float u_dir_shadow_layer[NUM_DIR_LIGHTS];    // its layer; < 0: no shadows
uniform mat4 u_dir_shadow_matrix[NUM_DIR_LIGHTS];    // camera-relative position -> the layer's clip space
uniform float u_dir_shadow_texel_m[NUM_DIR_LIGHTS];  // a texel's size, metres
#endif
#if NUM_POINT_LIGHTS > 0
uniform float u_point_shadow_layer[NUM_POINT_LIGHTS]; // its first of six layers (+x, -x, +y, -y, +z, -z); < 0: none
uniform vec2 u_point_shadow_near_far[NUM_POINT_LIGHTS];
uniform float u_point_shadow_tan_half;                // tan of each face's half angle (a little over 1)
#endif

// The 3 x 3 bilinear taps one texel apart, from four gathers of the 4 x 4 texels they cover (the same sum:
// columns i0 - 1 .. i0 + 2 weigh 1 - f.x, 1, 1, f.x, rows likewise). Not nine filtered lookups: textureGrad
// (explicit derivatives) makes llvmpipe sample with a lod per pixel, its slow path: about twice the gathers'
// time; texture() and sixteen texelFetch were slower too (docs/performance.md "Shadows"). A gather needs no
// derivatives, so it is defined in the light loop's non-uniform control flow too.
#if defined(SHADOW_GATHER)
float shadowPcf(sampler2DArrayShadow s, vec3 uvz, float layer) {
  vec2 t = uvz.xy / u_shadow_texel - 0.5;  // texel space: texel i's centre at i
  vec2 i0 = floor(t), f = t - i0;
  // Each gather at the corner between its 2 x 2 texels: (x, y, z, w) = (c0 r1, c1 r1, c1 r0, c0 r0).
  vec4 g00 = textureGather(s, vec3(i0 * u_shadow_texel, layer), uvz.z);
  vec4 g10 = textureGather(s, vec3((i0 + vec2(2.0, 0.0)) * u_shadow_texel, layer), uvz.z);
  vec4 g01 = textureGather(s, vec3((i0 + vec2(0.0, 2.0)) * u_shadow_texel, layer), uvz.z);
  vec4 g11 = textureGather(s, vec3((i0 + vec2(2.0, 2.0)) * u_shadow_texel, layer), uvz.z);
  vec2 e = 1.0 - f;
  float sum = dot(g00, vec4(e.x, 1.0, 1.0, e.x * e.y) * vec4(1.0, 1.0, e.y, 1.0)) +
              dot(g10, vec4(1.0, f.x, f.x * e.y, e.y)) +
              dot(g01, vec4(e.x * f.y, f.y, 1.0, e.x)) +
              dot(g11, vec4(f.y, f.x * f.y, f.x, 1.0));
  return sum * (1.0 / 9.0);
}
#else
// A GL without shadow gathers (before 4.0 and without GL_ARB_gpu_shader5): the same filter as nine bilinear
// comparisons, with zero explicit derivatives (the maps have one level; defined in non-uniform control flow).
float shadowPcf(sampler2DArrayShadow s, vec3 uvz, float layer) {
  float sum = 0.0;
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx)
      sum += textureGrad(s, vec4(uvz.xy + vec2(dx, dy) * u_shadow_texel, layer, uvz.z), vec2(0.0), vec2(0.0));
  return sum * (1.0 / 9.0);
}
#endif

// The fraction of the light reaching the point at map coordinates uvz of layer `layer`, per channel (a tinted
// lens passes each channel its own share).
vec3 shadowAt(vec3 uvz, float layer) {
  uvz.z = min(uvz.z, 1.0);
  vec3 lit = vec3(shadowPcf(u_shadow_depth, uvz, layer));
#if defined(SHADOW_LENSES)
  float behind_lens = 1.0 - shadowPcf(u_shadow_lens_depth, uvz, layer);
  lit *= mix(vec3(1.0), textureLod(u_shadow_lens_t, vec3(uvz.xy, layer), 0.0).rgb, behind_lens);
#endif
  return lit;
}

#if NUM_POINT_LIGHTS > 0
// A point light's map coordinates of v (from the light to the point) in .xyz and its face (0..5) in .w: the
// face of v's major axis, projected as glm::lookAt(light, light + axis, up) and glm::perspective project it
// for that face (pvrr/gl/shadow_pass.cpp kFaceAxis, kFaceUp; right = axis x up, up' = right x axis).
vec4 pointFace(vec3 v, vec2 near_far) {
  vec3 a = abs(v);
  float m, x, y, face;
  if (a.x >= a.y && a.x >= a.z) {
    m = a.x; face = v.x > 0.0 ? 0.0 : 1.0; x = v.x > 0.0 ? v.z : -v.z; y = v.y;
  } else if (a.y >= a.z) {
    m = a.y; face = v.y > 0.0 ? 2.0 : 3.0; x = -v.x; y = v.y > 0.0 ? -v.z : v.z;
  } else {
    m = a.z; face = v.z > 0.0 ? 4.0 : 5.0; x = v.z > 0.0 ? -v.x : v.x; y = v.y;
  }
  float n = near_far.x, f = near_far.y;
  float z_ndc = (f + n) / (f - n) - 2.0 * f * n / ((f - n) * m);
  return vec4(vec2(x, y) / (m * u_point_shadow_tan_half) * 0.5 + 0.5, z_ndc * 0.5 + 0.5, face);
}
#endif

// shading.glsl's ambientAndDirectional(n) + pointLights(p, n), each light's term shadowed.
vec3 shadowedLight(vec3 p, vec3 n) {
  vec3 light = u_ambient;
#if NUM_DIR_LIGHTS > 0
  for (int i = 0; i < NUM_DIR_LIGHTS; ++i) {
    float c = -dot(n, u_dir_light_dir[i]);
    if (c <= 0.0) continue;
    vec3 f = vec3(1.0);
    if (u_dir_shadow_layer[i] >= 0.0) {
      vec4 q = u_dir_shadow_matrix[i] * vec4(p + n * (kShadowNormalOffset * u_dir_shadow_texel_m[i]), 1.0);
      f = shadowAt(q.xyz / q.w * 0.5 + 0.5, u_dir_shadow_layer[i]);
    }
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
    vec3 f = vec3(1.0);
    if (u_point_shadow_layer[i] >= 0.0) {
      vec3 a = abs(to);
      // A texel at distance m along the face's axis: 2 tan_half m / side.
      float offset = kShadowNormalOffset * 2.0 * u_point_shadow_tan_half * u_shadow_texel * max(a.x, max(a.y, a.z));
      vec4 q = pointFace(p + n * offset - u_point_light_pos[i], u_point_shadow_near_far[i]);
      f = shadowAt(q.xyz, u_point_shadow_layer[i] + q.w);
    }
    light += c * f / d2 * u_point_light_radiance[i];
  }
#endif
  return light;
}
#endif
