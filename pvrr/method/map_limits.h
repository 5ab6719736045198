// Map sizes against what the GL can hold (issue 26 item 3), before any pass runs: every texture and render
// target a frame of a mode allocates at its scene's sizes (render.map_size, observer.image_size) is checked
// against the context's GL_MAX_TEXTURE_SIZE, GL_MAX_CUBE_MAP_TEXTURE_SIZE and GL_MAX_RENDERBUFFER_SIZE, and
// the memory they need at least against a budget. A size that does not fit is refused with one line naming the
// scene and the setting, and the largest value that fits: the map size sets the picture's accuracy, so it is
// not lowered behind the user's back (a clamp would pass a coarser picture as the one asked for).
// GL-free: the limits come in as GlLimits (pvrr/gl/context.h queryGlLimits reads them from the context).
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "pvrr/scene/scene.h"

namespace pvrr {

struct GlLimits {
  int max_texture_size = 0;       // GL_MAX_TEXTURE_SIZE
  int max_cube_map_size = 0;      // GL_MAX_CUBE_MAP_TEXTURE_SIZE
  int max_renderbuffer_size = 0;  // GL_MAX_RENDERBUFFER_SIZE
  double memory_bytes = 0;        // the budget for the frame's textures and targets; <= 0: not checked
  std::string memory_source;      // where the budget comes from, for the message (e.g. "PVRR_GPU_MEMORY_MB")
};

// The sizes a frame's allocations follow, besides the scene's (RendererOptions' fields of the same names).
struct MapSizeSettings {
  int map_size = 0;              // pvrr: a top-level map's texture side; envmap, impostor: the cube face side
  bool seen_points = true;       // seen-point attachments in every pass
  int lens_height_map_size = 0;  // impostor: a lens's refractor height maps (longer side)
  int surface_map_size = 0;      // impostor: a mirror's surface maps
};

// The bytes of GPU memory a frame of `mode` needs at least at `map_size`: the second pass's target
// (observer.image_size) and, per mode, the top-level pvrr maps (one per patch of every element, at
// patchMapSize, colour + seen points + depth) or one cube per element (six faces, colour + seen points or
// distances + one face of depth; impostor mode's second layers at half size when impostor_layers >= 2). A lower
// bound: nested maps, widened maps for reuse and impostor mode's element cubes come on top.
double mapMemoryBytes(const Scene& scene, RenderMode mode, const MapSizeSettings& settings);

// Throws pvrr::Error (one line: "<scene>: render.map_size N: ..." or "<scene>: observer.image_size WxH: ...")
// when a texture or target of a frame of `mode` exceeds a GL limit or mapMemoryBytes exceeds the budget, with
// the largest map_size that fits where lowering it helps. Raster mode needs no maps (only its target counts).
void checkMapLimits(const Scene& scene, RenderMode mode, const MapSizeSettings& settings, const GlLimits& limits);

// Everything checkMapLimits reads of a frame (the mode, the settings, the image size, each element's type and
// patch layout, and the limits themselves): a frame with the same key as the last one checked needs no second
// check, so the renderer checks once per change of settings, not every frame.
std::vector<double> mapLimitsKey(const Scene& scene, RenderMode mode, const MapSizeSettings& settings,
                                 const GlLimits& limits);

}  // namespace pvrr
