// Every frame checks itself (issue 26): after the viewpoint fit, how well each patch's perspective map can
// hold the patch's rays, a verdict per patch and element, and what was done about it. A picture that pvrr mode
// cannot make right is flagged here and in the stats, never passed as good.
//
// What is measured per patch (assessFrameQuality), over the vertices the viewer sees:
//  - the map's field of view, and whether the view volume had to be limited to ViewVolumeOptions::max_fov_rad
//    (then some rays leave the map: one perspective map cannot hold a spread near 180 deg, paper 4.1);
//  - hits behind the viewpoint mixed with hits in front of it (the zooming region of a patch whose other
//    rays go forward: neither the forward nor the reversed map holds both, so a triangle across the
//    boundary interpolates between two maps' coordinates);
//  - the fit's residual angles at the vertices (ViewpointFit::rms_angle_rad);
//  - the share of seen vertices whose texture coordinates fall outside [0, 1]^2;
//  - whether the fit was accepted.
// Verdicts: good (none of the above), degraded (one of them; the picture is drawn from the map and flagged),
// fallback (the map cannot hold the patch's rays and splitting cannot help: the patch is drawn from the
// reference tracer's colours at its vertices, applyTracedFallback).
#pragma once
#include <array>
#include <string>
#include <vector>

#include "pvrr/base/math.h"

namespace pvrr {

struct ElementFrame;
class RayScene;

enum class QualityVerdict { kGood, kDegraded, kFallback };
const char* toString(QualityVerdict v);

struct PatchQuality {
  QualityVerdict verdict = QualityVerdict::kGood;
  double fov_deg = 0;        // the larger of the map's two full angles
  bool fov_limited = false;  // the volume was clamped at its max_fov, or some hit projects outside the map
  int hits_behind = 0;       // zooming hits of a forward volume that also holds hits in front
  double fit_rms_arcmin = 0, fit_max_arcmin = 0;
  double st_outside_share = 0;  // seen vertices (not TIR) whose texture coordinates leave [0, 1]^2
  // The largest angle between the outgoing rays of two corners of one seen triangle (deg): the map is exact
  // at the vertices and interpolated between them, so the error inside a triangle grows with it.
  double max_ray_spread_deg = 0;
  // The largest angle between the surface normals of two corners of one seen triangle (deg): the curvature a
  // triangle spans, which bends its rays away from a common viewpoint (a plane mirror: 0, exact).
  double max_normal_spread_deg = 0;
  // Over the seen triangles with a totally reflected corner (a lens vertex drawn from the tracer's colour,
  // interpolated with no map between): the largest angle between two corners' directions to what they show
  // (the traced seen point, or the map's hit), each from its own vertex (deg).
  double max_traced_spread_deg = 0;
  // The same over the triangles whose every such corner leaves through the lens's edge (VertexRay::edge_exit):
  // a band that is dark in the reference too, whose border no grid resolves exactly. It drives the grid's
  // refinement (refinedGridSize) as the traced spread does, but flags nothing: the band is drawn as the reference
  // draws it, its border blended across one triangle.
  double max_edge_spread_deg = 0;
  double tir_share = 0;  // seen vertices (all channels) whose ray is totally reflected or leaves through the edge
  std::string reasons;   // "" when good; otherwise what failed, "; "-separated
  std::string action;    // what was done: "none", "flagged", "drawn from traced vertex colours"
};

struct ElementQuality {
  QualityVerdict verdict = QualityVerdict::kGood;  // the worst of its seen patches
  std::string action;                              // the element's split, if any, and the patch actions
  // What the viewer should know besides the verdict, in the user's terms (pvrr/method/eye_side.h: the eye
  // behind a mirror or a lens); "" when nothing.
  std::string note;
};

struct FrameQualityLimits {
  // A fit residual this large (RMS over the patch's vertices) means the map's interpolation between
  // vertices is far from the rays: twice the saddle mirror's 90' (which renders within 2.2' median) and
  // below the 15 mm toric mirror's 460' before it is split (30' median).
  double max_fit_rms_arcmin = 180.0;
  // Texture coordinates within this of [0, 1]^2 count as inside (float round-off of the frustum's own
  // bounding hits, which sit a margin inside it).
  double st_tolerance = 1e-6;
  // The volume counts as limited when its field of view is within this of ViewVolumeOptions::max_fov_rad.
  double fov_limit_tolerance_deg = 1e-3;
  double max_fov_deg = 150.0;  // ViewVolumeOptions::max_fov_rad's default, which fitPatchViews uses
  // Triangles spanning more of the surface's normals than this interpolate their rays poorly: above the
  // concave make-up mirror's 4.8 deg (0.13' median) and the strong toric lens's 3.8 deg (3.4'), below the
  // 60 mm sphere mirror's 9.6 deg (26') and the 50 mm toric mirror's 12.5 deg (14'), at 15 x 15 vertices.
  double max_normal_spread_deg = 6.0;
  // Traced colours are interpolated with no map between the vertices: half a triangle's spread of seen
  // directions may show as error inside it, and 1 deg is the 60' of a wrong picture.
  double max_traced_spread_deg = 2.0;
};

// Adaptive refinement (issue 26 item 2; the paper's future work "adaptive subdivision"), by whole grid: the
// vertices per side that bring every seen triangle's normal spread below limits.max_normal_spread_deg, and
// the spread of traced directions across a triangle with a totally reflected corner (a lens's TIR region)
// below limits.max_traced_spread_deg, assuming each falls in proportion to the grid spacing, with at most
// max_vertices in all (the grid keeps its aspect). f's own size when no patch exceeds a limit or f is not a
// grid. {grid_u, grid_v}.
std::array<int, 2> refinedGridSize(const ElementFrame& f, int max_vertices, const FrameQualityLimits& limits = {});

// Sets each PatchView::quality and ElementFrame::quality of f (after fitPatchViews). A patch the viewer does
// not see is good. Fallback needs a split that cannot help: the patch has hits on both sides of its viewpoint,
// or its map is field-of-view limited and f.split_exhausted.
void assessFrameQuality(ElementFrame& f, const FrameQualityLimits& limits = {});

// Draws each fallback patch from the reference tracer: every vertex of the patch gets VertexRay::traced with
// the tracer's colour along its outgoing ray (a mirror: what the map would show there, before the mirror's
// reflectance, which the shader applies; a lens: the light that leaves its back surface, times the
// transmittance) and the seen point, and PatchView::draw_traced is set. max_depth: the events the tracer may
// take from the outgoing ray; <= 0 leaves the patches flagged but drawn from their maps. A lens vertex the
// eye sees from behind (lensSeenFromBehind, pvrr/method/eye_side.h) is traced from f.eye through the vertex
// instead, with f.tir_trace_depth events: its traced colour is the whole pixel's. Returns the number of
// patches drawn traced.
int applyTracedFallback(const RayScene& rays, ElementFrame& f, int max_depth);

}  // namespace pvrr
