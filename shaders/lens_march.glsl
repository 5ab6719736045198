// A ray through a lens's glass in its refractor height maps (distance impostors, pvrr/impostor/lens_height_map.h): where
// the view ray enters, the march to where it meets a surface again, and the whole path through the lens.
#include "bilinear.glsl"
#include "optics.glsl"
#include "cpp_constants.glsl"
// A lens's maps: this element's (LENS), or those of the scene's one lens, which other elements' cubes show
// (LENS_IN_CUBES: followCubes refracts through it).
uniform sampler2D u_lens_front;   // refractor height maps (pvrr/impostor/lens_height_map.h): z, outward unit normal
uniform sampler2D u_lens_back;
uniform sampler2D u_lens_mask;    // 1 inside the outline, 0 outside
uniform vec4 u_hm;                // the maps' x0, y0, 1 / width, 1 / height (lens local, metres)
uniform vec2 u_hm_z;              // the back surface's lowest z and the front surface's highest z
uniform float u_hm_reach;         // the maps' diagonal: no straight path inside the glass is longer
uniform float u_far;              // render.far_distance_m: where a ray absorbed at the rim puts its seen point
uniform vec3 u_index;             // the glass's index at the R, G and B wavelengths (.y: the d line)
uniform vec3 u_absorption;        // the glass's absorption coefficient per channel, 1/m (0: clear; Element::absorption_per_m)
vec4 lensTexel(bool back, vec2 xy) {
  vec2 st = (xy - u_hm.xy) * u_hm.zw;
  return back ? bilinear(u_lens_back, st) : bilinear(u_lens_front, st);
}
bool inOutline(vec2 xy) { return bilinear(u_lens_mask, (xy - u_hm.xy) * u_hm.zw).r >= 0.5; }
// The heights of q above the back surface and below the front one: both positive inside the glass.
vec2 insideHeights(vec3 q) { return vec2(q.z - lensTexel(true, q.xy).x, lensTexel(false, q.xy).x - q.z); }

// The ray p + t d, leaving a point p of the glass's surface into the glass: where it meets a surface again,
// and which (back or front, the nearer crossing, as the tracer takes the nearer of its two surfaces). It steps
// out, doubling, to where it leaves the slab between the surfaces' extreme heights or the maps' reach; then
// false position with the Illinois halving on the crossed surface's filtered height, between the last step
// inside and the first outside (past the root at p itself, see below). The first step covers half the
// height of the surface ahead (in d.z's direction) above or below p, or 1 um when p lies on that surface
// (after a reflection off it). -1: no crossing.
float glassExit(vec3 p, vec3 d, out bool back) {
  float t_max = u_hm_reach;
  if (d.z < 0.0) t_max = min(t_max, (u_hm_z.x - p.z) / d.z);
  if (d.z > 0.0) t_max = min(t_max, (u_hm_z.y - p.z) / d.z);
  t_max = max(t_max, 1e-6);
  vec2 h0 = insideHeights(p);
  float ahead = d.z < 0.0 ? h0.x : h0.y;
  float t0 = 0.0, t1 = -1.0, t = min(max(1e-6, 0.5 * ahead / max(abs(d.z), 1e-3)), t_max);
  vec2 h1 = vec2(0.0);
  for (int k = 0; k < 32; ++k) {
    vec2 h = insideHeights(p + t * d);
    if (min(h.x, h.y) <= 0.0) {
      t1 = t, h1 = h;
      break;
    }
    t0 = t;
    if (t >= t_max) break;
    t = min(2.0 * t, t_max);
  }
  back = h1.x <= h1.y;
  if (t1 < 0.0) return -1.0;
  if (t0 > 0.0) h0 = insideHeights(p + t0 * d);
  float g0 = back ? h0.x : h0.y;
  // Outside already at the first step, from a point on the crossed surface itself (g0 below 1e-8 m: p's own
  // height, which the searches leave within ~1e-9 m of the surface; a reflection off it at a grazing angle):
  // halve the step until the ray is inside, so that false position does not return the root at p.
  for (int k = 0; k < 16 && t0 == 0.0 && g0 < 1e-8; ++k) {
    float th = 0.5 * t1;
    vec2 hh = insideHeights(p + th * d);
    if (min(hh.x, hh.y) > 0.0) {
      t0 = th, g0 = back ? hh.x : hh.y;
    } else {
      t1 = th, h1 = hh;
      back = h1.x <= h1.y;
      g0 = back ? h0.x : h0.y;
    }
  }
  if (t0 == 0.0 && g0 < 1e-8) return t1;  // outside within nanometres of p: that is the crossing
  float g1 = back ? h1.x : h1.y;
  g0 = max(g0, 0.0);
  if (g0 - g1 <= 0.0) return t1;
  int side = 0;
  for (int i = 0; i < 16; ++i) {
    t = (t0 * g1 - t1 * g0) / (g1 - g0);
    vec3 q = p + t * d;
    float zs = lensTexel(back, q.xy).x, g = back ? q.z - zs : zs - q.z;  // the crossed surface's only
    if (abs(g) < 1e-8) break;  // 10 nm: float heights at lens scale resolve ~1e-9 m, no finer
    if (g > 0.0) {
      t0 = t, g0 = g;
      if (side == 1) g1 *= 0.5;
      side = 1;
    } else {
      t1 = t, g1 = g;
      if (side == -1) g0 *= 0.5;
      side = -1;
    }
  }
  return t;
}

