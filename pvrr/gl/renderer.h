// The raster paths on the GPU: "raster" (elements drawn as plain surfaces), "pvrr" (the paper's two passes,
// with the CPU stages of pvrr/method/vertex_stage.h), "envmap" (a dynamic cube map from each element's centre,
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
// of three channels each, weighted per channel (pvrr/optics/spectrum.h), into the colour attachment only.
#pragma once
#include <array>
#include <memory>
#include <string>
#include <vector>

#include "pvrr/base/frame.h"
#include "pvrr/gl/caustic_pass.h"
#include "pvrr/method/pass_plan.h"
#include "pvrr/trace/ray_scene.h"
#include "pvrr/base/stats.h"
#include "pvrr/method/vertex_stage.h"

namespace pvrr::gl {

// What one frame produced, read back from the GPU (pvrr/base/frame.h: color, and with seen points on seen, element
// and element_point; bounces and channel_seen stay empty), and the pvrr mode's per-element state.
struct RasterFrame : Frame {
  std::vector<ElementFrame> elements;  // PVRR per-element state of this frame (pvrr mode)
};

// The planning's settings (map_size, map_texels_per_pixel, map_reuse_margin_deg: pvrr/method/pass_plan.h) are fields of
// the base.
struct RendererOptions : PassPlanOptions {
  // impostor: the longer side (texels) of a lens's refractor height maps (pvrr/impostor/lens_height_map.h), and the
  // side of a mirror's surface maps (pvrr/impostor/surface_map.h); each built once per renderer.
  int lens_height_map_size = 512;
  int surface_map_size = 512;
  // Caustics (pvrr/gl/caustic_pass.h): the caustic map's side, photons per side of each light's aperture over
  // an element, per wavelength sample.
  int caustic_map_size = 512;
  // Viewpoint options and channels. Channels empty: each element gets dispersionChannels(scene, element)
  // (the scene's render.dispersion and spectral_samples); otherwise every element gets these channels.
  VertexStageOptions vertex;
  bool read_back = true;            // false: leave the frame on the GPU (benchmarks of the draw alone)
  // false: colour only, for viewing (pvrr render): no seen-point and surface attachments in any pass and
  // RasterFrame::seen / element / element_point left empty; the accuracy reports need them on. Stage
  // "seen-points" reports which. The picture is then drawn into a 16-bit linear target (GL_RGBA16: colours
  // clamped to [0, 1], as the 8-bit sRGB encode of a picture clamps them, and rounded to 1/65535), faster
  // than the float target on llvmpipe; its 8-bit picture is within one code of the float frame's
  // (docs/method.md). Not when an element has more than three channels (spectral
  // dispersion): its additive draws' partial sums must not be clamped. A non-finite colour cannot reach a
  // 16-bit target (it is written as some value in [0, 1], usually 0), so `pvrr render`'s warning about
  // non-finite pixels needs the float target (seen points on).
  bool seen_points = true;
  // Which colour channel's texture coordinates feed the per-pixel seen point (RasterFrame::seen) in pvrr
  // mode: -1 the fit channel (the middle one with dispersion, else the only one); c >= 0 channel c (clamped
  // to the last channel), e.g. 0 and 2 give red's and blue's seen points on a dispersive lens.
  int seen_channel = -1;
  // Cull the back faces of closed convex environment meshes (EnvMesh::closed_convex: boxes, spheres) in each
  // pass whose depth is not reversed, where near clipping cannot cut the mesh open (NearClip: wholly beyond
  // the near plane, or out of the near rectangle's reach). The picture is the same, but where a back face tied
  // with a front face in depth (on silhouettes, or over thin or distant solids that the depth buffer cannot
  // separate): the front face now wins there, as in the tracer. false draws every face, for the tests that
  // compare.
  bool cull_back_faces = true;
  // Leave unshaded the texels of each first-pass map that its reader cannot fetch (pvrr/method/map_footprint.h: the
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
  // A window's frame (app/view): the second pass draws into the current context's default framebuffer (the
  // window's back buffer, of the observer's size, with a depth buffer and an sRGB-capable colour buffer, which
  // the caller checks), encoded to 8-bit sRGB by GL as it is written (GL_FRAMEBUFFER_SRGB, on for the pass
  // only), so that no pass copies the frame into the window. Only for a picture-only frame left on the GPU
  // (seen_points and read_back false) whose elements are drawn once each (no spectral dispersion: its partial
  // sums need the float target); otherwise, or false, the frame goes into its texture (colorTexture()).
  // Renderer::drewIntoDefaultFramebuffer says which the last frame did. pvrr render never sets it.
  bool into_default_framebuffer = false;
  // With into_default_framebuffer: pixels the caller draws over opaquely after the frame (a window's panel),
  // [x0, x1) x [y0, y1) in GL's window coordinates (rows bottom-up), all zero for none. Their depth is cleared
  // to the near plane before the second pass, so that every fragment there fails the depth test before it is
  // shaded (llvmpipe tests depth first where a shader neither discards nor writes depth), and their colour is
  // left as the back buffer held it. Not for a frame drawn into its texture, which stays whole.
  std::array<int, 4> covered_rect{};
};

// The options a scene asks for: its render section's planning settings (map_size, map_texels_per_pixel,
// map_reuse_margin_deg), each element's channels from its dispersion (vertex.channels empty), the rest default.
RendererOptions rendererOptionsFor(const Scene& scene);

// The frame cache and the map sizes belong to the planning (pvrr/method/pass_plan.h); these names keep them where the
// renderer's users look for them.
using pvrr::FrameCache;
using pvrr::patchMapSize;
using pvrr::topLevelMapSide;

class Renderer {
 public:
  Renderer(const Scene& scene, const RayScene& rays, RendererOptions options);
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  // Renders one frame of `scene` as seen by the scene's observer. Since construction the scene may have
  // changed only in its observer, its elements' poses and its animated meshes (applyAnimation), which are
  // updated in place (the caller updates the RayScene: updateElementPoses, updateEnvironmentMeshes). `mode`: a raster
  // mode (isRenderMode); RenderMode::Raytrace is the tracer's (an internal error here).
  RasterFrame render(RenderMode mode, FrameCache* cache = nullptr);
  // RendererOptions::read_back for the next frames (e.g. only the last of a run is written out).
  void setReadBack(bool on);
  // RendererOptions::into_default_framebuffer for the next frames (a window turns it off while it shows the
  // frame through a pass of its own, e.g. beside a reference).
  void setIntoDefaultFramebuffer(bool on);
  // Whether the last frame was drawn into the default framebuffer (RendererOptions::into_default_framebuffer);
  // colorTexture() is then 0.
  bool drewIntoDefaultFramebuffer() const;
  // RendererOptions::covered_rect for the next frames.
  void setCoveredRect(const std::array<int, 4>& rect);
  // The GL texture holding the last frame's linear colour (0 before the first frame), for a window to present
  // without a readback: GL_TEXTURE_2D of the frame's size, rows bottom-up as GL stores them, RGBA16 or RGBA32F
  // (RendererOptions::seen_points). Valid until the next render() in the renderer's context. 0 when the last
  // frame went into the default framebuffer.
  unsigned colorTexture() const;
  // The receivers' caustic light maps as the last frame drew them (pvrr/gl/caustic_pass.h); empty without
  // caustics.
  std::vector<CausticMap> causticMaps() const;
  // The caustic plan behind them (its notes say what was left out).
  const CausticPlan& causticPlan() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace pvrr::gl
