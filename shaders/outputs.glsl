// The fragment outputs of every program that draws into a pass (env.frag, sky.frag, element_*.frag), by
// variant. The shader writes o_color, o_seen and o_surface; what they become:
//   default          location 0 colour, 1 seen point, 2 surface point (second pass; pvrr maps have no 2; the
//                    impostor cubes of a scene of several elements take there the normal and index of the
//                    elements drawn in them, 0 elsewhere)
//   NO_SEEN_POINTS   colour only: o_seen and o_surface are locals the compiler drops, with what only they need
//   PLANES           a map of a lens with RGB dispersion: R, G and B in three R32F attachments (locations 0-2),
//                    the seen point at 3. The second pass reads each channel's plane at that channel's
//                    texture coordinates: one float per texel read instead of four.
#if defined(PLANES)
layout(location = 0) out float o_plane_r;
layout(location = 1) out float o_plane_g;
layout(location = 2) out float o_plane_b;
vec4 o_color;
#else
layout(location = 0) out vec4 o_color;
#endif
#if defined(NO_SEEN_POINTS)
vec4 o_seen, o_surface;
#elif defined(PLANES)
layout(location = 3) out vec4 o_seen;
vec4 o_surface;  // maps have no surface attachment
#else
layout(location = 1) out vec4 o_seen;
layout(location = 2) out vec4 o_surface;
#endif
// PEEL: the second layer of an impostor's distance map ([Umenhoffer et al.], depth peeling): a fragment no farther from
// the cube's origin than the first layer's surface in its direction (u_peel, the first layer's seen points,
// relative to the same origin) is dropped, so the layer holds the nearest surface beyond it. PEEL_GAP: the
// relative margin that drops the first layer's own surface, whose filtered distance between the first layer's
// texel centres errs by ~(texel angle)^2 tan^2 of its incidence (2e-4 on a road at 85 deg, 1024^2).
#if defined(PEEL)
uniform samplerCube u_peel;
const float PEEL_GAP = 2e-3;
void peel(vec3 p) {
  if (length(p) <= length(texture(u_peel, p).xyz) * (1.0 + PEEL_GAP)) discard;
}
#else
void peel(vec3 p) {}
#endif
#if defined(PLANES)
void shade();
void main() {
  shade();
  o_plane_r = o_color.r;
  o_plane_g = o_color.g;
  o_plane_b = o_color.b;
}
#define main shade
#endif
