// The mean radius of curvature of a mirror's reflecting surface as UN R46 defines it (its definitions and Annex 7),
// measured on the exact surface (pvrr fov, issue 21). The arc, the three points, r_p and r below are as the EU's
// text of the same requirements has them (Directive 2003/97/EC, Annex I 1.1.1.4-1.1.1.6 and Annex II Appendix 1:
// docs/fov.md "Verification"); R46's own Annex 7 was not read, and the spherometer's span (its Figure 3) is
// recalled, not confirmed:
//  - three measuring points, at 1/3, 1/2 and 2/3 of the arc of the reflecting surface through its centre
//    (the longer of the two central arcs of the mirror's parameter square: the one parallel to segment b, or the
//    perpendicular one where that is longer);
//  - at each point i, the radii r_i (in the normal section along the arc) and r'_i (in the normal section across
//    it), each what a spherometer reads there: the radius of the circle through the point and the two points of
//    the exact surface in that normal section whose projections onto the tangent plane lie half_span_m either
//    side of it (the spherometer's feet);
//  - r_p = (r_i + r'_i) / 2 at each point and r = (r_p1 + r_p2 + r_p3) / 3.
// Radii > 0 convex as seen from the front (cad/surface.h's sign), +inf where the three points are collinear.
// On a sphere every reading is R exactly; on a torus along a circle of symmetry, its two section radii.
#pragma once
#include <array>

#include "pvrr/base/math.h"
#include "pvrr/scene/scene.h"

namespace pvrr {

struct Annex7Radius {
  struct Point {
    Vec2 square{0};            // the measuring point on the mirror's parameter square [-1, 1]^2
    Vec3 p{0};                 // the point, element frame
    double r_along_m = kInf;   // r_i: the normal section along the measuring arc
    double r_across_m = kInf;  // r'_i: the normal section across it
    double r_p_m = kInf;       // (r_i + r'_i) / 2
  };
  std::array<Point, 3> points;
  double r_m = kInf;        // (r_p1 + r_p2 + r_p3) / 3
  bool arc_along_u = true;  // the measuring arc runs along the square's first axis (else its second)
  double arc_length_m = 0;  // the measuring arc's length
  double half_span_m = 0;   // the spherometer's half span used
  // The largest |r_i - r_p| / r_p, |r'_i - r_p| / r_p over the points, and |r_pj - r| / r: the quantities R46
  // bounds (0 where every radius is infinite).
  double max_principal_deviation = 0, max_point_deviation = 0;
};

// The measurement on element `el`'s front surface. The span is reduced (halved, at most 4 times) where a foot
// would fall outside the surface's domain; pvrr::Error when it still does, or where a foot cannot be found
// (the section does not meet the surface there).
Annex7Radius annex7Radius(const Element& el, double half_span_m = 0.02);

}  // namespace pvrr
