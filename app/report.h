// What render, compare and the reports share: one rendered frame in any mode, a GL session reused across
// frames, and the JSON pieces of the stats.
#pragma once
#include <array>
#include <cstdint>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "app/commands.h"
#include "pvrr/gl/context.h"

namespace pvrr::app {

struct RenderedFrame {
  int width = 0, height = 0;
  std::vector<Vec3> color, seen, element_point;
  std::vector<int> element;
  // The reference: specular events (reflections, refractions, TIRs) of each pixel's path; empty otherwise.
  std::vector<int> bounces;
  // The reference with rgb dispersion: each channel's (R, G, B) seen point per pixel; empty otherwise.
  std::array<std::vector<Vec3>, 3> channel_seen;
  double frame_ms = 0;
  FrameStages stages;
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

RenderedFrame renderFrame(LoadedScene& ls, const std::string& mode, const std::string& gl_backend_name,
                          RenderSession* session);
// A measured frame: one warm-up, then the median frame time of `frames` frames, each doing every stage.
RenderedFrame timedFrame(LoadedScene& ls, const std::string& mode, const std::string& gl_backend_name, int frames,
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

struct ErrorStats {
  size_t pixels = 0;
  double median_arcmin = 0, p95_arcmin = 0, max_arcmin = 0;
  double psnr_db = 0, rmse = 0;
};
// Angular error over the pixels where the reference sees an optical element, and colour error (sRGB 0..1)
// over the same pixels. `errors_arcmin` receives the per-pixel error (NaN outside the element pixels).
ErrorStats compareToReference(const RenderedFrame& ref, const RenderedFrame& mode, std::vector<double>* errors_arcmin,
                              int only_element = -1);

// Per-pixel angular error (arcmin) between two seen points at the reference's element point, over the
// pixels where the reference sees an optical element (NaN elsewhere, and where the angle is not finite).
std::vector<double> angularErrors(const RenderedFrame& ref, const std::vector<Vec3>& ref_seen,
                                  const std::vector<Vec3>& mode_seen);
// Median, p95 and max of the finite errors among the pixels where `region` (if given) equals `value`.
ErrorStats summarizeErrors(const std::vector<double>& errors_arcmin, const std::vector<int8_t>* region = nullptr,
                           int8_t value = 1);

// The zooming region (issue 5; docs/accuracy.md): a pixel is in it when the reference's seen point lies
// behind the fitted viewpoint of the patch under the pixel, along that patch's forward direction:
// (seen - fit.eye) . forward <= 0, where forward is the forward volume's (pvrr/method/view_volume.h: the normalised
// mean of the patch's outgoing ray directions; recomputed from the rays when the patch's volume is the
// reversed one). The patch under a pixel is the patch of the element vertex nearest the reference's element
// point. Per pixel: 1 zooming, 0 not, -1 no element pixel or an element missing from `frames`, 2 not
// classified: the reference path (ref.bounces, when given) has more specular events than the element's own
// (mirror 1, lens 2), so its seen point lies beyond a second element (a mirror seen in a mirror) or a TIR.
std::vector<int8_t> zoomingRegion(const RenderedFrame& ref, const std::vector<ElementFrame>& frames,
                                  const Scene* scene = nullptr);

// Colour fringes (issue 6): the deviation of a channel at a pixel is the angle between the eye ray (eye to
// the element point) and the line from the element point to that channel's seen point. Blue bends more than
// red where deviation(B) > deviation(R). Over the pixels in `mask` (non-zero) whose |deviation(B) -
// deviation(R)| is at least min_difference_arcmin (pixels with no dispersion are left out).
struct FringeStats {
  size_t pixels = 0;                       // pixels counted
  double median_blue_minus_red_arcmin = 0;  // median of deviation(B) - deviation(R)
  double fraction_blue_bends_more = 0;      // fraction of the counted pixels with deviation(B) > deviation(R)
};
FringeStats fringeStats(const Vec3& eye, const std::vector<Vec3>& element_point, const std::vector<Vec3>& red_seen,
                        const std::vector<Vec3>& blue_seen, const std::vector<int8_t>& mask,
                        double min_difference_arcmin = 0.01);

}  // namespace pvrr::app
