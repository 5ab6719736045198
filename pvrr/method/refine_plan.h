// Per-fragment refinement of pvrr mode (render.refine; docs/method.md "Per-fragment refinement"): which
// elements and patch views refine their fragments' texture coordinates, and why the others do not (the stats
// say so, as for every stage skipped).
#pragma once
#include <string>

#include "pvrr/method/vertex_stage.h"

namespace pvrr {

// A patch's viewpoint fit whose largest vertex angle is at most this (rad) interpolates exactly: every ray of
// the patch passes through the viewpoint (a plane mirror, whose fit is exact to rounding, ~1e-12), so the
// projective interpolation of its texture coordinates is the exact ray's already.
constexpr double kExactFitRad = 1e-7;

// Why element `f` (of `scene`) is not refined with `steps` secant steps, or "" when it is: off (steps 0), a
// mirror with more than one channel or a lens with more than three (spectral sets drawn additively), drawn dark
// at the depth limit, or every patch view exact or unrefinable (refineView). A lens refines each of its
// channels' exact exit rays (shaders/pvrr_refine.glsl).
std::string refineSkipReason(const Scene& scene, const ElementFrame& f, int steps);

// Why patch view pv is not refined, or "": exact already (kExactFitRad), or drawn from traced colours. A reversed
// (zooming region) map is refined: its rays pass its viewpoint and move backward along its axis, meeting the
// farthest surface its reversed depth holds first (shaders/pvrr_refine.glsl).
std::string refineViewSkipReason(const PatchView& pv);

}  // namespace pvrr
