#version 330 core
// Optical elements in distance-impostor mode ([Szirmay-Kalos et al.]): the envmap cube maps, whose seen
// points give each direction's distance from the cube's origin, searched per fragment for the point the exact
// reflected (or doubly refracted) ray meets (impostor_search.glsl). Variants by prepended defines:
//   LENS         the element is a lens: the ray through the glass is traced per fragment in the lens's
//                refractor height maps (lens_march.glsl, pvrr/impostor/lens_height_map.h); else a mirror, whose exact
//                surface point the view ray meets is found in its surface maps (surface_maps.glsl)
//   IMPOSTOR_ITERATIONS  the search's false-position steps
//   IMPOSTOR_CHANNELS 3  a lens's R, G and B each refracted with its own index (u_index), else the middle one only
//                (for a mirror: through the scene's lens, LENS_IN_CUBES)
//   CUBE_ELEMENTS n (2 to 4), LENS_IN_CUBES: a search that meets another element in a cube goes on in that
//                element's cubes (cube_elements.glsl)
//   IMPOSTOR_LAYERS 2  each distance map has a second, depth-peeled layer ([Umenhoffer et al.]), searched where the first
//                layer's search ends off a surface (layeredHit): the element's first draw discards those pixels,
//                LAYER_PROBE counts them, LAYER_MARCH draws them
//   CUBE_GEOMETRY  an element drawn into another element's cube: a mirror's exact surface point (a lens's mesh
//                point) as the seen point, and its normal and element id in the surface output
//   NO_SEEN_POINTS  colour only: o_seen is not an output (shaders/outputs.glsl; RendererOptions::seen_points off)
#include "element_inputs.glsl"
uniform samplerCube u_cube;       // the environment's colour from the element's origin (the envmap cube)
uniform samplerCube u_seen_cube;  // its seen points relative to that origin (u_seen_offset): the distances
uniform mat3 u_to_local;          // world directions -> the element's local frame (whose origin is the cube's)
#if IMPOSTOR_LAYERS > 1
uniform samplerCube u_cube1;      // the second layers (depth-peeled)
uniform samplerCube u_seen_cube1;
#endif
#if IMPOSTOR_LAYERS > 1
uniform vec3 u_background;        // render.background: what a ray that escapes past an occluder sees (g_escaped)
#endif
uniform int u_seen_channel;       // IMPOSTOR_CHANNELS 3: the channel whose ray gives the seen point
#if defined(LENS)
uniform int u_max_events;         // the events inside the glass the tracer follows: render.max_depth - 1
#endif
#include "outputs.glsl"
#include "shading.glsl"
#include "optics.glsl"
#include "surface_maps.glsl"
#include "lens_march.glsl"
#include "impostor_search.glsl"
#include "cube_elements.glsl"

#if !defined(CUBE_ELEMENTS)
// The element's own cubes: the colour and seen point (relative to the origin) where the ray x + d R meets them.
void envHit(vec3 x, vec3 R, out vec3 colour, out vec4 seen) {
#if IMPOSTOR_LAYERS > 1
  int layer;
  vec3 l = layeredHit(u_seen_cube, u_seen_cube1, x, R, layer);
  colour = layer == 1 ? texture(u_cube1, l).rgb : texture(u_cube, l).rgb;
  seen = g_seen_at;  // the search's read there (impostor_search.glsl)
  if (g_escaped) colour = u_background, seen = vec4(x + R * u_far, 0.0);  // past an occluder to the sky
#else
  float d_at;
  vec3 l = impostorHit(u_seen_cube, x, R, d_at);
  checkResolved(l, d_at);
  colour = texture(u_cube, l).rgb;
  seen = g_seen_at;
#endif
}
#endif

