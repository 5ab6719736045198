// The search of a distance impostor's cube ([Szirmay-Kalos et al.]) and of its depth-peeled second layer ([Umenhoffer et al.],
// IMPOSTOR_LAYERS 2) for the point a ray meets. Positions relative to the cube's origin.
// The distance from the cube's origin to what it sees in direction dir (the sky's seen point lies u_far along
// its ray: a sure overshoot for every nearer point).
float envDistance(samplerCube seen, vec3 dir) { return length(texture(seen, dir).xyz); }

// Whether some search of this fragment ended off every layer of the distance maps: the maps do not hold what
// its ray meets (a surface hidden from the cube's origin, or the search ran out of steps). The second pass
// marks its seen point (w + 2), and the renderer counts those pixels (pvrr/method/cube_quality.h).
bool g_unresolved = false;
// The first layer's search ended within 1e-3 of the distance the cube holds there (onSurface's tolerance);
// d: that distance (impostorHit's d_at).
void checkResolved(vec3 l, float d) {
  if (!(abs(length(l) - d) <= 1e-3 * d)) g_unresolved = true;
}

// [Szirmay-Kalos et al.], section 2.2: the point of the ray x + d R (x relative to the cube's origin, R unit, d >= 0) at the
// distance the impostor holds for its own direction. The first guesses assume a surface perpendicular to R at
// the distance seen along R, then a plane through the two samples; then false position between the last
// undershooting (in front of the surface) and overshooting parameters, 0 while there is none (the direction
// R itself, at infinity, stands in for a missing overshoot, as in the paper).
// falsePosition: that search from parameter dl, with the last undershooting (dun, ratio |l| / distance pun) and
// overshooting (dov, pov) parameters so far (0: none); r1 the distance the impostor holds along R. d_at: the
// distance the impostor holds at the point returned, which the search reads there (it stopped on a ratio
// within 1e-6 of 1, or its steps ran out and it read the point of the last), so that the caller's test of
// the result (onSurface, checkResolved) need not read it again. That read is the loop's last pass: a renderer
// that runs a branch's code for a whole SIMD group of pixels (llvmpipe masks lanes; it does not jump) paid for
// the caller's read after the loop in every pixel, and pays for this pass only in groups where some pixel's
// search ran out of steps.
// g_seen_at: the texel itself (the seen point there), which the caller would otherwise read again at the same
// coordinates for its seen point (element_impostor.frag envHit, cube_elements.glsl): the same value, one cube
// read fewer for every pixel.
vec4 g_seen_at = vec4(0.0);
vec3 falsePosition(samplerCube seen, vec3 x, vec3 R, float r1, float dl, float dun, float pun, float dov, float pov,
                   out float d_at) {
  vec3 l = x + R * dl;
  d_at = -1.0;
  for (int i = 0; i <= IMPOSTOR_ITERATIONS; ++i) {
    vec4 s = texture(seen, l);
    float d = length(s.xyz), llp = length(l) / d;
    if (abs(1.0 - llp) < 1e-6 || i == IMPOSTOR_ITERATIONS) {  // as close as float distances resolve, or the last
      d_at = d;
      g_seen_at = s;
      break;
    }
    float ddl;
    if (llp < 1.0) {  // undershooting
      dun = dl, pun = llp;
      ddl = dov == 0.0 ? r1 * (1.0 - llp) : (dl - dov) * (1.0 - llp) / (llp - pov);
    } else {          // overshooting
      dov = dl, pov = llp;
      ddl = dun == 0.0 ? r1 * (1.0 - llp) : (dl - dun) * (1.0 - llp) / (llp - pun);
    }
    dl = max(dl + ddl, 0.0);
    l = x + R * dl;
  }
  if (dot(l, l) > 0.0) return l;
  d_at = r1;
  g_seen_at = texture(seen, R);  // (rare: a read here costs the pixels of its SIMD group only)
  return R;  // x at the cube's origin and d = 0: the direction itself
}
// r1: the distance the impostor holds along R; d_at and g_seen_at as falsePosition's.
vec3 impostorHit(samplerCube seen, vec3 x, vec3 R, out float r1, out float d_at) {
  r1 = envDistance(seen, R);
  float dp = r1 - dot(x, R);
  vec3 p = x + R * dp;
  float ppp = length(p) / envDistance(seen, p);
  float dun = 0.0, dov = 0.0, pun = ppp, pov = ppp;
  if (ppp < 1.0) dun = dp; else dov = dp;
  float dl = max(dp + r1 * (1.0 - ppp), 0.0);
  return falsePosition(seen, x, R, r1, dl, dun, pun, dov, pov, d_at);
}
vec3 impostorHit(samplerCube seen, vec3 x, vec3 R, out float d_at) {
  float r1;
  return impostorHit(seen, x, R, r1, d_at);
}