// Where the view ray through the fragment at x (lens local, direction v) meets the lens: the front surface
// near x (the rasterised triangle lies within its sag of the surface), or, for a lens seen from behind
// (back), the back surface between the eye and x. Secant steps on the ray's height above that surface.
vec3 entryPoint(vec3 x, vec3 v, bool back) {
  if (abs(v.z) < 1e-4) return x;
  float ta = 0.0, ga = x.z - lensTexel(back, x.xy).x;
  float tb = -ga / v.z;
  vec3 q = x + tb * v;
  float gb = q.z - lensTexel(back, q.xy).x;
  for (int i = 0; i < 6 && abs(gb) > 1e-8 && gb != ga; ++i) {  // to 10 nm, as glassExit
    float tc = tb - gb * (tb - ta) / (gb - ga);
    ta = tb, ga = gb, tb = tc;
    q = x + tb * v;
    gb = q.z - lensTexel(back, q.xy).x;
  }
  return x + tb * v;
}

// One wavelength's path through the lens (local frame) from the entry point x, where the view direction v
// meets the surface with outward normal n. It refracts in, then follows the events inside the glass as the
// tracer does up to its depth limit (max_events; render.max_depth is at most MAX_DEPTH_LIMIT): each is an
// exit (refraction, exact Fresnel) or a total internal reflection. Returns the exit point and sets the exit
// direction, the transmittance per channel and the tracer's events spent on the way (entry, inside, exit);
// transmittance: the interfaces' Fresnel terms times the glass's absorption over the path inside it,
// exp(-u_absorption L) per channel (the caller keeps the channel it traces, or all three when one path serves
// all); vec3(0): absorbed, at the returned point (the depth limit) or, with `rim`, where the ray left the
// outline (the tracer's lens has no rim surface: its seen point lies u_far along `dir`, the ray inside).
vec3 throughLens(vec3 x, vec3 v, vec3 n, float eta, int max_events, out vec3 dir, out vec3 transmittance,
                 out bool rim, out int spent) {
  float cos_i = -dot(v, n);
  vec3 d = refract(v, n, 1.0 / eta);
  float fresnel = 1.0 - fresnelDielectric(cos_i, 1.0, eta);
  float inside = 0.0;  // the path's length inside the glass
  rim = false;
  vec3 p = x;
  for (int event = 0; event < MAX_DEPTH_LIMIT; ++event) {
    bool back;
    float t = glassExit(p, d, back);
    if (t < 0.0 || !inOutline((p + t * d).xy)) {
      rim = true;
      break;
    }
    p += t * d;
    inside += t;
    if (event >= max_events) break;  // absorbed at p
    vec3 nout = normalize(lensTexel(back, p.xy).yzw);
    float c = dot(d, nout);
    if (c <= 0.0) break;  // met from outside: a path the maps cannot represent
    vec3 out_dir = refract(d, -nout, eta);
    if (out_dir != vec3(0.0)) {
      dir = out_dir;
      vec3 glass = u_absorption == vec3(0.0) ? vec3(1.0) : exp(-u_absorption * inside);
      transmittance = (fresnel * (1.0 - fresnelDielectric(c, eta, 1.0))) * glass;
      spent = event + 2;  // the entry, the events inside, the exit
      return p;
    }
    d = reflect(d, nout);  // total internal reflection
  }
  dir = d;
  transmittance = vec3(0.0);
  spent = 0;
  return p;
}