#if defined(LENS)
void main() {
#if defined(LAYER_PROBE)
  return;  // the probe counts the pixels the first draw left (pvrr/gl/cube_pass.cpp)
#endif
  vec3 n = normalize(v_normal);
  vec3 view = normalize(v_pos - u_view_origin);
  float cos_i = -dot(view, n);
  o_surface = vec4(v_pos, u_element_id);
#if defined(CUBE_GEOMETRY)
  // A lens in another element's cube: where the ray from the cube's origin meets its mesh, its outward normal
  // (the texel's weight, and the side the search enters, which then refracts in the lens's own height maps)
  // and its index.
  peel(v_pos);
  o_color = vec4(0.0);
  o_seen = vec4(v_pos, 1.0);
  o_surface = vec4(n, u_element_id);
#else
  vec3 weight = vec3(1.0);
  // In the lens's frame (its origin is the cube's). Seen from behind (the front mesh faces away), the view
  // ray enters through the back surface, between the eye and this fragment.
  vec3 x = u_to_local * (v_pos - u_seen_offset), v = u_to_local * view;
  bool from_back = cos_i <= 0.0;
  vec3 entry = entryPoint(x, v, from_back);
  vec3 c = vec3(0.0);
  vec4 seen = vec4(entry * u_to_local, 1.0);
  if (inOutline(entry.xy)) {
    vec3 n_in = normalize(lensTexel(from_back, entry.xy).yzw);
    if (dot(v, n_in) < 0.0) {
      for (int ch = 0; ch < IMPOSTOR_CHANNELS; ++ch) {
        int k = IMPOSTOR_CHANNELS == 3 ? ch : 1;
        vec3 dir;
        vec3 tr;
        bool rim;
        int spent;
        vec3 q = throughLens(entry, v, n_in, u_index[k], u_max_events, dir, tr, rim, spent);
        bool seen_here = ch == (IMPOSTOR_CHANNELS == 3 ? u_seen_channel : 0);
        if (tr == vec3(0.0)) {  // absorbed, as in the tracer: dark
          if (seen_here) seen = rim ? vec4((q + u_far * dir) * u_to_local, 0.0) : vec4(q * u_to_local, 1.0);
          continue;
        }
        // Back to world axes: the local frame's origin is the cube's.
#if defined(CUBE_ELEMENTS)
        vec4 s;
        bool again;  // met the lens once more, through a mirror: with this channel's index already
        vec3 rgb = tr * followCubes(u_self, q * u_to_local + u_seen_offset, dir * u_to_local, spent, k, s, again);
        if (seen_here) seen = vec4(s.xyz - u_seen_offset, s.w);
#else
        vec3 rgb;
        vec4 s;
        envHit(q * u_to_local, dir * u_to_local, rgb, s);
        rgb *= tr;
        if (seen_here) seen = s;
#endif
        if (IMPOSTOR_CHANNELS == 3) c[ch] = rgb[ch];
        else c = rgb;
      }
    }
  }
  o_color = vec4(weight * c, 1.0);
  o_seen = vec4(seen.xyz + u_seen_offset, seen.w + (g_unresolved ? 2.0 : 0.0));
#endif  // CUBE_GEOMETRY
}
#else
void main() {
  vec3 n = normalize(v_normal);
  vec3 view = normalize(v_pos - u_view_origin);
  float cos_i = -dot(view, n);
  o_surface = vec4(v_pos, u_element_id);
  // The exact surface point on this fragment's view ray (relative to the camera origin) and the exact normal
  // there, from the surface maps, in place of the triangle's point and the interpolated vertex normals.
  // A view ray that misses the surface within its outline (at the silhouette, where the triangles reach past
  // the surface, or past the trimmed outline) sees past the mirror, as in the tracer: the fragment is dropped
  // and the environment drawn after the elements fills the pixel. So is one whose search did not come within
  // 1e-5 of its distance (counted by the tests as holes: none in the shipped mirrors).
  vec3 e = u_to_local * (u_view_origin - u_seen_offset), vl = u_to_local * view;
  vec4 sp;  // the position map there; w: 1 inside the outline
  vec2 st = surfaceHit(v_st1.xy, e, vl, sp) * u_sm.x + u_sm.y;
  vec3 w = sp.xyz - e;
  if (sp.w < 0.5 || length(w - dot(w, vl) * vl) > 1e-5 * length(w)) discard;
#if defined(LAYER_PROBE)
  return;  // the probe counts the pixels the first draw left (pvrr/gl/cube_pass.cpp), not the mirror's misses
#endif
  vec3 pos = u_seen_offset + sp.xyz * u_to_local;
  n = normalize(bilinear(u_surf_n, st).xyz * u_to_local);
  view = normalize(pos - u_view_origin);
  cos_i = -dot(view, n);
  o_surface = vec4(pos, u_element_id);
#if defined(CUBE_GEOMETRY)
  peel(pos);
  o_color = vec4(0.0);
  o_seen = vec4(pos, 1.0);
  o_surface = vec4(n, u_element_id);
  return;
#endif
  vec3 weight = vec3(1.0);
  if (cos_i <= 0.0) {  // the mirror's back: dark (as the tracer), once, not in each additive draw
    o_color = u_additive ? vec4(0.0) : vec4(MIRROR_BACK_ALBEDO * shadeDiffuse(vec3(1.0), v_pos, -n), 1.0);
    o_seen = vec4(v_pos, 1.0);
    return;
  }
  weight = u_reflectance;
  if (u_metal)
    weight = vec3(fresnelConductor(cos_i, u_metal_n.r, u_metal_k.r), fresnelConductor(cos_i, u_metal_n.g, u_metal_k.g),
                  fresnelConductor(cos_i, u_metal_n.b, u_metal_k.b));
#if defined(CUBE_ELEMENTS)
  vec4 seen;
  bool refracted;
  vec3 c = followCubes(u_self, pos, reflect(view, n), 1, 1, seen, refracted);
#if defined(LENS_IN_CUBES) && IMPOSTOR_CHANNELS == 3
  // The scene's lens disperses: a path that met it is followed again for R and B with their own indices
  // (paths that did not are the same in every channel).
  if (refracted) {
    for (int ch = 0; ch < 3; ch += 2) {
      vec4 s;
      vec3 rgb = followCubes(u_self, pos, reflect(view, n), 1, ch, s, refracted);
      c[ch] = rgb[ch];
      if (ch == u_seen_channel) seen = s;
    }
  }
#endif
  seen.xyz -= u_seen_offset;
#else
  vec3 c;
  vec4 seen;
  envHit(pos - u_seen_offset, reflect(view, n), c, seen);
#endif
  o_color = vec4(weight * c, 1.0);
  o_seen = vec4(seen.xyz + u_seen_offset, seen.w + (g_unresolved ? 2.0 : 0.0));
}
#endif  // LENS
