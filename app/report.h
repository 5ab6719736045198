// What render, compare and the reports share: one rendered frame in any mode, a GL session reused across
// frames, and the JSON pieces of the stats.
#pragma once
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
};

RenderedFrame renderFrame(LoadedScene& ls, const std::string& mode, const std::string& gl_backend_name,
                          RenderSession* session);
// A measured frame: one warm-up, then the median frame time of `frames` frames, each doing every stage.
RenderedFrame timedFrame(LoadedScene& ls, const std::string& mode, const std::string& gl_backend_name, int frames,
                         double* median_ms);
nlohmann::json elementsJson(const Scene& scene, const std::vector<ElementFrame>& frames);
// Per-vertex data as VTK PolyData (.vtp) for ParaView: the grid of each element with point arrays.
void writeVerticesVtp(const std::string& path, const Scene& scene, const std::vector<ElementFrame>& frames);
// A tessellation as OBJ (v, vn, f v//vn), PLY or VTP, chosen by extension; atomic.
void writeTessellation(const std::string& path, const cad::Tessellation& t);

// Peak resident memory of this process so far (VmHWM), in MB.
double peakRssMb();

struct ErrorStats {
  size_t pixels = 0;
  double median_arcmin = 0, p95_arcmin = 0, max_arcmin = 0;
  double psnr_db = 0, rmse = 0;
};
// Angular error over the pixels where the reference sees an optical element, and colour error (sRGB 0..1)
// over the same pixels. `errors_arcmin` receives the per-pixel error (NaN outside the element pixels).
ErrorStats compareToReference(const RenderedFrame& ref, const RenderedFrame& mode, std::vector<double>* errors_arcmin,
                              int only_element = -1);

}  // namespace pvrr::app
