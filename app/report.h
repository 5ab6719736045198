// What render, compare and the reports share: one rendered frame in any mode, a GL session reused across
// frames, and the JSON pieces of the stats. The accuracy metric itself is pvrr/analysis/accuracy.h.
#pragma once
#include <array>
#include <cstdint>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "app/commands.h"
#include "pvrr/analysis/accuracy.h"
#include "pvrr/base/frame.h"
#include "pvrr/gl/context.h"

namespace pvrr::app {

// A frame of any mode (pvrr/base/frame.h), with what only the CLI records: the pvrr mode's per-element stats as
// JSON (elementsJson) and the GL backend that drew it.
struct RenderedFrame : Frame {
  nlohmann::json elements = nlohmann::json::array();
  std::string gl_backend;
};

// A GL context, the Embree scene and the renderer, kept across the frames of one command.
struct RenderSession {
  std::unique_ptr<gl::GlContext> context;
  std::unique_ptr<RayScene> rays;
  std::unique_ptr<gl::Renderer> renderer;
  gl::FrameCache cache;
  int seen_channel = -1;  // gl::RendererOptions::seen_channel of the renderer this session creates
  bool moving_elements = false;  // RaySceneOptions::moving_elements: the head turns between frames
  bool seen_points = true;       // gl::RendererOptions::seen_points: off when only the picture is wanted
  // Whether the next raster frame is read back from the GPU (RenderedFrame's pixels): off for frames that are
  // only timed or not written, so that no frame time includes the readback (a viewer presents the frame).
  bool read_back = true;
};

// Poses an animated scene at time t_s (applyAnimation); if anything moved, the session's renderer and ray
// scene, which hold the scene's geometry, are dropped to be built again, with a fresh frame cache. Returns
// whether anything moved. A scene without animation stays as it is.
bool poseSceneAt(LoadedScene& ls, double t_s, RenderSession* session);

// A --mode or --modes value: a raster mode (isRasterMode), or also raytrace where `raytrace_ok`. Throws
// pvrr::Error "mode: expected one of pvrr, raster, envmap, impostor, raytrace; got ..." for another value.
RenderMode parseModeOption(const std::string& text, bool raytrace_ok);
RenderedFrame renderFrame(LoadedScene& ls, RenderMode mode, const std::string& gl_backend_name,
                          RenderSession* session);
// A measured frame: one warm-up, then the median frame time of `frames` frames, each doing every stage.
RenderedFrame timedFrame(LoadedScene& ls, RenderMode mode, const std::string& gl_backend_name, int frames,
                         double* median_ms);
nlohmann::json elementsJson(const Scene& scene, const std::vector<ElementFrame>& frames);
// One line per element of elementsJson whose quality verdict is not good ("PREFIX quality: NAME degraded:
// ACTION; patch P: REASONS"), on stdout, so that a picture the mode cannot make right never passes silently.
void printQuality(const nlohmann::json& elements, const std::string& prefix);
// The stages of a frame: [{"name", "ms", "ran", "reason"[, "count"][, "note"]}].
nlohmann::json stagesJson(const FrameStages& s);
// Per-vertex data as VTK PolyData (.vtp) for ParaView: the grid of each element with point arrays.
void writeVerticesVtp(const std::string& path, const Scene& scene, const std::vector<ElementFrame>& frames);
// A tessellation as OBJ (v, vn, f v//vn), PLY or VTP, chosen by extension; atomic.
void writeTessellation(const std::string& path, const cad::Tessellation& t);

// Peak resident memory of this process so far (VmHWM), in MB.
double peakRssMb();
// Resident memory of this process now (the resident pages of /proc/self/statm), in MB; 0 where unreadable.
double currentRssMb();
// The frame after which `render --frames N` records its baseline resident memory: frame 100, or the first
// frame when N < 100 (1-based).
int rssBaselineFrame(int frames);

}  // namespace pvrr::app
