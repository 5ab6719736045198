// Ambient occlusion from displacement fields: pvrr/method/ao_field.cpp's fieldVisibility in GLSL (keep them
// in step; the definition is pvrr/trace/ambient_occlusion.h's). Defines from pvrr/gl/ao_fields.cpp:
// AO_FIELDS (occluding objects), AO_POSITIONS and AO_DIRECTIONS (each field's sampling), AO_SIDE (the
// fragment's rays per field: AO_SIDE^2).
#if defined(AMBIENT_OCCLUSION)
uniform sampler2DArray u_ao_field;      // per field one layer of bytes (R8): 254ths of 2 r, 255 a miss
uniform vec3 u_ao_centre[AO_FIELDS];    // the bounding sphere's centre, relative to the camera origin
uniform mat3 u_ao_rotation[AO_FIELDS];  // the field's frame to the world (its object's motion)
uniform float u_ao_radius[AO_FIELDS];
uniform int u_ao_self;                  // the field of the object being drawn (it does not occlude itself)
const float AO_PI = 3.14159265358979;
// A sphere seen within a cone narrower than this (sin^2 of its half angle) is left out: it could hide at
// most this cosine-weighted fraction (ao_field.cpp's kAoMinCone).
const float AO_MIN_CONE = 0.002;

vec2 aoConcentricDisk(vec2 s) {
  if (s.x == 0.0 && s.y == 0.0) return vec2(0.0);
  if (abs(s.x) > abs(s.y)) {
    float phi = AO_PI / 4.0 * (s.y / s.x);
    return s.x * vec2(cos(phi), sin(phi));
  }
  float phi = AO_PI / 2.0 - AO_PI / 4.0 * (s.x / s.y);
  return s.y * vec2(cos(phi), sin(phi));
}

vec2 aoConcentricSquare(vec2 d) {
  float r = length(d);
  if (r == 0.0) return vec2(0.0);
  float psi = atan(d.y, d.x);
  if (psi < -AO_PI / 4.0) psi += 2.0 * AO_PI;
  float k = 4.0 / AO_PI;
  if (psi < AO_PI / 4.0) return vec2(r, k * psi * r);
  if (psi < 3.0 * AO_PI / 4.0) return vec2(k * (AO_PI / 2.0 - psi) * r, r);
  if (psi < 5.0 * AO_PI / 4.0) return vec2(-r, -k * (psi - AO_PI) * r);
  return vec2(-k * (1.5 * AO_PI - psi) * r, -r);
}

void aoBasis(vec3 n, out vec3 t, out vec3 b) {
  float sgn = n.z >= 0.0 ? 1.0 : -1.0;
  float a = -1.0 / (sgn + n.z);
  float c = n.x * n.y * a;
  t = vec3(1.0 + sgn * n.x * n.x * a, sgn * c, -sgn * n.x);
  b = vec3(c, sgn + n.y * n.y * a, -n.y);
}

vec2 aoOctEncode(vec3 u) {
  vec2 p = u.xy / (abs(u.x) + abs(u.y) + abs(u.z));
  if (u.z < 0.0) p = (1.0 - abs(p.yx)) * vec2(p.x >= 0.0 ? 1.0 : -1.0, p.y >= 0.0 ? 1.0 : -1.0);
  return p * 0.5 + 0.5;
}

vec3 aoOctDecode(vec2 uv) {
  vec2 p = uv * 2.0 - 1.0;
  vec3 v = vec3(p, 1.0 - abs(p.x) - abs(p.y));
  if (v.z < 0.0) v.xy = (1.0 - abs(v.yx)) * vec2(v.x >= 0.0 ? 1.0 : -1.0, v.y >= 0.0 ? 1.0 : -1.0);
  return normalize(v);
}

