// The "render" section of a scene file (docs/scene-format.md): the render mode, the dispersion mode and the
// render settings, each written once. The parser (pvrr/scene/scene_json.h) starts from RenderDesc{} and the
// runtime scene's RenderSettings (pvrr/scene/scene.h) derives from it; the CLI (--mode, --modes), the GL
// renderer and the reference tracer take these enums, named by these tables.
#pragma once
#include <string>

#include "pvrr/base/math.h"
#include "pvrr/base/names.h"

namespace pvrr {

// pvrr: the method (per-vertex rays, virtual viewpoints, two passes; pvrr/gl/renderer.h); raster: elements
// drawn as plain surfaces; raytrace: the exact reference tracer (CPU, pvrr/trace/tracer.h); envmap: a dynamic
// cube map from each element's centre (the classic baseline); impostor: distance impostors (the glass mode).
enum class RenderMode { Pvrr, Raster, Raytrace, Envmap, Impostor };
inline constexpr NameTable<RenderMode, 5> kRenderModeNames = {{{RenderMode::Pvrr, "pvrr"},
                                                               {RenderMode::Raster, "raster"},
                                                               {RenderMode::Raytrace, "raytrace"},
                                                               {RenderMode::Envmap, "envmap"},
                                                               {RenderMode::Impostor, "impostor"}}};
constexpr const NameTable<RenderMode, 5>& nameTable(RenderMode) { return kRenderModeNames; }
static_assert(namesAreUnique(kRenderModeNames));

// The modes the GL renderer draws: all but Raytrace, the reference tracer's.
constexpr bool isRasterMode(RenderMode m) { return m != RenderMode::Raytrace; }

// off: one ray (one draw) with each lens's index at the d line; rgb: one per colour channel at that channel's
// wavelength (pvrr/optics/spectrum.h), keeping that channel; spectral: N wavelengths summed with the
// colour-matching weights.
enum class DispersionMode { Off, Rgb, Spectral };
inline constexpr NameTable<DispersionMode, 3> kDispersionModeNames = {
    {{DispersionMode::Off, "off"}, {DispersionMode::Rgb, "rgb"}, {DispersionMode::Spectral, "spectral"}}};
constexpr const NameTable<DispersionMode, 3>& nameTable(DispersionMode) { return kDispersionModeNames; }
static_assert(namesAreUnique(kDispersionModeNames));

// How each patch's virtual viewpoint is fitted (pvrr/method/viewpoint.h): auto: closed form + own Gauss-Newton,
// Ceres when the quick solve fails a check (the default); gauss-newton: closed form + own Gauss-Newton only;
// ceres: closed form + Ceres (autodiff, DENSE_QR); closed-form: the least-squares line distance only.
enum class ViewpointSolver { kAuto, kGaussNewton, kCeres, kClosedForm };
inline constexpr NameTable<ViewpointSolver, 4> kViewpointSolverNames = {{{ViewpointSolver::kAuto, "auto"},
                                                                        {ViewpointSolver::kGaussNewton, "gauss-newton"},
                                                                        {ViewpointSolver::kCeres, "ceres"},
                                                                        {ViewpointSolver::kClosedForm, "closed-form"}}};
constexpr const NameTable<ViewpointSolver, 4>& nameTable(ViewpointSolver) { return kViewpointSolverNames; }
static_assert(namesAreUnique(kViewpointSolverNames));

// The largest render.max_depth the format accepts: the shaders' event loops are bounded by it
// (MAX_DEPTH_LIMIT, injected by pvrr/gl/program.cpp).
inline constexpr int kMaxDepthLimit = 64;

// The most secant steps render.refine accepts: the shader's search loop is unrolled by it.
inline constexpr int kMaxRefineSteps = 16;

// render.ambient_occlusion (pvrr/trace/ambient_occlusion.h): off by default. The raster path's displacement
// fields (pvrr/method/ao_field.h) sample `positions`^2 points on each occluding object's bounding sphere
// (octahedral map) and `directions`^2 rays from each (concentric map), turned at load into an occlusion
// volume a fragment reads (pvrr/gl/ao_fields.h); the reference casts `reference_samples` rays per shaded point.
struct AmbientOcclusionDesc {
  bool on = false;
  int positions = 64;
  int directions = 16;
  int reference_samples = 256;
};

// The settings of the "render" section with their defaults: the defaults of the scene format.
struct RenderDesc {
  RenderMode mode = RenderMode::Pvrr;
  int map_size = 1024;               // a map's longer side at most (texels)
  double map_texels_per_pixel = 4;   // a top-level map's texels per image pixel of its patch; 0: map_size
  double map_reuse_margin_deg = 2;   // maps widened this much for reuse by later frames; 0: no reuse
  int impostor_iterations = 8;       // impostor mode: false-position steps of each fragment's search
  int impostor_layers = 2;           // impostor mode: layers of each distance map (2: the second depth-peeled)
  // pvrr mode: the secant steps of each mirror fragment's search of its map along its exact reflected ray
  // (docs/method.md "Per-fragment refinement"); 0: off, the paper's interpolated texture coordinates.
  int refine = 0;
  // Relative to the current directory, as written. The parser and the build fill in out/<scene name>.png
  // when the file names none.
  std::string output;
  int max_depth = 4;
  DispersionMode dispersion = DispersionMode::Off;
  int spectral_samples = 16;
  Vec3 background{0.55, 0.7, 0.9};  // linear RGB of escaping rays (the sky)
  ViewpointSolver viewpoint_solver = ViewpointSolver::kAuto;
  AmbientOcclusionDesc ambient_occlusion;
};

}  // namespace pvrr
