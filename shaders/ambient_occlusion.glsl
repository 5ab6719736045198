// Ambient occlusion from displacement fields: pvrr/method/ao_field.cpp's volumeOcclusion and
// groundMapOcclusion in GLSL (keep them in step; the definition is pvrr/trace/ambient_occlusion.h's). Defines
// from pvrr/gl/ao_fields.cpp: AO_FIELDS (occluders), AO_VOLUME (each occlusion volume's grid points per axis,
// kAoVolumeSize), AO_PER_VERTEX (few enough occluders for their varyings: the transforms per vertex); the
// ground variant (a horizontal plane facing up, every occluder turning about the vertical: AoReceiver::Ground)
// also AO_GROUND and AO_HEIGHTS (the ground maps' heights per field), and reads only the ground maps. A mesh no
// field reaches is drawn without AMBIENT_OCCLUSION at all. llvmpipe shades both sides of a per-fragment branch,
// so nothing here branches per fragment; a field that does not reach the draw is weighted by 0 (a loop over
// a uniform list of them, dynamically indexed, measured slower).
#if defined(AMBIENT_OCCLUSION) && defined(AO_VALUES)
// A faceted face drawn as a grid whose vertices hold its occlusion (pvrr/gl/ao_vertex_receivers.h): for its
// normal as uploaded and for the opposite one; the side facing the viewer is chosen per vertex (one per face),
// and the value interpolated across the triangles: no texture read.
// Where the face's light is computed per vertex (FACETED, no shadows: env.vert's AO_LIGHT) the occluded ambient is
// subtracted from it there and the light interpolated instead of flat: the fragments do nothing for the occlusion
// (the same value, as the face's light is constant over it; llvmpipe pays per interpolated component and per
// fragment instruction: docs/performance.md "Ambient occlusion", seventh round). Otherwise the value rides in
// the w of the position's varying (env.vert, env.frag: v_pos_ao) and the fragment subtracts it.
#if defined(AO_VERTEX)
layout(location = 3) in vec2 a_ao;
float aoValue(vec3 n_facing, vec3 n_uploaded) { return dot(n_facing, n_uploaded) > 0.0 ? a_ao.x : a_ao.y; }
#elif !defined(AO_LIGHT)
float ambientOcclusion(vec3 x, vec3 n) { return v_pos_ao.w; }
#endif
#elif defined(AMBIENT_OCCLUSION) && defined(AO_SCREEN)
// A static receiver in a pass that drew the occlusion image first (pvrr/gl/environment_pass.cpp): its occlusion,
// evaluated from the fields at an eighth of the resolution per axis, read bilinearly where the fragment lies.
#if !defined(AO_VERTEX)
uniform sampler2D u_ao_image;
uniform vec4 u_ao_image_map;  // the image's coordinates: gl_FragCoord.xy * map.xy + map.zw (the pass's viewport)
float ambientOcclusion(vec3 x, vec3 n) {
  return texture(u_ao_image, gl_FragCoord.xy * u_ao_image_map.xy + u_ao_image_map.zw).r;
}
#endif
#elif defined(AMBIENT_OCCLUSION)
uniform vec3 u_ao_centre[AO_FIELDS];    // the bounding sphere's centre, relative to the camera origin
uniform mat3 u_ao_rotation[AO_FIELDS];  // the field's frame to the world (its object's motion)
uniform float u_ao_radius[AO_FIELDS];
#if defined(AO_VERTEX) && defined(AO_PER_VERTEX)
// The vertex shader (env.vert): each field's offset from its centre in its own frame, affine in the position,
// so interpolated exactly; the fragments do not transform it.
out vec3 v_ao_p[AO_FIELDS];
void aoVertex(vec3 x) {
  for (int f = 0; f < AO_FIELDS; ++f) v_ao_p[f] = transpose(u_ao_rotation[f]) * (x - u_ao_centre[f]);
}
#if defined(FACETED) && !defined(AO_GROUND)
// A faceted mesh's face normal (facing the viewer) in each field's frame, once per vertex.
flat out vec3 v_ao_n[AO_FIELDS];
void aoVertexNormal(vec3 n) {
  for (int f = 0; f < AO_FIELDS; ++f) v_ao_n[f] = transpose(u_ao_rotation[f]) * n;
}
#endif
#elif !defined(AO_VERTEX)
// The offset of x (relative to the camera origin) from field f's centre in its frame, and normal n there.
#if defined(AO_PER_VERTEX)
in vec3 v_ao_p[AO_FIELDS];
#define AO_OFFSET(f, x) v_ao_p[f]
#else
#define AO_OFFSET(f, x) (transpose(u_ao_rotation[f]) * ((x) - u_ao_centre[f]))
#endif
#if defined(AO_PER_VERTEX) && defined(FACETED) && !defined(AO_GROUND)
flat in vec3 v_ao_n[AO_FIELDS];
#define AO_NORMAL(f, n) v_ao_n[f]  // the face normal it was computed from
#else
#define AO_NORMAL(f, n) (transpose(u_ao_rotation[f]) * (n))
#endif
uniform float u_ao_reaches[AO_FIELDS];  // 1: field f reaches this draw (AoField::reach; not its own), else 0
#if defined(AO_GROUND)
// Per field AO_HEIGHTS layers of kAoGroundSize^2: O(+y) at warped (x, z), the fade included. It shares the
// volume's texture unit (another target; no program reads both).
uniform sampler2DArray u_ao_ground;
uniform int u_ao_height;                // the layer of this draw's plane within each field's

