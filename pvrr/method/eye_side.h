// Which side of an element the eye sees (issue 26 item 3: the eye on or behind an element, explained in the
// user's terms). A mirror reflects on its front side only; its back is drawn dark in every mode, as the
// reference tracer draws it, so an eye behind a mirror sees nothing reflected: the note says why. pvrr mode
// traces a lens's vertex rays into its front surface; an eye on the lens's back side gets a note and the
// frame's quality verdict says whether the picture can be trusted. applyEyeSide also flags a picture found
// wrong and passed as good (docs/robustness.md, "Held-out-style hunt"): other elements shown in a patch's map
// from a viewpoint far off the rays' directions; and it says how lens rays that leave the glass through its
// edge are drawn (vertex_stage marks them and draws them from the tracer, as the reference does).
#pragma once
#include <string>

#include "pvrr/scene/scene.h"

namespace pvrr {

struct ElementFrame;
namespace cad {
struct GridPatch;
}

struct EyeSide {
  int seen = 0;  // vertices the viewer sees (ElementFrame::in_view == 2; all when in_view is empty)
  int back = 0;  // of those, the vertices whose front surface faces away from the eye: (eye - p) . n < 0
};

// Over f's seen vertices, as seen from f.eye.
EyeSide eyeSide(const ElementFrame& f);

// "" when the eye sees the element's front side wherever it sees the element; otherwise one sentence in the
// user's terms, e.g. "the eye is behind mirror 'left' (its back side faces the eye): nothing is reflected
// toward it; it is drawn as its dark back, as the reference draws it".
std::string eyeSideNote(const Scene& scene, const ElementFrame& f);

// After assessFrameQuality, for an element traced from the observer's eye (not a nested frame): sets
// f.quality.note (eyeSideNote) and, for a lens whose back the eye sees, makes every seen patch that holds such
// a vertex a fallback patch (its vertex rays entered the front surface from the wrong side: the map would show
// nothing the lens shows); applyTracedFallback then draws those vertices from the tracer's colour along the
// eye's ray through them (pvrr/method/frame_quality.h).
void applyEyeSide(const Scene& scene, ElementFrame& f);

// Seen lens vertices (middle channel, front side facing the eye) whose internal ray leaves the glass through
// the lens's edge: marked so by vertex_stage (VertexRay::edge_exit), or with a back point beyond the outline (on
// the back surface's extension) by more than kLensEdgeExitLimitArcmin as seen from the eye (the band of rays
// that truly leave through the edge is about that wide). Over one patch's vertices, or all when patch is null.
inline constexpr double kLensEdgeExitLimitArcmin = 10.0;
// How far (m, in the lens's plane) back point `back_point` (world) of lens `el` lies beyond its outline, along
// the ray from the outline's centre; 0 or less inside it.
double lensBeyondOutline(const Element& el, const Vec3& back_point);
// Whether an internal ray whose back point is `back_point`, of a vertex `distance` (m) from the viewer, leaves the
// glass through the lens's edge by more than kLensEdgeExitLimitArcmin: the band of rays that truly leave through
// the edge near it is about as wide as its drift beyond the outline, and what matters is how wide it looks.
bool lensEdgeExit(const Element& el, const Vec3& back_point, double distance);
struct LensEdgeExits {
  int vertices = 0;
  double max_beyond_m = 0, max_band_arcmin = 0;
};
LensEdgeExits lensEdgeExits(const Element& el, const ElementFrame& f, const cad::GridPatch* patch);

// A seen patch whose vertex rays land on another element (its map shows that element as seen from the patch's
// viewpoint) is flagged when the angle at the hit between the ray and the direction from the viewpoint is over
// this (median over the patch's such vertices). The other element is recognised on any front surface: a sag
// surface solved directly, a CAD or subdivision surface by its closest point (eye_side.cpp, SurfaceProbe). Measured on
// the mirror pair at 96 x 72: 3.4' with its convex mirror (pixels 0.84' median), 14' and 27' with the mirror turned
// concave (R -1 m; pixels 39' median, p95 2489', and 63'): the pixels' error ran 2.3 to 2.7 times this measure, so 10'
// flags what nears the 60' line.
inline constexpr double kNestedParallaxLimitArcmin = 10.0;

// Whether f's vertex i is a lens vertex whose front surface faces away from f.eye.
bool lensSeenFromBehind(const Element& el, const ElementFrame& f, size_t i);

}  // namespace pvrr
