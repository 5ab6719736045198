// The CPU stages of PVRR for one optical element (paper section 3): per-vertex rays traced exactly into the
// scene ("vertex-rays"), one least-squares virtual viewpoint and view volume per patch and colour channel
// ("viewpoint-fit"), and each vertex's texture coordinates: the projection of its exact hit point through
// that patch's virtual camera.
#pragma once
#include <array>
#include <optional>
#include <string>
#include <vector>

#include "cad/tessellate.h"
#include "pvrr/base/names.h"
#include "pvrr/trace/ray_scene.h"
#include "pvrr/method/frame_quality.h"
#include "pvrr/method/view_volume.h"
#include "pvrr/method/viewpoint.h"
#include "pvrr/trace/ray_scene.h"

namespace pvrr {

enum class VertexStatus { Hit, Escape, Tir };
// The names in pvrr vertices' CSV ("status" column).
inline constexpr NameTable<VertexStatus, 3> kVertexStatusNames = {
    {{VertexStatus::Hit, "hit"}, {VertexStatus::Escape, "escape"}, {VertexStatus::Tir, "tir"}}};
constexpr const NameTable<VertexStatus, 3>& nameTable(VertexStatus) { return kVertexStatusNames; }
static_assert(namesAreUnique(kVertexStatusNames));

// One vertex of the element's front surface, for one colour channel.
struct VertexRay {
  Vec3 dir{0};     // outgoing direction into the scene (unit)
  Vec3 origin{0};  // where the outgoing ray starts: the vertex (mirror) or the back-surface point (lens)
  VertexStatus status = VertexStatus::Escape;
  Vec3 hit{0};     // the exact hit point, or the far point of an escaping ray
  // Lenses: the direction inside the glass, the back-surface point and its unit normal.
  Vec3 internal_dir{0}, back_point{0}, back_normal{0};
  // Lens: Fresnel transmittance of both interfaces times, for a tinted lens, the glass's absorption over the
  // internal path vertex -> back_point, exp(-alpha_c L) per RGB channel c (Element::absorption_per_m).
  Vec3 transmittance{1.0};
  // A lens vertex whose internal ray is totally reflected at the back surface (status Tir; transmittance 0)
  // when VertexStageOptions::tir_trace_depth > 0: what the reference tracer shows along the vertex's
  // incoming ray at this channel's wavelength (the light reflected inside the lens and leaving through the
  // front or beyond), its colour and seen point. The second pass draws it there, interpolated towards the
  // neighbouring vertices' map colours, in place of dark.
  bool traced = false;
  Vec3 traced_color{0}, traced_seen{0};
  // A lens vertex whose internal ray meets the back surface's extension beyond the outline by more than
  // kLensEdgeExitLimitArcmin as seen from the viewer (eye_side.h lensEdgeExit): it leaves through the edge.
  // Status Tir as above (traced where a depth budget is given); back_point holds the extension's point.
  bool edge_exit = false;
};

// One patch's virtual camera. With dispersion the channels share the viewpoint and the first pass (fitted
// to the middle channel's rays, as in the paper) and differ only in their texture coordinates.
struct PatchView {
  int patch = 0;       // index into ElementFrame::grid_patches
  ViewpointFit fit;
  ViewVolume volume;
  std::vector<std::vector<Vec2>> st;  // [channel][vertex of the patch, in GridPatch::vertices order]
  // Projective weight per vertex: the clip w of the vertex itself in the patch's camera. The second pass
  // interpolates (s q, t q, q) and divides per fragment, which is exact for a plane mirror (the vertex, the
  // viewpoint and the hit are collinear) and follows the surface's own projection for curved ones. All 1
  // (plain affine interpolation, as in the paper) when some vertex lies behind the viewpoint.
  std::vector<double> q;
  int rays_excluded = 0;  // flagged (tir / edge) rays left out of the fit
  int rays_out_of_view = 0;  // rays of vertices outside the viewer's clip volume, left out of the view volume
  // Where the viewer's clip volume cuts the patch's triangles that it sees in part: a point of a triangle (its
  // corners, indices into GridPatch::vertices, and barycentric weights). The view volume holds the rays
  // interpolated there in place of the rays of the corners outside the viewer's view, so the map covers what
  // the image shows rather than whole edge triangles (a spectacle lens tessellated 24 x 24 has triangles of
  // ~10 degrees at 12 mm from the eye).
  struct ViewEdgeSample {
    glm::u32vec3 corners{0};
    Vec3 weights{0};
  };
  std::vector<ViewEdgeSample> view_edge;
  bool in_view = true;    // false: the viewer sees none of the patch (its map need not be rendered)
  PatchQuality quality;   // assessFrameQuality's verdict on this patch's map
  // Drawn from its vertices' traced colours (VertexRay::traced, applyTracedFallback) instead of its map.
  bool draw_traced = false;
};

// One colour channel (wavelength sample) of the vertex stages. The second pass sums the channels' warped
// maps: colour = sum_c rgb_weight_c (*) transmittance_c (*) map(st_c) ((*): per RGB component).
struct ChannelSpec {
  double wavelength_nm = 0;  // <= 0: the d line
  // Unset: channel c of three is RGB channel c (unit weight, RGB mode); a single channel has (1, 1, 1).
  std::optional<Vec3> rgb_weight;
  ChannelSpec() = default;
  ChannelSpec(double wavelength, std::optional<Vec3> weight = std::nullopt)
      : wavelength_nm(wavelength), rgb_weight(weight) {}
};

// The colour weight of channel c of `channels` (ChannelSpec::rgb_weight, or its default).
Vec3 channelWeight(const std::vector<ChannelSpec>& channels, size_t c);

// THE choice of colour channels for one element, used by every raster path and report: one channel at the
// d line with weight (1, 1, 1) for a mirror, for a lens whose material disperses not ("dispersion": false)
// and when `dispersion` is Off; Rgb: the three channels of spectrum.h's RGB mode (C, d, F lines, unit
// weights); Spectral: the `spectral_samples` samples of spectrum.h's spectral mode with their weights,
// the same the tracer's spectral mode sums. Throws pvrr::Error for too few samples.
std::vector<ChannelSpec> dispersionChannels(const Scene& scene, int element, DispersionMode dispersion,
                                            int spectral_samples);
// The same with the dispersion mode by name (kDispersionModeNames); throws pvrr::Error for another name.
std::vector<ChannelSpec> dispersionChannels(const Scene& scene, int element, const std::string& dispersion,
                                            int spectral_samples);
// The same with the scene's own settings (RenderSettings::dispersion and spectral_samples).
std::vector<ChannelSpec> dispersionChannels(const Scene& scene, int element);

struct VertexStageOptions {
  // 1 (no dispersion), 3 (R, G, B) or N spectral samples. The renderer (pvrr/gl/renderer.h) chooses per
  // element with dispersionChannels() when this is empty.
  std::vector<ChannelSpec> channels{ChannelSpec{}};
  // Per frame the fit stops at a relative cost decrease of 1e-2: every vertex is exact whatever the
  // viewpoint, which only shapes the interpolation between vertices (docs/method.md). Measured at 640 x 480,
  // 1e-2 against 1e-6: median errors within 0.003' (car 0.7917' -> 0.7916', saddle 2.3301' -> 2.3324',
  // concave 0.1333' -> 0.1334', spectacle 0.6614' both); the car mirror's 45 x 45 fit takes 2 Gauss-Newton
  // iterations instead of 7 (its cost within 0.4 % of the optimum). Acceptance is checked as ever.
  ViewpointOptions viewpoint = [] {
    ViewpointOptions o;
    o.function_tolerance = 1e-2;
    return o;
  }();
  double max_patch_fov_rad = 0;  // overrides the element's when > 0
  // Adaptive refinement (applied by the renderer, PvrrPass::refineElement): the most vertices a refined grid
  // may have; 0: none. 4096 holds the 63 x 63 grid at which the 50 mm toric mirror renders within 0.8' median.
  int refine_max_vertices = 4096;
  // true: after the whole grid's refinement (refinedGridSize), split the base quads whose maps still err, each
  // to its own level, within the same budget (chooseLocalSplitByMapError, pvrr/method/local_split.h; conforming,
  // cad/local_refine.h). On by default: against the uniform refinement alone it improves every stiff case
  // measured (toric mirror 2.45' -> 1.23' median, -30 D toric lens 4.04' -> 1.05', the TIR lens unchanged),
  // and it triggers only where the uniform refinement does, so elements that need none keep their grid. At
  // equal vertex counts it wins where the error concentrates (the lens: 1.05' at 1677 vertices against 1.76'
  // at 2025 uniformly), not where the surface bends evenly (the toric mirror: 1.23' at 3428 against 0.85' at
  // 3364), docs/robustness.md. Costs one traced ray per seen triangle a frame on a refined element.
  bool refine_locally = true;
  int max_patch_splits = 4;      // doublings per direction for the automatic split
  // World -> clip of the camera that draws the element (the observer's, or the map camera of the element
  // that shows it). When set, each patch's view volume holds only what that camera sees (ElementFrame::
  // in_view): the rays of the vertices inside its view and the rays interpolated where its view cuts a
  // triangle (PatchView::view_edge), so the map spends its texels on what is seen: a spectacle lens 12 mm from
  // the eye spans ~150 deg, of which a 50 deg view sees about a third across. The viewpoint is still fitted
  // to all the patch's rays. Unset: all.
  std::optional<Mat4> viewer_clip;
  // Events the reference tracer may still take from a vertex's incoming ray (the scene's render.max_depth
  // for the observer's view, less the events before it for an element seen in another's map). > 0: a lens
  // vertex whose ray is totally reflected inside the lens gets the tracer's answer (VertexRay::traced);
  // 0: it stays dark.
  int tir_trace_depth = 0;
  // A mirror vertex's ray that cannot meet its own mirror (RayScene::intersectBeside: the mirror's candidate
  // tessellation lies wholly behind the vertex's tangent plane, as a convex mirror's does, and the ray leaves
  // in front of it) is traced beside the mirror, with the same hit, without traversing the mirror's
  // candidates, among which every such ray starts. false traces every ray through the whole scene, for the
  // tests that compare.
  bool beside_own_mirror = true;
};

struct ElementFrame {
  int element = -1;
  Vec3 eye{0};
  cad::Tessellation grid;                   // local coordinates (from cad)
  std::vector<Vec3> world_pos, world_normal;
  std::vector<ChannelSpec> channels;         // the channels the rays were traced for
  std::vector<std::vector<VertexRay>> rays;  // [channel][vertex]
  std::vector<cad::GridPatch> grid_patches;
  std::vector<PatchView> views;              // one per patch
  double rays_ms = 0, fit_ms = 0;
  int rays_beside = 0;  // rays traced beside their own mirror (VertexStageOptions::beside_own_mirror), all channels
  int patches_u = 1, patches_v = 1;
  std::string split_note;                    // why patches were split, if they were
  bool split_exhausted = false;              // the field-of-view split stopped at the finest split the grid allows
  ElementQuality quality;                    // assessFrameQuality's verdict (set by fitPatchViews)
  // Per vertex: non-zero when a triangle holding it can be seen by VertexStageOptions::viewer_clip (empty:
  // all vertices, no viewer given): 2 inside the viewer's clip volume, 1 outside it (a corner of a triangle
  // seen in part). Vertices of triangles the viewer cannot see get texture coordinates too, but they shape
  // no pixel.
  std::vector<char> in_view;
  int tir_trace_depth = 0;  // VertexStageOptions::tir_trace_depth the rays were traced with
};

// Tessellates the element (its tess_u x tess_v grid) in local and world coordinates. `grid`: that
// tessellation when the caller kept it (the same surface, grid and outline; ElementGridCache), posed anew.
ElementFrame prepareElement(const Scene& scene, int element, const cad::Tessellation* grid = nullptr);

// The elements' tessellations, kept while each element's front surface, grid size and outline stay the
// same: prepareElement's costly part (evaluating a NURBS grid with curvatures), which a rigid element needs
// once, whatever its pose.
class ElementGridCache {
 public:
  // The element's tessellation: its own grid, or the one refine() chose, kept until the element's surface,
  // grid size or outline changes.
  const cad::Tessellation& get(const Scene& scene, int element);
  // Tessellates the element at tess_u x tess_v from now on (adaptive refinement, refinedGridSize).
  void refine(const Scene& scene, int element, int tess_u, int tess_v);
  // Refines the element's grid (its own, or the one refine() chose) locally from now on: each base quad to its
  // level (cad::refineGridLocally; chooseLocalSplit). The same levels again change nothing; all 0: the grid.
  void refineLocally(const Scene& scene, int element, const std::vector<uint8_t>& quad_levels);
  // The grid size refine() set and get() still returns; {0, 0} when none.
  std::array<int, 2> refined(int element) const {
    if (size_t(element) >= entries_.size()) return {0, 0};
    return {entries_[size_t(element)].refined_u, entries_[size_t(element)].refined_v};
  }

