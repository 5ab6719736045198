// Refractor height maps of a lens for the distance-impostor glass mode (`--mode impostor`; the refractor height
// maps of [Dancsik and Minarik], in place of the refractor cube map of [Szirmay-Kalos et al.], whose samples a
// thin lens's centre sees at grazing angles).
//
// A lens's two surfaces are sag graphs over its local xy plane (cad/sag.h): z = z_vertex - Z(x, y). Each map
// samples one surface on a regular grid of texel centres over the outline's bounding box, widened by
// kHeightMapMargin of its size on each side (rays inside the glass travel sideways), and stores per texel the
// local height z and the unit normal facing out of the glass: +z side for the front (eye-side) surface, -z
// side for the back, and a mask of the outline (1 inside, 0 outside: the reference tracer's lens has no rim,
// so light that reaches the surfaces beyond the outline is absorbed there). The fragment shader
// (shaders/element_impostor.frag with LENS, shaders/lens_march.glsl) finds where a ray inside the glass meets a surface again by
// stepping out and then false position on the bilinearly filtered heights.
//
// Units and frames: the lens's local frame, metres. Texel (i, j) is centred on (x0 + (i + 0.5) dx,
// y0 + (j + 0.5) dy); texture coordinate s = (x - x0) / (nx dx), t = (y - y0) / (ny dy).
#pragma once
#include <vector>

#include "pvrr/scene/scene.h"

namespace pvrr {

constexpr double kHeightMapMargin = 0.05;

struct LensHeightMap {
  int nx = 0, ny = 0;
  double x0 = 0, y0 = 0, dx = 0, dy = 0;
  // Per texel, rows of increasing y: z, then the outward unit normal (4 floats).
  std::vector<float> front, back;
  std::vector<float> inside;  // per texel: 1 where its centre lies inside the outline, else 0
  double back_z_min = 0, front_z_max = 0;  // the extreme heights over the map: bounds of a ray's search
  double reach = 0;  // the map box's diagonal: no straight path inside the glass is longer
  int clamped_texels = 0;  // texels where a sag is undefined (beyond a sphere's radius): moved inwards
};

// Samples both surfaces of a lens element on an n x m grid (n along the longer side of the box, square texels).
// Throws pvrr::Error for a mirror, or for n outside [8, 8192].
LensHeightMap buildLensHeightMap(const Element& lens, int n);

// The map's bilinear sample (z and the normal, normalised) of one surface at local (x, y): GL_LINEAR with
// clamp-to-edge in exact arithmetic (a GPU's filter weights have about 8 fractional bits, which moves a height
// by up to 1/512 of the difference between neighbouring texels, ~6e-8 m on the shipped lenses): for tests.
Vec4 sampleHeightMap(const LensHeightMap& map, bool back, double x, double y);

}  // namespace pvrr