// The occluded fraction (0..1) of the ambient light at x (relative to the camera origin) with normal n.
float ambientOcclusion(vec3 x, vec3 n) {
  float o = 0.0;
  for (int f = 0; f < AO_FIELDS; ++f) {
    vec2 p = AO_OFFSET(f, x).xz;
    vec2 uv = p / (abs(p) + u_ao_radius[f]) * 0.5 + 0.5;
    o += u_ao_reaches[f] * texture(u_ao_ground, vec3(uv, float(f * AO_HEIGHTS + u_ao_height))).r;
  }
  return n.y > 0.0 ? min(o, 1.0) : 0.0;  // facing down, the plane sees none of an occluder standing on it
}
#else
// Per field (along z) eight blocks of AO_VOLUME^3 side by side along x, one per octant of normals: the
// occlusion for the axis normals of its signs (pvrr/gl/ao_fields.cpp).
uniform sampler3D u_ao_volume;
// A sphere seen within a cone narrower than this (sin^2 of its half angle) is left out, faded out from twice
// it (ao_field.h's kAoMinCone, aoFade).
const float AO_MIN_CONE = 0.01;

// The occlusion field f casts at x with unit normal n: its volume read trilinearly at the warped coordinates
// x / (|x| + r), an ambient cube of the six axis normals (sum n_i^2 O(sign(n_i) axis_i)).
float aoFieldOcclusion(int f, vec3 x, vec3 n_world) {
  vec3 p = AO_OFFSET(f, x);
  vec3 n = AO_NORMAL(f, n_world);
  float radius = u_ao_radius[f];
  float fade = clamp(radius * radius / (AO_MIN_CONE * dot(p, p)) - 1.0, 0.0, 1.0);
  const float size = float(AO_VOLUME);
  // Grid coordinates within the block, clamped to its outermost texels' centres (GL_CLAMP_TO_EDGE of one).
  vec3 g = clamp((p / (abs(p) + radius) * 0.5 + 0.5) * size, 0.5, size - 0.5);
  float block = dot(vec3(lessThan(n, vec3(0.0))), vec3(1.0, 2.0, 4.0));
  vec3 a = texture(u_ao_volume, vec3((g.x + block * size) / (8.0 * size), g.y / size,
                                     (g.z + float(f) * size) / (size * float(AO_FIELDS)))).rgb;
  return fade * dot(n * n, a);
}

// The occluded fraction (0..1) of the ambient light at x (relative to the camera origin) with normal n.
float ambientOcclusion(vec3 x, vec3 n) {
  float o = 0.0;
  for (int f = 0; f < AO_FIELDS; ++f) o += u_ao_reaches[f] * aoFieldOcclusion(f, x, n);
  return min(o, 1.0);
}
#endif
#endif  // AO_VERTEX
#endif