 private:
  struct Entry {
    cad::SurfacePtr surface;  // held, so that a new surface can never reuse a dropped one's address
    int tess_u = 0, tess_v = 0;        // the element's own grid size (the key)
    int refined_u = 0, refined_v = 0;  // the refined grid's size; 0: not refined
    bool has_outline = false;
    cad::Outline outline;
    cad::Tessellation grid;
    cad::Tessellation base;  // the grid before local refinement (empty while there is none)
  };
  std::vector<Entry> entries_;
};

// Stage "vertex-rays": traces every vertex's ray for every channel from `eye`.
void traceVertexRays(const RayScene& rays, ElementFrame& f, const Vec3& eye, const VertexStageOptions& opt);
// The same with one incoming-ray origin per vertex (multiple reflection: an element seen inside another's
// map, each vertex lit along the ray that really reaches it from the outer element's surface); `eye` is
// recorded as ElementFrame::eye. Throws pvrr::Error unless there is one origin per vertex.
void traceVertexRays(const RayScene& rays, ElementFrame& f, const Vec3& eye, const std::vector<Vec3>& origins,
                     const VertexStageOptions& opt);
// Stage "viewpoint-fit": patches (split automatically if the element asks), viewpoints, view volumes and
// texture coordinates. Throws nothing for degenerate input: each fit reports its condition and fallback.
void fitPatchViews(const Scene& scene, ElementFrame& f, const VertexStageOptions& opt);

// The projective weights (PatchView::q) and texture coordinates (PatchView::st) of the patch's vertices
// through pv.volume: the hit points projected by that camera. Used after the view volume is replaced (the
// renderer's map reuse gives a patch the volume of the map it already holds).
void projectPatchMap(const ElementFrame& f, PatchView& pv);

// Eye-fixed caching (paper section 5): when the element has not moved relative to the eye, its rays in the
// eye's frame and its fitted viewpoints are unchanged. moveRigidly carries a cached frame along with the
// eye (motion = new eye pose * inverse of the old one); updateTextureCoordinates then re-intersects the
// (unchanged) rays with the scene, rebuilds each view volume around the kept viewpoint and recomputes the
// texture coordinates: exact, without re-refracting or re-fitting.
void moveRigidly(ElementFrame& f, const Mat4& motion);
void updateTextureCoordinates(const RayScene& rays, ElementFrame& f);

// The image pixels a patch covers: the summed screen area of its triangles (either face), each vertex
// projected through `world_to_clip` and clamped to the image (a triangle partly outside it counts its part
// inside, roughly); triangles wholly at or behind the eye plane are left out, and a patch with a triangle
// across that plane counts as the whole image (its projection is unbounded). width x height: the image.
double patchScreenPixels(const ElementFrame& f, const PatchView& pv, const Mat4& world_to_clip, int width, int height);

}  // namespace pvrr
