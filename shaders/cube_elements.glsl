// CUBE_ELEMENTS n (2 to 4): the scene's n elements each have cube maps in which the other mirrors are drawn with
// their surface point, normal and index (distance-normal impostors, [Dancsik and Minarik]): a search that meets a mirror
// reflects there and goes on in that mirror's cubes (followCubes); LENS_IN_CUBES: the other elements' cubes
// show the scene's one lens too, and a search that meets it refracts through its height maps and goes on in
// the lens's cubes.
#include "cpp_constants.glsl"
#include "impostor_search.glsl"
#include "lens_march.glsl"
#include "optics.glsl"
#include "shading.glsl"
#if defined(CUBE_ELEMENTS)
// Per element (index): its cubes (colour; seen points, whose lengths are the distances; normal and index + 1
// of an element drawn in them, 0 elsewhere), their origin relative to the camera origin, and its mirror
// material.
uniform samplerCube u_cubes[CUBE_ELEMENTS];
uniform samplerCube u_seen_cubes[CUBE_ELEMENTS];
uniform samplerCube u_normal_cubes[CUBE_ELEMENTS];
#if IMPOSTOR_LAYERS > 1
uniform samplerCube u_cubes1[CUBE_ELEMENTS];  // the second layers (depth-peeled)
uniform samplerCube u_seen_cubes1[CUBE_ELEMENTS];
uniform samplerCube u_normal_cubes1[CUBE_ELEMENTS];
#endif
uniform vec3 u_cube_centre[CUBE_ELEMENTS];
uniform bool u_el_metal[CUBE_ELEMENTS];
uniform vec3 u_el_reflectance[CUBE_ELEMENTS];
uniform vec3 u_el_metal_n[CUBE_ELEMENTS];
uniform vec3 u_el_metal_k[CUBE_ELEMENTS];
uniform int u_self;               // this element's index
uniform int u_max_depth;          // render.max_depth: the tracer absorbs at an element met after that many events
#if defined(LENS_IN_CUBES)
uniform int u_cube_lens;          // the lens's element index
uniform mat3 u_lens_to_local;     // world directions -> the lens's local frame (whose origin is its cube's)
#endif

// The multi-bounce loop of [Dancsik and Minarik] and [Umenhoffer et al.] over distance-normal impostors. The ray from x
// (relative to the camera origin) along R, with `depth` of the tracer's events spent, is searched in the cubes of
// element `cur`; where it meets another mirror drawn there, it reflects at the found point with that mirror's normal
// and material (exact Fresnel) and goes on in that mirror's cubes, as the tracer does: absorbed at an element met after
// u_max_depth events, dark at a mirror's back. LENS_IN_CUBES: where it meets the scene's lens, it enters the lens's
// height maps where the ray meets the surface (a ray past its outline goes on in the lens's cubes, which do not show
// the lens), refracts through the glass (throughLens, with the index of `channel`: 0-2 R, G, B) and goes on from the
// exit in the lens's cubes. Returns the colour; `seen`: the last point, relative to the camera origin (w 0: escaping);
// `refracted`: whether the path met the lens (else no channel matters).
#if IMPOSTOR_LAYERS > 1
#define CUBE_LOOKUP(k)                                                                                              \
  if (cur == k) {                                                                                                  \
    centre = u_cube_centre[k];                                                                                     \
    int layer;                                                                                                     \
    l = layeredHit(u_seen_cubes[k], u_seen_cubes1[k], x - centre, R, layer);                                       \
    c = layer == 1 ? texture(u_cubes1[k], l).rgb : texture(u_cubes[k], l).rgb;                                     \
    s = g_seen_at; /* the search's read there (impostor_search.glsl) */                                           \
    nid = layer == 1 ? texture(u_normal_cubes1[k], l) : texture(u_normal_cubes[k], l);                             \
    if (g_escaped) c = u_background, s = vec4(x - centre + R * u_far, 0.0), nid = vec4(0.0);                        \
  }
#else
#define CUBE_LOOKUP(k)                                                                                              \
  if (cur == k) {                                                                                                  \
    centre = u_cube_centre[k];                                                                                     \
    l = impostorHit(u_seen_cubes[k], x - centre, R, d_at);                                                         \
    checkResolved(l, d_at);                                                                                        \
    c = texture(u_cubes[k], l).rgb;                                                                                \
    s = g_seen_at;                                                                                                 \
    nid = texture(u_normal_cubes[k], l);                                                                           \
  }
