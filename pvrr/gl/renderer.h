// The raster paths on the GPU: "raster" (elements drawn as plain surfaces), "pvrr" (the paper's two passes,
// with the CPU stages of pvrr/vertex_stage.h), "envmap" (a dynamic cube map from each element's centre,
// the classic baseline) and "impostor" (the glass mode of distance impostors: the same cube maps with each
// direction's distance, searched per fragment along the exact reflected ray, or along the ray refracted
// through a lens's refractor height maps; docs/method.md "Distance impostors"). A current GL context
// (pvrr/gl/context.h) is required.
//
// Multiple reflection (pvrr mode): an element inside another element's view volume is drawn in that
// element's first pass with its own PVRR maps, its vertex rays starting where the outer element's rays that
// reach it leave the outer surface; recursively (an explicit work list, parents before children, rendered
// deepest first) down to the scene's render.max_depth, beyond which it is drawn black with its own surface
// as the seen point, as the tracer absorbs there. Stage "nested-passes" reports the recursion.
// Spectral dispersion: N channels share one first pass per patch; the second pass adds ceil(N / 3) draws
// of three channels each, weighted per channel (pvrr/spectrum.h), into the colour attachment only.
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "pvrr/frame.h"
#include "pvrr/ray_scene.h"
#include "pvrr/stats.h"
#include "pvrr/vertex_stage.h"

namespace pvrr::gl {

enum class RasterMode { Raster, Pvrr, Envmap, Impostor };
RasterMode parseRasterMode(const std::string& mode);  // throws pvrr::Error
std::string modeName(RasterMode mode);                 // the name parseRasterMode takes

// What one frame produced, read back from the GPU (pvrr/frame.h: color, and with seen points on seen, element
// and element_point; bounces and channel_seen stay empty), and the pvrr mode's per-element state.
struct RasterFrame : Frame {
  std::vector<ElementFrame> elements;  // PVRR per-element state of this frame (pvrr mode)
};

struct RendererOptions {
  int map_size = 1024;              // first-pass map's longer side at most (pvrr), cube face size (envmap, impostor)
  // impostor: the longer side (texels) of a lens's refractor height maps (pvrr/lens_height_map.h), and the
  // side of a mirror's surface maps (pvrr/surface_map.h); each built once per renderer.
  int lens_height_map_size = 512;
  int surface_map_size = 512;
  // pvrr: each top-level map's texels per image pixel of its patch (Scene render.map_texels_per_pixel); the
  // map's longer side is lowered from map_size to that (topLevelMapSide). 0: always map_size.
  double map_texels_per_pixel = 4;
  // Viewpoint options and channels. Channels empty: each element gets dispersionChannels(scene, element)
  // (the scene's render.dispersion and spectral_samples); otherwise every element gets these channels.
  VertexStageOptions vertex;
  bool read_back = true;            // false: leave the frame on the GPU (benchmarks of the draw alone)
  // false: colour only, for viewing (pvrr render): no seen-point and surface attachments in any pass and
  // RasterFrame::seen / element / element_point left empty; the accuracy reports need them on. Stage
  // "seen-points" reports which. The picture is then drawn into a 16-bit linear target (GL_RGBA16: colours
  // clamped to [0, 1], as the 8-bit sRGB encode of a picture clamps them, and rounded to 1/65535), about
  // 1.2 ms faster than the float target at 1280 x 720 on llvmpipe; its 8-bit picture is within one code of
  // the float frame's (docs/method.md). Not when an element has more than three channels (spectral
  // dispersion): its additive draws' partial sums must not be clamped. A non-finite colour cannot reach a
  // 16-bit target (it is written as some value in [0, 1], usually 0), so `pvrr render`'s warning about
  // non-finite pixels needs the float target (seen points on).
  bool seen_points = true;
  // Which colour channel's texture coordinates feed the per-pixel seen point (RasterFrame::seen) in pvrr
  // mode: -1 the fit channel (the middle one with dispersion, else the only one); c >= 0 channel c (clamped
  // to the last channel), e.g. 0 and 2 give red's and blue's seen points on a dispersive lens.
  int seen_channel = -1;
  // Map reuse across frames (Scene render.map_reuse_margin_deg), with a FrameCache only: once a frame
  // follows another, each top-level map is rendered this much wider on each side (at the same texel
  // density), and later frames whose views still lie inside it, from a viewpoint that moved by under a
  // quarter texel of parallax, draw from it without a first pass (stage "first-pass" says why, or why not).
  // 0: every frame that moved renders its maps.
  double map_reuse_margin_deg = 2;
  // Cull the back faces of closed convex environment meshes (EnvMesh::closed_convex: boxes, spheres) in each
  // pass whose depth is not reversed, where near clipping cannot cut the mesh open (NearClip: wholly beyond
  // the near plane, or out of the near rectangle's reach). The picture is the same, but where a back face tied
  // with a front face in depth (on silhouettes, or over thin or distant solids that the depth buffer cannot
  // separate): the front face now wins there, as in the tracer. false draws every face, for the tests that
  // compare.
  bool cull_back_faces = true;
  // Leave unshaded the texels of each first-pass map that its reader cannot fetch (pvrr/map_footprint.h: the
  // element's triangles at their texture coordinates, widened by the bilinear neighbourhood): the car mirror's
  // warped image covers about three quarters of its map. Not for maps widened for reuse, whose later frames
  // read elsewhere. The picture is the same texel for texel; false draws whole maps, for the tests that
  // compare.
  bool skip_unread_texels = true;
  // Draw the environment meshes nearest first (farthest first in reversed-depth maps; depthSortedDrawOrder),
  // so that what a nearer mesh hides fails the early depth test instead of being shaded and overwritten. The
  // picture changes only where two meshes tie in depth; false keeps the scene's order, for the tests that
  // compare.
  bool sort_environment = true;
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
  bool environment_changed = true;
  // Map reuse (RendererOptions::map_reuse_margin_deg): the top-level maps the renderer last rendered, in map
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

// The map size (longer side, texels) of each of an element's top-level patches when `patches_in_view` of them
// are in the observer's view: map_size up to four patches, beyond that shrunk so that all of them together
// hold about as many texels as four full maps. Each map renders mapTexels(volume, this) (pvrr/view_volume.h).
int patchMapSize(int map_size, size_t patches_in_view);

// The longer side (texels) of the map of the top-level patch `pv` of `f`: patchMapSize, lowered to what the
// patch's pixels in the observer's image need at options.map_texels_per_pixel (mapSideForPixels of
// patchScreenPixels). It renders mapTexels(pv.volume, this) texels.
int topLevelMapSide(const Scene& scene, const ElementFrame& f, const PatchView& pv, const RendererOptions& options);

class Renderer {
 public:
  Renderer(const Scene& scene, const RayScene& rays, RendererOptions options);
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  // Renders one frame of `scene` (which may have moved since construction only in its observer and in the
  // poses of elements attached to the observer) as seen by the scene's observer.
  RasterFrame render(RasterMode mode, FrameCache* cache = nullptr);
  // RendererOptions::read_back for the next frames (e.g. only the last of a run is written out).
  void setReadBack(bool on);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace pvrr::gl
