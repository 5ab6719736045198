// Surface maps of a mirror for the distance-impostor mode (`--mode impostor`): its exact surface sampled over
// its parameter domain, so that each fragment reflects at the exact surface point its view ray meets, with the
// exact normal there, instead of at the rasterised triangle's point with the interpolated vertex normals
// (whose error falls only quadratically with the vertex spacing: the saddle mirror's impostor median was
// 1.74' at 15 x 15 vertices, 0.19' at 45 x 45).
//
// Sample (i, j) of an n x n map is the surface at u = u0 + i (u1 - u0) / (n - 1), v = v0 + j (v1 - v0) / (n - 1)
// (the domain's corners are samples): position, the first derivatives with respect to the normalised
// parameters s = (u - u0) / (u1 - u0) and t = (v - v0) / (v1 - v0) (parameters far from 0, such as a NURBS's
// knots, then cost the shader no float precision) and the exact unit normal (oriented as cad's surface
// normal), in the element's local frame, metres; the position's w is 1 where (u, v) lies inside the element's
// outline (always without one), else 0. Where the surface cannot be evaluated (a sag beyond a sphere's
// radius, in a corner of the outline's box) or has no normal, the sample is taken from the nearest point
// towards the domain's centre that can, and marked outside. Texture coordinate of normalised parameter s:
// s (n - 1) / n + 0.5 / n, so that bilinear filtering interpolates between the samples. The fragment shader
// (shaders/element_impostor.frag, shaders/surface_maps.glsl) starts from the fragment's interpolated (s, t) and takes Gauss-Newton
// steps on the distance of the map's point from its view ray.
#pragma once
#include <vector>

#include "cad/outline.h"
#include "cad/surface.h"

namespace pvrr {

struct SurfaceMap {
  int n = 0;
  double u0 = 0, v0 = 0, u1 = 1, v1 = 1;
  // Per sample, rows of increasing v: xyz and w (4 floats each); w: the outline mask for the position, 0 for
  // the others.
  std::vector<float> position, du, dv, normal;
  int moved_samples = 0;  // samples taken from a point moved inwards
};

// Throws pvrr::Error for n outside [2, 4096], or when a sample finds no evaluable point with a normal on the
// way to the domain's centre. `outline`: in the surface's parameter plane (Element::outline), or null.
SurfaceMap buildSurfaceMap(const cad::Surface& surface, int n, const cad::Outline* outline = nullptr);

// The map's bilinear sample at parameter (u, v) (GL_LINEAR with clamp-to-edge; the shader computes it so, with
// float weights): position, derivatives (normalised parameters, as stored), the normal (normalised) and the
// outline mask: for tests.
struct SurfaceMapSample {
  Vec3 position, du, dv, normal;
  double inside = 0;
};
SurfaceMapSample sampleSurfaceMap(const SurfaceMap& map, double u, double v);

}  // namespace pvrr