// The field's distance along the ray entering its sphere at unit s (field frame) in direction w; 1e30: a miss.
float aoFieldDistance(int f, vec3 s, vec3 w) {
  ivec2 p = clamp(ivec2(floor(aoOctEncode(s) * float(AO_POSITIONS))), 0, AO_POSITIONS - 1);
  vec3 t, b;
  aoBasis(-aoOctDecode((vec2(p) + 0.5) / float(AO_POSITIONS)), t, b);
  vec2 disk = vec2(dot(w, t), dot(w, b));
  float r = length(disk);
  if (r > 1.0) disk /= r;
  ivec2 d = clamp(ivec2(floor((aoConcentricSquare(disk) * 0.5 + 0.5) * float(AO_DIRECTIONS))), 0, AO_DIRECTIONS - 1);
  float v = texelFetch(u_ao_field, ivec3(p * AO_DIRECTIONS + d, f), 0).r * 255.0;
  return v > 254.5 ? 1e30 : v / 254.0 * 2.0 * u_ao_radius[f];
}

// The occlusion field f casts at x (relative to the camera origin) with unit normal n.
float aoFieldOcclusion(int f, vec3 x, vec3 n_world) {
  mat3 to_field = transpose(u_ao_rotation[f]);
  vec3 p = to_field * (x - u_ao_centre[f]);
  vec3 n = to_field * n_world;
  float radius = u_ao_radius[f];
  float dist2 = dot(p, p), c = dist2 - radius * radius;
  float occluded = 0.0;
  const float cell = 2.0 / float(AO_SIDE);
  if (c > 0.0) {
    float sin2 = radius * radius / dist2;
    float dist = sqrt(dist2);
    vec3 axis = -p / dist;
    if (sin2 < AO_MIN_CONE || dot(n, axis) < -sqrt(sin2)) return 0.0;
    float cos_a = sqrt(1.0 - sin2);
    vec3 ta, tb;
    aoBasis(axis, ta, tb);
    float weight = 2.0 * (1.0 - cos_a) / float(AO_SIDE * AO_SIDE);
    for (int i = 0; i < AO_SIDE; ++i)
      for (int j = 0; j < AO_SIDE; ++j) {
        vec2 d = aoConcentricDisk(vec2(float(i) + 0.5, float(j) + 0.5) * cell - 1.0);
        float r2 = dot(d, d), cos_t = 1.0 - r2 * (1.0 - cos_a);
        float sin_t = sqrt(max(0.0, 1.0 - cos_t * cos_t));
        vec2 around = r2 > 0.0 ? d * inversesqrt(r2) : vec2(0.0);
        vec3 w = cos_t * axis + sin_t * (around.x * ta + around.y * tb);
        float cos_n = dot(w, n), bb = dot(p, w), disc = bb * bb - c;
        if (cos_n <= 0.0 || disc < 0.0) continue;
        vec3 e = p + (-bb - sqrt(disc)) * w;
        if (aoFieldDistance(f, normalize(e), w) < 1e29) occluded += weight * cos_n;
      }
    return min(occluded, 1.0);
  }
  vec3 tn, bn;
  aoBasis(n, tn, bn);
  for (int i = 0; i < AO_SIDE; ++i)
    for (int j = 0; j < AO_SIDE; ++j) {
      vec2 d = aoConcentricDisk(vec2(float(i) + 0.5, float(j) + 0.5) * cell - 1.0);
      vec3 w = normalize(d.x * tn + d.y * bn + sqrt(max(0.0, 1.0 - dot(d, d))) * n);
      float bb = dot(p, w);
      float t_exit = -bb + sqrt(max(0.0, bb * bb - c));
      vec3 e = p + t_exit * w;
      if (aoFieldDistance(f, normalize(e), -w) < t_exit) occluded += 1.0;
    }
  return occluded / float(AO_SIDE * AO_SIDE);
}

// The occluded fraction (0..1) of the ambient light at x with normal n.
float ambientOcclusion(vec3 x, vec3 n) {
  float o = 0.0;
  for (int f = 0; f < AO_FIELDS; ++f)
    if (f != u_ao_self) o += aoFieldOcclusion(f, x, n);
  return min(o, 1.0);
}
#endif
