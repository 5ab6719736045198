// A mirror's surface maps (distance impostors, pvrr/impostor/surface_map.h) and the search for the exact surface point
// on a view ray.
#include "bilinear.glsl"
uniform sampler2D u_surf_p;       // surface maps over the parameter domain (pvrr/impostor/surface_map.h), local frame:
uniform sampler2D u_surf_du;      // position, first derivatives and unit normal
uniform sampler2D u_surf_dv;
uniform sampler2D u_surf_n;
uniform vec2 u_sm;                // texture coordinate = (s, t) * u_sm.x + u_sm.y ((s, t): normalised parameters)

// The normalised parameters of the surface point on the view ray from e with direction v (both local), from
// the fragment's interpolated ones: Gauss-Newton steps on the ray's distance from the map's point (the
// rasterised triangle lies within its sag of the surface, a few steps of its own size away), each at most a
// tenth of the domain, until the distance is below 1e-7 of the point's distance from e (float rounding), a
// step is below 1e-6 of the domain (the rest is float noise: about half the fragments never reach 1e-7), or
// the ray runs along the surface. The derivatives are read once, at the start: the steps are a few texels
// long, so the first Jacobian steers them as well (one surface-map read a step instead of three). The caller
// tests the distance left. sp: the position map at the parameters returned (bilinear(u_surf_p, ...)), read
// by each step after its move, so that the caller need not read it again (a renderer that runs every path for
// a whole SIMD group of pixels, llvmpipe, paid for that read in every pixel).
vec2 surfaceHit(vec2 uv, vec3 e, vec3 v, out vec4 sp) {
  vec2 st = uv * u_sm.x + u_sm.y;
  sp = bilinear(u_surf_p, st);
  vec3 w = sp.xyz - e;
  vec3 r = w - dot(w, v) * v;
  if (length(r) <= 1e-7 * length(w)) return uv;
  vec3 su = bilinear(u_surf_du, st).xyz, sv = bilinear(u_surf_dv, st).xyz;
  vec3 a = su - dot(su, v) * v, b = sv - dot(sv, v) * v;
  float aa = dot(a, a), ab = dot(a, b), bb = dot(b, b);
  // aa bb - ab^2 = ((su x sv) . v)^2 for vectors projected across v, computed without the cancellation.
  float c = dot(cross(su, sv), v), det = c * c;
  if (!(det > 1e-12 * aa * bb)) return uv;
  for (int i = 0; i < 6; ++i) {
    vec2 g = vec2(dot(a, r), dot(b, r));
    vec2 delta = -vec2(bb * g.x - ab * g.y, aa * g.y - ab * g.x) / det;
    float len = length(delta);
    if (len > 0.1) delta *= 0.1 / len;
    uv = clamp(uv + delta, vec2(0.0), vec2(1.0));
    st = uv * u_sm.x + u_sm.y;
    sp = bilinear(u_surf_p, st);
    if (i == 5 || len < 1e-6) break;
    w = sp.xyz - e;
    r = w - dot(w, v) * v;
    if (length(r) <= 1e-7 * length(w)) break;
  }
  return uv;
}