#endif
vec3 followCubes(int cur, vec3 x, vec3 R, int depth, int channel, out vec4 seen, out bool refracted) {
  vec3 throughput = vec3(1.0);
  refracted = false;
  // MAX_DEPTH_LIMIT passes past the lens's outline without an event: no seen point of its own
  seen = vec4(x, 1.0);
  for (int bounce = 0; bounce < MAX_DEPTH_LIMIT; ++bounce) {
    vec3 centre = vec3(0.0), l = R, c = vec3(0.0);
    vec4 s = vec4(0.0), nid = vec4(0.0);
    float d_at;  // (one layer) the distance the cube holds at l
    CUBE_LOOKUP(0)
    CUBE_LOOKUP(1)
#if CUBE_ELEMENTS > 2
    CUBE_LOOKUP(2)
#endif
#if CUBE_ELEMENTS > 3
    CUBE_LOOKUP(3)
#endif
    // The normal and index are filtered like the rest, and the texels of the environment hold zero: where an
    // element's texels blend with those of what lies behind it, |normal| is the element's weight, the larger
    // weight decides, and the index divided by it is the element's.
    float weight = length(nid.xyz);
    int hit = weight >= 0.5 ? int(floor(nid.w / weight + 0.5)) - 1 : -1;
    if (hit < 0 || hit >= CUBE_ELEMENTS || hit == cur) {
      seen = vec4(s.xyz + centre, s.w);
      return throughput * c;
    }
    vec3 p = centre + l, n = nid.xyz / weight;
#if defined(LENS_IN_CUBES)
    if (hit == u_cube_lens) {
      // The lens's frame: its origin is its cube's. The cube holds the front mesh's outward normal: a ray
      // along it meets the lens from behind (as the second pass decides).
      vec3 lens_centre = u_cube_centre[hit];
      vec3 xl = u_lens_to_local * (p - lens_centre), vl = u_lens_to_local * R;
      bool from_back = dot(R, n) >= 0.0;
      vec3 entry = entryPoint(xl, vl, from_back);
      // Past the outline (the cube's texels blend the lens's rim with what lies behind it): the ray misses
      // the lens and goes on, unchanged, in its cubes.
      if (!inOutline(entry.xy)) {
        x = p;
        cur = hit;
        continue;
      }
      seen = vec4(lens_centre + entry * u_lens_to_local, 1.0);
      if (depth >= u_max_depth) return vec3(0.0);  // the tracer's depth limit: absorbed at the surface
      vec3 n_in = normalize(lensTexel(from_back, entry.xy).yzw);
      if (dot(vl, n_in) >= 0.0) return vec3(0.0);  // along the surface: nothing to refract
      vec3 dir;
      vec3 tr;
      bool rim;
      int spent;
      vec3 q = throughLens(entry, vl, n_in, u_index[channel], u_max_depth - 1 - depth, dir, tr, rim, spent);
      refracted = true;
      if (tr == vec3(0.0)) {  // absorbed inside the glass, or at its rim
        seen = rim ? vec4(lens_centre + (q + u_far * dir) * u_lens_to_local, 0.0)
                   : vec4(lens_centre + q * u_lens_to_local, 1.0);
        return vec3(0.0);
      }
      throughput *= tr;
      depth += spent;
      x = lens_centre + q * u_lens_to_local;
      R = dir * u_lens_to_local;
      cur = hit;
      continue;
    }
#endif
    seen = vec4(p, 1.0);
    if (depth >= u_max_depth) return vec3(0.0);  // the tracer's depth limit: absorbed
    float cos_i = -dot(R, n);
    if (cos_i <= 0.0) return throughput * MIRROR_BACK_ALBEDO * shadeDiffuse(vec3(1.0), p, -n);  // the mirror's back
    throughput *= u_el_metal[hit] ? vec3(fresnelConductor(cos_i, u_el_metal_n[hit].r, u_el_metal_k[hit].r),
                                         fresnelConductor(cos_i, u_el_metal_n[hit].g, u_el_metal_k[hit].g),
                                         fresnelConductor(cos_i, u_el_metal_n[hit].b, u_el_metal_k[hit].b))
                                  : u_el_reflectance[hit];
    R = reflect(R, n);
    x = p;
    cur = hit;
    ++depth;
  }
  return vec3(0.0);
}
#endif
