// Ambient occlusion from displacement fields: pvrr/method/ao_field.cpp's volumeVisibility in GLSL (keep them
// in step; the definition is pvrr/trace/ambient_occlusion.h's). Defines from pvrr/gl/ao_fields.cpp:
// AO_FIELDS (occluders), AO_VOLUME (each occlusion volume's grid points per axis, kAoVolumeSize).
#if defined(AMBIENT_OCCLUSION)
uniform sampler3D u_ao_volume;          // per field two blocks of AO_VOLUME slices: O(+x, -x, +y, -y), O(+z, -z)
uniform vec3 u_ao_centre[AO_FIELDS];    // the bounding sphere's centre, relative to the camera origin
uniform mat3 u_ao_rotation[AO_FIELDS];  // the field's frame to the world (its object's motion)
uniform float u_ao_radius[AO_FIELDS];
uniform int u_ao_self;                  // the field of the object being drawn (it does not occlude itself)
// A sphere seen within a cone narrower than this (sin^2 of its half angle) is left out, faded out from twice
// it (ao_field.h's kAoMinCone, aoFade).
const float AO_MIN_CONE = 0.01;

// The occlusion field f casts at x (relative to the camera origin) with unit normal n: its volume read
// trilinearly at the warped coordinates x / (|x| + r), an ambient cube of the six axis normals.
float aoFieldOcclusion(int f, vec3 x, vec3 n_world) {
  mat3 to_field = transpose(u_ao_rotation[f]);
  vec3 p = to_field * (x - u_ao_centre[f]);
  float radius = u_ao_radius[f];
  float fade = clamp(radius * radius / (AO_MIN_CONE * dot(p, p)) - 1.0, 0.0, 1.0);
  if (fade <= 0.0) return 0.0;
  vec3 n = to_field * n_world;
  vec3 uvw = p / (abs(p) + radius) * 0.5 + 0.5;
  // Within the field's block of slices: clamped to its outermost slices' centres, then offset to the block.
  const float size = float(AO_VOLUME);
  float z = clamp(uvw.z * size, 0.5, size - 0.5);
  const float depth = float(2 * AO_FIELDS * AO_VOLUME);
  vec3 n2 = n * n;
  vec4 a = texture(u_ao_volume, vec3(uvw.xy, (z + float(2 * f) * size) / depth));
  float o = n2.x * (n.x >= 0.0 ? a.r : a.g) + n2.y * (n.y >= 0.0 ? a.b : a.a);
  // The +-z block only where the normal has a z part (not for a ground under a car turning about y).
  if (n2.z > 1e-4) {
    vec2 b = texture(u_ao_volume, vec3(uvw.xy, (z + float(2 * f + 1) * size) / depth)).rg;
    o += n2.z * (n.z >= 0.0 ? b.r : b.g);
  }
  return fade * o;
}

// The occluded fraction (0..1) of the ambient light at x with normal n.
float ambientOcclusion(vec3 x, vec3 n) {
  float o = 0.0;
  for (int f = 0; f < AO_FIELDS; ++f)
    if (f != u_ao_self) o += aoFieldOcclusion(f, x, n);
  return min(o, 1.0);
}
#endif
