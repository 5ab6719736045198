// Local adaptive refinement (issue 26 item 2; the paper's future work "adaptive subdivision"): which base
// quads of an element's grid to subdivide, and how deep, so that the vertices go where the rays diverge
// (cad/local_refine.h makes the conforming tessellation; the renderer applies it, PvrrPass::refineElement).
#pragma once
#include <cstdint>
#include <vector>

#include "pvrr/method/frame_quality.h"
#include "pvrr/trace/ray_scene.h"

namespace pvrr {

struct ElementFrame;

// Per base quad of f.grid (cad::Tessellation::quad_levels' order): the largest spread over its limit (1: at
// the limit) among the quad's seen triangles, with the measures of PatchQuality: the angle between two
// corners' surface normals over limits.max_normal_spread_deg, or, for a triangle with a totally reflected
// corner, between two corners' directions to what they show over limits.max_traced_spread_deg. 0 for a quad
// with no seen triangle. Works on a plain grid and on a locally refined one (the quad's sub-triangles).
std::vector<double> quadSpreadRatios(const ElementFrame& f, const FrameQualityLimits& limits = {});

// Per base quad of f.grid (after fitPatchViews): the largest angle (arcmin) at the centroid of a seen triangle
// between what its patch's map shows there (the corners' texture coordinates interpolated projectively, as the
// second pass does) and the reference: the tracer's seen point along the eye's ray through the flat
// triangle's centroid, both as seen from the patch's viewpoint. The error PVRR makes inside a triangle, where
// it is largest for a smooth surface; it falls with the square of the spacing. Triangles with a totally
// reflected corner, drawn traced, and rays that miss the element are left out (0).
// max_probes > 0: at most about that many triangles, evenly strided over the seen ones (a sample: the other
// quads read 0).
std::vector<double> quadMapErrors(const RayScene& rays, const ElementFrame& f, size_t max_probes = 0);

struct LocalSplit {
  std::vector<uint8_t> levels;  // per base quad, 2:1 balanced (cad::balanceQuadLevels)
  bool changed = false;         // differs from f.grid's levels (all 0 for a plain grid)
  int quads_split = 0;          // base quads at a level above 0
  int quads_seen = 0;           // base quads with a seen triangle
  int max_level = 0;
  size_t vertices = 0;          // of the refined tessellation
  bool budget_limited = false;  // some quad is left above `target` for the vertex budget (or the finest level)
  // Without the budget: the local split's vertices for `target`, and the uniform grid's that brings the worst
  // quad to it (the grid spacing divided by its ratio over target, as refinedGridSize assumes).
  size_t target_vertices = 0, uniform_vertices = 0;
  // Over the seen quads: the largest ratio and the median (how much the error concentrates).
  double ratio_max = 0, ratio_median = 0;
  // chooseLocalSplitByMapError on a grid no spread limit triggers: the median map error (arcmin) of its sample
  // of seen quads (kBroadMapErrorProbes), and whether it was over the broad limit (which triggered it).
  double sampled_median_arcmin = 0;
  bool broad_map_error = false;
};

// The levels that bring each quad's ratio (quadSpreadRatios) to `target` or below, assuming it halves with each
// level (the spreads fall in proportion to the spacing), starting from f.grid's own levels, which are never
// lowered (the grid cache keeps a refinement while the surface stays). Nothing changes unless some quad is
// over its limit (ratio > 1). Within max_vertices: when the levels for `target` need more, the worst quads go
// first (the levels for the lowest target above it that fits). Needs a grid frame (f.grid.grid_u >= 2).
LocalSplit chooseLocalSplit(const ElementFrame& f, int max_vertices, const FrameQualityLimits& limits = {},
                            double target = 0.9);

// The map error (quadMapErrors, arcmin) a quad may keep; above it the map-error split refines the quad.
inline constexpr double kLocalSplitMapErrorArcmin = 6.0;
// The spread limits see curvature, not every cause of a map that errs: the shipped spectacle lens turned 15 deg
// off the gaze (about the eye's centre of rotation) spans 3 deg of normals (limit 6), yet its 24 x 24 grid
// interpolates the strongly varying oblique rays with a median quad error of 3.7' (pictures 2.9' median against
// 0.67' straight; a -4 D lens so turned 5.3' and 4.2'). So a lens's plain grid that no spread limit triggers has
// a sample of its seen quads' map errors measured (at most kBroadMapErrorProbes traced rays a frame), and when
// their median is over kBroadLensMapErrorArcmin its interpolation errs broadly, not only at the picture's edges
// (where single quads err by tens of minutes in good pictures), and the map-error split runs, to that limit.
// The shipped lenses' medians: 0.01-1.1' in 4:3 pictures (turned 10 deg: 2.7'); the spectacle lens in a 16:9
// picture 4.9', whose wider view takes in the periphery (pictures 4.1' -> 0.47' median). Not for mirrors: a mirror whose map errs
// broadly without a spread limit reached is one whose map shows another mirror from the wrong point (the
// concave mirror facing the wall mirror: 5' and up), which no split mends and whose split would hide the
// nested-parallax flag (eye_side.h) in smaller patches (measured: 39' -> 48' median, unflagged); the shipped
// mirrors' medians are 0.5-0.9', the saddle's 3.6'.
inline constexpr double kBroadLensMapErrorArcmin = 2.0;
inline constexpr size_t kBroadMapErrorProbes = 96;

// The same choice from the reference (quadMapErrors): when some quad is over its spread limit (the trigger of
// chooseLocalSplit and refinedGridSize, so an element neither refines keeps its grid), each quad is refined
// until its map error, falling 4 x a level, is below target^2 x kLocalSplitMapErrorArcmin, or for a triangle with
// a totally reflected corner its traced spread below target x its limit; worst first within max_vertices.
// `refined`: the element's grid was refined already (uniformly), which triggers it too. A plain grid (not
// locally refined) that neither triggers is triggered by a broad map error (its sample's median over
// broad_limit_arcmin: kBroadLensMapErrorArcmin for a lens; infinite, never, for a mirror).
LocalSplit chooseLocalSplitByMapError(const RayScene& rays, const ElementFrame& f, int max_vertices,
                                      const FrameQualityLimits& limits = {}, double target = 0.9,
                                      bool refined = false, double broad_limit_arcmin = kInf);

}  // namespace pvrr
