// The CPU planning of pvrr mode's first passes, without GL: which map passes a frame renders (the top-level
// patch views and the nested passes of elements seen in other elements' maps), the size of each map, and
// whether a frame can draw from the maps of an earlier one (map reuse) or renders them widened for it. The
// renderer (pvrr/gl/renderer.h) executes the plan; what it needs from GL (the maximum texture size, which map
// slots it holds in R, G and B planes) comes in as arguments.
#pragma once
#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "pvrr/scene/render_desc.h"
#include "pvrr/trace/ray_scene.h"
#include "pvrr/scene/scene.h"
#include "pvrr/method/vertex_stage.h"

namespace pvrr {

// The settings of the planning; gl::RendererOptions derives from it, so its fields are set on a
// RendererOptions by these names.
// The defaults are the scene format's (RenderDesc, pvrr/scene/render_desc.h), written there once.
struct PassPlanOptions {
  int map_size = RenderDesc{}.map_size;  // first-pass map's longer side at most (pvrr), cube face size (envmap, impostor)
  // pvrr: each top-level map's texels per image pixel of its patch (Scene render.map_texels_per_pixel); the
  // map's longer side is lowered from map_size to that (topLevelMapSide). 0: always map_size.
  double map_texels_per_pixel = RenderDesc{}.map_texels_per_pixel;
  // Map reuse across frames (Scene render.map_reuse_margin_deg), with a FrameCache only: once a frame
  // follows another, each top-level map is rendered this much wider on each side (at the same texel
  // density), and later frames whose views still lie inside it, from a viewpoint that moved by under a
  // quarter texel of parallax, draw from it without a first pass (stage "first-pass" says why, or why not).
  // 0: every frame that moved renders its maps.
  double map_reuse_margin_deg = RenderDesc{}.map_reuse_margin_deg;
};

// Reuse across frames (paper section 5, eye-fixed caching): when an element has not moved relative to the
// eye, its vertex rays and viewpoints are kept; when the environment has not changed either, its first
// pass is kept too.
struct FrameCache {
  bool valid = false;
  std::vector<Mat4> element_to_eye;  // per element, the element pose relative to the eye of the last frame
  Mat4 view{1.0};                    // the observer's view matrix of the cached frame
  Mat4 projection{1.0};              // and its projection: what it sees of each element (ElementFrame::in_view)
  std::vector<ElementFrame> elements;
  // Set by the caller: whether the environment may have changed since the last frame drawn with this cache.
  // false also lets envmap and impostor modes reuse their cube maps, while no element moved
  // (pvrr/gl/cube_pass.h).
  bool environment_changed = true;
  // The renderer's own record of the animated environment meshes (Scene::mesh_motion) of the last frame drawn
  // with this cache. When they moved, the renderer starts the frame from a fresh cache (as if the caller had
  // made a new one: everything that depends on the environment is recomputed), keeps this record, and sets
  // only_meshes_moved for that frame, so that the passes that follow the meshes themselves (the cube maps,
  // pvrr/gl/cube_pass.h) may update in place; it clears the flag again when the frame is done.
  std::vector<Mat4> mesh_motion;
  bool only_meshes_moved = false;
  // Map reuse (PassPlanOptions::map_reuse_margin_deg): the top-level maps the renderer last rendered, in map
  // slot order, with the (widened) volume and the longer side each was rendered with. Empty when that
  // first pass cannot be reused (it had nested passes or elements drawn dark, or was not widened).
  struct Map {
    int element = -1;
    size_t view = 0;
    ViewVolume volume;
    int side = 0;
    bool rendered = false;  // false: the patch was out of view, its map not drawn
  };
  std::vector<Map> maps;
  uint64_t maps_serial = 0;  // the first pass that drew them (unique in the process; the renderer that holds
                             // maps of another serial drew over them)
  int maps_age = 0;          // frames drawn from them since
  bool last_plan_nested = false;  // the last first pass had nested passes or dark elements: the next one is
                                  // not widened (its maps could not be kept)
  uint64_t frame_serial = 0;  // the first pass whose maps `elements` were drawn with (the renderer must still
                              // hold them for a frame that skips its first pass)
};

// --- map sizes ---

// At most this many first passes per frame (top-level and nested): each holds a size^2 colour, seen-point
// and depth target. Elements that would need more are drawn dark in their map, and the stats say so.
constexpr size_t kMaxFirstPasses = 16;

// The map size (longer side, texels) of each of an element's top-level patches when `patches_in_view` of them
// are in the observer's view: map_size up to four patches, beyond that shrunk so that all of them together
// hold about as many texels as four full maps. Each map renders mapTexels(volume, this) (pvrr/method/view_volume.h).
int patchMapSize(int map_size, size_t patches_in_view);

// The longer side (texels) of the map of the top-level patch `pv` of `f`: patchMapSize, lowered to what the
// patch's pixels in the observer's image need at options.map_texels_per_pixel (mapSideForPixels of
// patchScreenPixels). It renders mapTexels(pv.volume, this) texels.
int topLevelMapSide(const Scene& scene, const ElementFrame& f, const PatchView& pv, const PassPlanOptions& options);

// The map size of an element seen in a map of size `parent`: half of it, at least 128 texels (for both the
// texture and the side rendered).
int nestedMapSize(int parent);

// --- what a pass sees ---

// Patch views a viewer can see (the others render no map).
size_t patchesInView(const ElementFrame& f);

// Whether any part of the convex hull of `points` can be inside the view volume: false only when every
// point lies outside one and the same clip plane (homogeneous outcodes; exact for a convex hull).
bool mayBeInVolume(const std::vector<Vec3>& points, const Mat4& m);

// The element's interfaces, each an event of the tracer's depth: 2 for a lens, 1 for a mirror.
int elementInterfaces(const Element& el);

// A top-level element whose interfaces reach render.max_depth (a lens with max_depth 1): the tracer
// absorbs at its back surface, so it is drawn dark and needs no map.
bool beyondDepth(const Scene& scene, const ElementFrame& f);

// Whether the top-level patch view v of f needs its map: the observer sees the patch and the element is
// not dark at the depth limit.
bool topLevelVisible(const Scene& scene, const ElementFrame& f, size_t v);

// A lens with RGB dispersion (three channels of unit R, G and B weights): its maps are planes, its second
// pass reads one component per channel.
bool rgbLens(const Element& el, const ElementFrame& f);

// --- multiple reflection (recursive PVRR with an explicit work list) ---

// An element drawn inside a first pass besides the environment: with its own PVRR maps (its vertex rays
// start from that pass's viewpoint), or dark where the tracer reaches its depth limit.
struct NestedDraw {
  int element = -1;
  const ElementFrame* frame = nullptr;  // null: drawn dark
  size_t first_slot = 0;                // map slot of frame->views[0]; views[v] uses first_slot + v
};
// One first pass: the map of one patch view.
struct MapPass {
  const ElementFrame* owner = nullptr;
  size_t view = 0;
  int depth = 0;     // the tracer's depth (events before) of what this map shows: 1 behind a mirror seen
                     // from the eye, 2 behind a lens (two interfaces)
  size_t slot = 0;   // index into the renderer's maps
  int size = 0;      // the map texture's width and height (nestedMapSize for nested maps)
  int side = 0;      // the longer side rendered (topLevelMapSide; nested: half the parent's): the pass renders the
                     // lower-left mapTexels(volume, side) of the texture
  bool visible = true;  // false: a top-level element the observer cannot see; its map is left as it is
  std::vector<NestedDraw> nested;
};

// A frame's first passes, parents before children. `passes` and `nested_frames` point into each other and
// into the top-level frames the plan was made from, which must outlive it.
struct PassPlan {
  std::vector<MapPass> passes;
  std::vector<std::unique_ptr<ElementFrame>> nested_frames;  // elements as seen from virtual viewpoints
  size_t top = 0;           // the top-level passes (the first `top` of `passes`, slots 0 .. top - 1)
  size_t dark = 0;          // elements drawn dark at the depth limit or budget
  bool budget_hit = false;  // some of them because of kMaxFirstPasses
  size_t nested() const { return passes.size() - top; }
  // Planned first passes that render a map (the budget counts these).
  size_t visiblePasses() const;
};

// Where the light that reaches each of `points` through the owner's patch leaves the owner (beyond the
// paper, which starts the nested rays at the outer virtual viewpoint and so inherits its fit residual):
// the outgoing-ray origins of the owner's vertices (mirror points, lens back points), interpolated at the
// point's position in the patch's map with the barycentric coordinates, in texture space, of the owner
// triangle that holds it there. A point outside the patch's image extrapolates from the nearest
// triangle, up to half a triangle; beyond that (or behind the map camera) it uses the viewpoint itself.
std::vector<Vec3> rayOrigins(const ElementFrame& owner, const PatchView& pv, const std::vector<Vec3>& points);

// Plans this frame's first passes: the top-level patch views of `frames` (slots 0..), then, breadth
// first, for every pass the other elements inside its view volume, each traced and fitted from the pass's
// viewpoint with its own maps appended to the list, down to the scene's depth limit. Children always
// follow their parent, so rendering the list backwards renders every map before the pass that reads it.
// `opts`: each element's vertex-stage options as seen from the eye.
// `top_size_side`: the texture size and rendered side of each top-level slot (widened maps); default
// patchMapSize and topLevelMapSide.
PassPlan planPasses(const Scene& scene, const RayScene& rays, const std::vector<ElementFrame>& frames,
                    const std::vector<VertexStageOptions>& opts, const PassPlanOptions& options,
                    const std::vector<std::array<int, 2>>* top_size_side = nullptr);

// Map reuse (PassPlanOptions::map_reuse_margin_deg). Whether the top-level maps of the last first pass
// (cache.maps) serve this frame's views: the same slots; every view the observer sees was rendered, lies
// inside its map's frustum (frustumContains), needs at most 15 % more texel density than the map has
// (and at least half), its viewpoint moved by under a quarter of the map's smallest texel angle as seen
// from its nearest hit point (parallax), and no other element reaches into the map's volume (nothing to
// nest; an element is never drawn in its own maps). If so each seen view takes its map's volume and its
// texture coordinates are projected through it; `note` says by what margin. Otherwise `note` says why not.
// held_serial: the first pass whose maps the renderer holds (FrameCache::maps_serial); planes_slots: per map
// slot the renderer holds, whether it is in R, G and B planes (slots beyond it: not).
bool reuseMaps(const Scene& scene, std::vector<ElementFrame>& frames, const FrameCache& cache,
               const PassPlanOptions& options, uint64_t held_serial, const std::vector<bool>& planes_slots,
               std::string* note);

// Widens every top-level forward view by the reuse margin (widenViewVolume) at the texel density it needs
// (its side scaled by the wider extent) in a texture 25 % larger than patchMapSize (but no larger than
// max(patchMapSize, max_texture_size)), and projects its texture coordinates through the wider volume. A
// narrow view gets a smaller margin, so that its longer extent grows by at most kMaxWidening and its density
// is kept within that texture. Returns each slot's texture size and side.
constexpr double kMaxWidening = 1.2;
std::vector<std::array<int, 2>> widenMaps(const Scene& scene, std::vector<ElementFrame>& frames,
                                          const PassPlanOptions& options, int max_texture_size);

}  // namespace pvrr