#if IMPOSTOR_LAYERS > 1
// The layered distance maps of [Umenhoffer et al.], for what an occluder near the element hides from the cube's
// origin ([Szirmay-Kalos et al.], Fig. 6): the second layer holds the nearest surfaces beyond the first (depth
// peeling).
//
// Whether l, found by a search on the ray from x along R, lies on a surface of the layer: the search came within
// 1e-3 of the distance there, and it did not end where the ray passes behind a depth edge. There the layer's
// distance jumps (1.5 texels to either side, across the ray's sweep, the farther more than 1.5 x the nearer),
// the filtered distance blends the two surfaces, and the search ends between them, at a point on neither:
// more than 1.25 x the nearer's distance and less than 0.8 x the farther's.
// d: the distance the layer holds at l (falsePosition's d_at).
bool onSurface(samplerCube seen, vec3 l, vec3 R, float d) {
  float len = length(l);
  if (!(abs(len - d) <= 1e-3 * d)) return false;
  vec3 u = l / len, t = R - dot(R, u) * u;
  float tl = length(t);
  if (tl < 1e-4) return true;  // the ray runs along the origin's line of sight: it sweeps no edge
  t *= 3.0 / (float(textureSize(seen, 0).x) * tl);  // 1.5 texels at a face's centre (2 / size a texel)
  float d0 = envDistance(seen, u - t), d1 = envDistance(seen, u + t);
  float dn = min(d0, d1), df = max(d0, d1);
  return !(df > 1.5 * dn && len > 1.25 * dn && len < 0.8 * df);
}

// |p| / the layer's distance in p's direction (s: the layer's texel there): below 1 in front of the layer,
// above behind it.
float sampleRatio(vec3 p, vec4 s) {
  float len = length(p);
  return len > 0.0 ? len / length(s.xyz) : 0.0;
}
float rayRatio(samplerCube seen, vec3 p) { return sampleRatio(p, texture(seen, p)); }

// A crossing of a layer between the march's parameters d0 (ratio r0 < 1) and d1 (ratio r1 >= 1; at_end: the
// ray's end at infinity), refined by false position; whether it lies on the layer's surface. rR: the distance
// the layer holds along R.
bool layerCrossing(samplerCube seen, vec3 x, vec3 R, float rR, float d0, float r0, float d1, float r1, bool at_end,
                   out vec3 l) {
  float dl = at_end ? max(d0 + rR * (1.0 - r0), d0) : d0 + (d1 - d0) * (1.0 - r0) / (r1 - r0);
  float d_at;
  l = falsePosition(seen, x, R, rR, dl, d0, r0, at_end ? 0.0 : d1, r1, d_at);
  return onSurface(seen, l, R, d_at);
}

