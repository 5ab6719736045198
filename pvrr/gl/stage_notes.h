// The renderer's stages (pvrr/base/stats.h) by name, and the texts of their notes and skip reasons, in one place:
// the stats JSON carries them, and tests and users read them, so they stay as they are written here.
#pragma once
#include <chrono>
#include <cstdint>
#include <string>
#include <vector>

#include "pvrr/gl/renderer.h"
#include "pvrr/method/pass_plan.h"
#include "pvrr/base/stats.h"

namespace pvrr::gl {

using Clock = std::chrono::steady_clock;
inline double msSince(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

// The stage names, in the order a frame reports them.
namespace stage {
inline constexpr const char* kVertexRays = "vertex-rays";
inline constexpr const char* kRefraction = "refraction";
inline constexpr const char* kViewpointFit = "viewpoint-fit";
inline constexpr const char* kTextureCoordinates = "texture-coordinates";
inline constexpr const char* kColourChannels = "colour-channels";
inline constexpr const char* kFirstPass = "first-pass";
inline constexpr const char* kNestedPasses = "nested-passes";
inline constexpr const char* kSecondPass = "second-pass";
inline constexpr const char* kSeenPoints = "seen-points";
}  // namespace stage

// Closed convex meshes drawn and culled by EnvironmentPass::draw, summed over a stage's passes for its note.
struct CullCount {
  int drawn = 0, culled = 0;
  void add(const CullCount& o) { drawn += o.drawn, culled += o.culled; }
};
// cull_on: RendererOptions::cull_back_faces.
std::string cullNote(const CullCount& c, bool cull_on);

// --- the CPU stages (vertex-rays, refraction, viewpoint-fit, texture-coordinates, colour-channels) ---

// Modes other than pvrr, and scenes without an element: none of them runs (impostor mode does their work per
// fragment and says so).
void noteCpuStagesSkipped(FrameStages& stages, const Scene& scene, RenderMode mode);

// What pvrr mode's CPU stages did this frame.
struct PvrrCpuStages {
  bool all_reused = false;     // every element kept its rays and viewpoints (eye-fixed cache)
  bool nothing_moved = false;  // and the frame is the cached one
  bool any_texcoords = false;  // texture coordinates were redone for a cached element that moved with the eye
  bool has_lens = false;
  double rays_ms = 0, refraction_ms = 0, fit_ms = 0, texcoord_ms = 0;
  size_t mirror_rays = 0, beside = 0;  // traced this frame; beside: VertexStageOptions::beside_own_mirror
};
void notePvrrCpuStages(FrameStages& stages, const PvrrCpuStages& s, const std::vector<ElementFrame>& frames);

// --- first-pass and nested-passes ---

// Raster mode, or no element.
void noteFirstPassesSkipped(FrameStages& stages, const Scene& scene, RenderMode mode);

// Pvrr mode without a first pass: `reuse_note` says which maps it draws from (empty: the eye-fixed cache's).
void notePvrrFirstPassSkipped(FrameStages& stages, const std::string& reuse_note);

// What pvrr mode's first pass did.
struct PvrrFirstPass {
  double ms = 0, plan_ms = 0;
  bool widen = false;        // its maps were widened for reuse
  bool reuse_on = false;     // map reuse applies to this frame (a cache that holds an earlier frame)
  bool any_forward = false;  // some view is forward (reversed maps are never widened nor reused)
  std::string reuse_note;    // why the maps of an earlier frame were not reused
  int64_t unread = 0, texels = 0;  // map texels left unshaded, of those rendered
  CullCount culled;
};
// planes_slots: per map slot, whether it is in R, G and B planes.
void notePvrrFirstPass(FrameStages& stages, const Scene& scene, const RendererOptions& options, const PassPlan& plan,
                       const std::vector<bool>& planes_slots, const PvrrFirstPass& s);

// What the cube maps of envmap and impostor modes took.
struct CubeFirstPass {
  double ms = 0;
  int layers = 1, layer1_size = 0;  // of each impostor distance map; the second layer's face size
  int follow = 0;                   // ImpostorMaps::cubeElements
  bool lens_in_cubes = false;
  size_t lens_count = 0;
  int height_maps = 0, surface_maps = 0;  // built this frame
  int drawn_in_cubes = 0;                 // (cube, element) pairs
  CullCount culled;
};
void noteCubeFirstPass(FrameStages& stages, const Scene& scene, RenderMode mode, bool cull_on, const CubeFirstPass& s);

// --- second-pass and seen-points ---

// The impostor second layers: drawn (their time, the cubes' cull note and the pixels that needed them), or not.
std::string secondLayersNote(double ms, const std::string& cull_note, uint64_t pixels);
std::string secondLayersSkippedNote();
void noteSecondPass(FrameStages& stages, double ms, const std::string& cull_note, const std::string& layer_note,
                    bool seen_points);

}  // namespace pvrr::gl
