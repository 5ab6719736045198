// The straight chord through a lens's glass. The shadow rule of tinted lenses (pvrr/trace/shadow_rays.h,
// pvrr/gl/shadow_pass.h) lets light cross a lens without bending it, absorbed over the length of glass it
// crosses: this is that length, in the lens's local frame (cad/sag.h).
#pragma once
#include <optional>

#include "cad/lens.h"

namespace pvrr::cad {

struct LensChord {
  double length_m = 0;
  bool through_edge = false;  // the line leaves through the edge (the outline's prism), not the other surface
};

// The length of glass a straight line crosses after entering the lens at `p`, a point of its front (surface 0)
// or back (surface 1) inside the outline, along `d` (either sense: the one that enters the glass is taken): to
// the other surface where the line meets it inside the outline, else to where it leaves the outline's prism
// (the edge band). nullopt where the line runs along the surface (within 1e-9 of its plane's tangent) or the
// other surface cannot be found (its sag undefined along the way).
std::optional<LensChord> chordInside(const LensSolid& lens, int surface, const Vec3& p, const Vec3& d);

}  // namespace pvrr::cad