// The first hit of the ray x + d R (x relative to the cube's origin, R unit) in the two layers; `layer`: which
// holds it. The first layer's search as above; where its result is not on a surface, [Umenhoffer et al.]'s linear search:
// LAYER_STEPS steps over both layers, uniform in the direction from the origin (from x's to R's: d = |x| t /
// (1 - t)), each bracket of an undershooting and an overshooting sample refined by false position and kept if
// on a surface, the nearer of the two layers' first. Nothing kept: the first layer's result. The march starts
// a quarter step out (t = 1 / (4 LAYER_STEPS)), so that no bracket starts at d = 0, which falsePosition
// reads as no undershoot yet.
//
// Where no bracket lies on a surface, and the march's last finite sample (15 |x| along R) lies, in each layer,
// behind its surface or in front of its sky, the ray has gone past every surface the maps hold without meeting
// one: it passed behind the occluders (crossing the layers only at depth edges) and escapes (g_escaped); the
// caller shows the background along R, with the tracer's far seen point. What two layers cannot hold (a
// surface hidden behind two occluders from the cube's origin) is taken for the sky there. Before, the search
// ended on the occluder's texel at R, on no surface of the ray: in two facing mirrors
// (tests/data/stress/mirror-tunnel.json) the back mirror showed the front mirror, and went on in its cubes
// from a point off it, where its rays pass behind the red ball and over the front mirror's edge to the sky.
bool g_escaped = false;
//
// A first-layer search that ends on the sky may have passed a surface the ray meets first: its first guesses
// start from the distance the layer holds along R, which for the sky is render.far_distance_m, and the ratio
// there is 1 whatever lies before. Where the ray from x (off the cube's origin) meets a surface that the
// origin sees past (a floor that ends before R's direction from the origin does), the search ended on
// the sky (the mirror tunnel's front mirror showed the sky for the floor). skyPastSurface: some of 8 samples
// of the ray, uniform in the direction from the origin as the march's, lies behind the first layer; then the
// march decides. Only where the search goes on in other elements' cubes (CUBE_ELEMENTS), whose rays start
// anywhere on another mirror, far from the cube's origin: with one element the check changed no pixel of the
// shipped scenes and cost 14 % of car-mirror's impostor frame (CPU time, 1280 x 720, eye orbiting: 51.7 ->
// 59.0 ms, medians of 3 interleaved runs; without it 49.8 -> 51.0 ms, within the runs' noise).
bool skyPastSurface(samplerCube seen0, vec3 x, vec3 R) {
#if !defined(CUBE_ELEMENTS)
  return false;  // one element: its rays start within its outline of the cube's origin (see above)
#endif
  float a = length(x);
  for (int i = 0; i < 8; ++i) {
    float t = (float(i) + 0.5) / 8.0;
    if (rayRatio(seen0, x + R * (a * t / (1.0 - t))) >= 1.0) return true;
  }
  return false;
}
const int LAYER_STEPS = 16;
vec3 layeredHit(samplerCube seen0, samplerCube seen1, vec3 x, vec3 R, out int layer) {
  layer = 0;
  g_escaped = false;
  float rR0, d_at;
  vec3 l0 = impostorHit(seen0, x, R, rR0, d_at);
  if (onSurface(seen0, l0, R, d_at) && !(g_seen_at.w < 0.5 && skyPastSurface(seen0, x, R))) return l0;
#if !defined(LAYER_MARCH)
  discard;  // the second draw, LAYER_MARCH, shades this pixel (pvrr/gl/cube_pass.cpp)
  return l0;
#else
  vec4 s_l0 = g_seen_at;  // (g_seen_at: the texel of the layer at the point returned)
  float a = length(x), t0 = 0.25 / float(LAYER_STEPS), d_prev = a * t0 / (1.0 - t0);
  vec3 p0 = x + R * d_prev;
  vec4 s0 = texture(seen0, p0), s1 = texture(seen1, p0);
  // Each sample's ratios (rayRatio) and texels' w (0: the sky) in the two layers.
  vec2 r_prev = vec2(sampleRatio(p0, s0), sampleRatio(p0, s1)), w_prev = vec2(s0.w, s1.w);
  float rR1 = envDistance(seen1, R);
  vec2 r_last = r_prev, w_last = w_prev;  // at the last finite sample
  // The steps run in an inner loop that only looks for the next bracket (two cube reads a step); its
  // refinement runs after it, once per bracket. A renderer that runs a branch's code for a whole SIMD group of
  // pixels whether or not any of them takes it (llvmpipe: it masks lanes, it does not jump) paid for both
  // layers' refinements and surface tests at every step when they sat in the step loop: 10 cube reads a step
  // where 2 are needed. The brackets found and their order are those of one loop.
  int i = 1;
  for (int bracket = 0; bracket < LAYER_STEPS && i <= LAYER_STEPS; ++bracket) {
    bool at_end = false;
    float d = 0.0;
    vec2 r = vec2(0.0), w = vec2(0.0);
    for (; i <= LAYER_STEPS; ++i) {
      at_end = i == LAYER_STEPS;
      if (at_end) r_last = r_prev, w_last = w_prev;
      float t = float(i) / float(LAYER_STEPS);
      d = at_end ? 0.0 : a * t / (1.0 - t);
      vec3 p = x + R * d;
      vec4 s0 = texture(seen0, p), s1 = texture(seen1, p);
      r = at_end ? vec2(2.0) : vec2(sampleRatio(p, s0), sampleRatio(p, s1));
      w = vec2(s0.w, s1.w);
      if ((r_prev.x < 1.0 && r.x >= 1.0) || (r_prev.y < 1.0 && r.y >= 1.0)) break;
      d_prev = d, r_prev = r, w_prev = w;
    }
    if (i > LAYER_STEPS) break;  // no bracket left
    vec3 l, best = l0;
    vec4 s_best = s_l0;
    float d_best = -1.0;
    if (r_prev.x < 1.0 && r.x >= 1.0 && layerCrossing(seen0, x, R, rR0, d_prev, r_prev.x, d, r.x, at_end, l))
      best = l, d_best = dot(l - x, R), s_best = g_seen_at;
    if (r_prev.y < 1.0 && r.y >= 1.0 && layerCrossing(seen1, x, R, rR1, d_prev, r_prev.y, d, r.y, at_end, l) &&
        (d_best < 0.0 || dot(l - x, R) < d_best)) {
      layer = 1;
      return l;
    }
    if (d_best >= 0.0) {
      g_seen_at = s_best;
      return best;
    }
    d_prev = d, r_prev = r, w_prev = w;
    ++i;
  }
  if ((r_last.x >= 1.0 || w_last.x < 0.5) && (r_last.y >= 1.0 || w_last.y < 0.5)) {
    g_escaped = true;
    return R;
  }
  g_unresolved = true;  // no bracket on either layer's surface
  g_seen_at = s_l0;
  return l0;
#endif
}
#endif
