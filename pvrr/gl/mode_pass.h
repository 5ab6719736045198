// What the renderer's passes share, and the interface of the work of one raster mode: the plain elements of
// raster mode (and of every mode in a scene without elements), pvrr mode's CPU stages, maps and element draws
// (pvrr_pass.h), envmap and impostor modes' cube maps and element draws (cube_pass.h). The Renderer
// (renderer.cpp) chooses one per frame and draws the second pass's target, environment and readback around it.
#pragma once
#include <string>
#include <vector>

#include "pvrr/gl/element_mesh.h"
#include "pvrr/gl/environment_pass.h"
#include "pvrr/gl/framebuffer.h"
#include "pvrr/gl/programs.h"
#include "pvrr/gl/renderer.h"

namespace pvrr::gl {

// The resources the Renderer owns and lends to its passes.
struct RenderContext {
  const Scene& scene;
  const RayScene& rays;
  const RendererOptions& options;
  const Programs& programs;
  const EnvironmentPass& environment;
  MeshPool& meshes;
  ElementGridCache& grid_cache;  // the elements' tessellations, posed anew each frame
  int max_texture_size = 0;      // GL_MAX_TEXTURE_SIZE
  int max_texture_units = 0;     // GL_MAX_TEXTURE_IMAGE_UNITS
};

// A camera of one pass (the second pass, or a first pass from a virtual viewpoint): positions are relative
// to `origin`.
struct PassCamera {
  Vec3 origin{0};
  Mat4 view_proj{1.0};   // relativeViewProj: acts on positions relative to origin
  Vec3 rays_from{0};     // where the viewing rays start, relative to origin (0: the camera itself)
  bool reversed_depth = false;
  bool planes = false;   // the target is a lens map in R, G and B planes (shaders/outputs.glsl PLANES)
};

class ModePass {
 public:
  virtual ~ModePass() = default;
  // Everything before the second pass: the CPU stages and the first passes (maps, cube maps), with their
  // stage notes, in the order of pvrr/base/stats.h.
  virtual void prepare(RenderMode mode, FrameStages& stages, FrameCache* cache) = 0;
  // Whether an element's second-pass draws add partial sums (more than three channels): the target must then
  // be float.
  virtual bool additiveDraws() const { return false; }
  // The elements into `target` (cleared depth, depth test on, GL_LESS) as seen by `eye`, before the
  // environment; returns what the second pass's note adds for them.
  virtual std::string drawElements(RenderMode mode, const PassCamera& eye, const Framebuffer& target) = 0;
  // Once the frame's draws have finished (after glFinish): what the second pass's note adds from the GPU's
  // counts of them, appended to drawElements' note (read here so that the frame's draws run without a wait).
  virtual std::string finishedNote(const std::string& note) const { return note; }
  // The frame's per-element PVRR state (RasterFrame::elements), once drawn.
  virtual std::vector<ElementFrame> takeElements() { return {}; }
};

}  // namespace pvrr::gl
