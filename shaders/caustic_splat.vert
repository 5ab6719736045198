#version 330 core
// Splats the caustic map's photons into one receiver's light map (pvrr/gl/caustic_pass.h): one point per
// texel (gl_VertexID), drawn where its exit ray first meets a mapped receiver's plane (a curved receiver: the
// receiver itself, projected onto its plane) inside that receiver's rectangle, if that receiver is this map's and the mesh the photon's exit ray meets first (the caustic map's
// direction w): light stopped by anything else lands on no map. Positions are relative to the photon mesh's anchor.
#define CAUSTIC_RECEIVERS 4
uniform sampler2D u_origin;
uniform sampler2D u_direction;
uniform sampler2D u_power;
uniform int u_side;                                // the caustic map's side, texels
uniform float u_texel_measure;                     // a texel's aperture measure (m^2 or tangent-plane area)
uniform int u_receivers;
uniform int u_receiver;                            // the receiver drawn
uniform vec3 u_centre[CAUSTIC_RECEIVERS];          // each receiver's rectangle: centre, unit axes, half sizes
uniform vec3 u_axis_u[CAUSTIC_RECEIVERS];
uniform vec3 u_axis_v[CAUSTIC_RECEIVERS];
uniform vec2 u_half[CAUSTIC_RECEIVERS];
uniform int u_mesh[CAUSTIC_RECEIVERS];             // each receiver's surface: its Scene::meshes index, or a sheet's id
uniform int u_curved[CAUSTIC_RECEIVERS];           // 1: curved (a height field over its rectangle's plane)
uniform vec2 u_window_centre;                      // the drawn map's window, receiver coordinates (m)
uniform vec2 u_window_size;
uniform vec2 u_cells;
flat out vec2 v_pixel;                             // the photon in the map's pixels (cell centres at i + 0.5)
flat out vec3 v_power;                             // its power (W)
void main() {
  gl_PointSize = 3.0;  // covers the four cells whose centres lie within one cell of the photon
  gl_Position = vec4(2.0, 2.0, 2.0, 1.0);  // outside the clip volume: no photon
  v_pixel = vec2(0.0);
  v_power = vec3(0.0);
  ivec2 t = ivec2(gl_VertexID % u_side, gl_VertexID / u_side);
  vec4 o = texelFetch(u_origin, t, 0);
  if (o.w < 0.5) return;
  vec4 dm = texelFetch(u_direction, t, 0);
  vec3 d = normalize(dm.xyz);
  int mesh = int(floor(dm.w + 0.5));
  float best = 3.0e38;
  int hit = -1;
  vec2 uv_hit = vec2(0.0);
  for (int r = 0; r < CAUSTIC_RECEIVERS; ++r) {
    if (r >= u_receivers) break;
    if (u_mesh[r] != mesh) continue;
    if (u_curved[r] != 0) {
      // The ray's first hit on the mesh itself, at the texel's distance (the power map's w, interpolated between
      // the exact hits at the photon mesh's vertices), projected onto the receiver's plane.
      float s_hit = texelFetch(u_power, t, 0).w;
      if (!(s_hit > 0.0) || s_hit >= best) continue;
      vec3 x_hit = o.xyz + s_hit * d - u_centre[r];
      vec2 uv_curved = vec2(dot(x_hit, u_axis_u[r]), dot(x_hit, u_axis_v[r]));
      if (any(greaterThan(abs(uv_curved), u_half[r]))) continue;
      best = s_hit;
      hit = r;
      uv_hit = uv_curved;
      continue;
    }
    vec3 n = cross(u_axis_u[r], u_axis_v[r]);
    float dn = dot(d, n);
    if (dn == 0.0) continue;
    float s = dot(u_centre[r] - o.xyz, n) / dn;
    if (!(s > 0.0) || s >= best) continue;
    vec3 x = o.xyz + s * d - u_centre[r];
    vec2 uv = vec2(dot(x, u_axis_u[r]), dot(x, u_axis_v[r]));
    if (any(greaterThan(abs(uv), u_half[r]))) continue;
    best = s;
    hit = r;
    uv_hit = uv;
  }
  if (hit != u_receiver) return;
  v_pixel = (uv_hit - u_window_centre) / u_window_size * u_cells + 0.5 * u_cells;
  v_power = texelFetch(u_power, t, 0).rgb * u_texel_measure;
  gl_Position = vec4(v_pixel / u_cells * 2.0 - 1.0, 0.0, 1.0);
}
