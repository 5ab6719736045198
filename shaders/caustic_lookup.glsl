// The caustic light on the environment (pvrr/gl/caustic_pass.h): the receivers' light maps, irradiance per
// unit area of the receiving surface (W/m^2 in the scene's light units), looked up at the point's projection
// onto the receiver's plane where the point's height over that plane is the map's (its alpha: the surface's
// height, bilinear between cell centres; 0 for a planar receiver), added to the diffuse light as
// albedo * E (the shading model of shading.glsl, where a directional light of intensity 1 facing the surface
// gives albedo * 1). CAUSTICS: a light has caustics on; the maps are the layers of one RGBA32F array, each
// receiver's cells in its lower-left corner, filtered bilinearly between cell centres (the texel centres).
#if defined(CAUSTICS)
#define CAUSTIC_RECEIVERS 4
uniform sampler2DArray u_caustic_map;
uniform int u_caustic_count;                          // receivers mapped, at most CAUSTIC_RECEIVERS
uniform vec3 u_caustic_centre[CAUSTIC_RECEIVERS];     // each window's centre, relative to the camera origin
uniform vec3 u_caustic_u[CAUSTIC_RECEIVERS];          // its unit axes (u x v: the receiver's normal)
uniform vec3 u_caustic_v[CAUSTIC_RECEIVERS];
uniform vec4 u_caustic_scale[CAUSTIC_RECEIVERS];      // xy: texture coordinates per metre, zw: of the centre
uniform vec2 u_caustic_extent[CAUSTIC_RECEIVERS];     // the cells' part of the texture, texture coordinates
const float CAUSTIC_SLAB_M = 1e-3;                    // how far off the receiver's plane a point still lies on it

vec3 causticIrradiance(vec3 p) {
  vec3 e = vec3(0.0);
  for (int r = 0; r < CAUSTIC_RECEIVERS; ++r) {
    if (r >= u_caustic_count) break;
    vec3 x = p - u_caustic_centre[r];
    vec2 c = vec2(dot(x, u_caustic_u[r]), dot(x, u_caustic_v[r])) * u_caustic_scale[r].xy + u_caustic_scale[r].zw;
    if (any(lessThan(c, vec2(0.0))) || any(greaterThan(c, u_caustic_extent[r]))) continue;
    vec4 m = texture(u_caustic_map, vec3(c, float(r)));
    // The point lies on the receiver where its height over the plane is the map's (alpha: 0 for a planar one).
    if (!(abs(dot(x, cross(u_caustic_u[r], u_caustic_v[r])) - m.a) <= CAUSTIC_SLAB_M)) continue;
    e += m.rgb;
  }
  return e;
}
#endif
