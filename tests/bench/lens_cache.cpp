// Issue 6: the eye-fixed cached lens frame with dispersion against a plain raster frame of the same scene
// (goal: cached lens frame <= 1.5 x the raster frame). The spectacle lens (-3 D CR-39, attached to the
// observer) with RGB dispersion switched on (three texture-coordinate sets, one shared first pass), at
// 1280 x 720 on the backend named by PVRR_GL.
//   - BM_LensFrame/raster: the plain raster frame (the lens drawn as a surface, no reflection map);
//   - BM_LensFrame/pvrr_fresh: every PVRR stage every frame (no cache);
//   - BM_LensFrame/pvrr_cached_orbit: the head turns 0.05 deg each frame with the spectacles attached:
//     refraction and viewpoint are reused, the scene intersections, texture coordinates and second pass run,
//     and the first pass runs whenever the view leaves the margin of the last maps (map reuse,
//     render.map_reuse_margin_deg: every 2 deg here, i.e. one frame in 40) (the interactive case). 200
//     frames: five map renders and a jump back by 10 deg;
//   - BM_LensFrame/pvrr_cached_still: nothing moved: only the second pass runs.
// Each reports ratio_vs_raster (medians) and mean_ratio_vs_raster (means: the occasional map render
// included), measured against a raster run inside the same benchmark (same load), the slowest frame
// (max_ms) and the share of frames that drew a first pass (first_pass_share).
// Figures: docs/performance.md (scripts/measure).
#include <benchmark/benchmark.h>

#include <algorithm>

#include <glm/gtc/matrix_transform.hpp>

#include "pvrr/gl/context.h"
#include "pvrr/gl/renderer.h"
#include "pvrr/scene/scene_build.h"
#include "pvrr/scene/scene_json.h"
#include "pvrr/optics/spectrum.h"

namespace {

using namespace pvrr;

enum class Variant { Raster, Fresh, CachedOrbit, CachedStill };

double medianMs(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

double meanMs(const std::vector<double>& v) {
  double sum = 0;
  for (double x : v) sum += x;
  return v.empty() ? 0.0 : sum / double(v.size());
}

void frameVsRaster(benchmark::State& state, const std::string& scene, const std::vector<std::string>& sets,
                   Variant variant) {
  auto ctx = gl::GlContext::create(gl::glBackendFromEnvironment(gl::GlBackend::Auto));
  SceneDesc desc = loadScene(std::string(PVRR_SOURCE_DIR) + "/models/" + scene + ".json", sets);
  Scene s = buildScene(desc);
  const bool attached = std::any_of(s.elements.begin(), s.elements.end(), [](const Element& e) { return e.attached_to_observer; });
  RaySceneOptions ro;
  ro.moving_elements = variant == Variant::CachedOrbit && attached;  // as pvrr render --orbit does
  RayScene rays(s, ro);
  gl::RendererOptions opt;
  opt.read_back = false;
  opt.seen_points = false;  // the picture only, as pvrr render draws it
  opt.vertex.channels.clear();  // each element's own: dispersionChannels() gives the lens R, G and B
  gl::Renderer r(s, rays, opt);
  gl::FrameCache cache;
  const Vec3 eye0 = s.observer.eye, target0 = s.observer.target;
  int frame = 0;
  auto turnHead = [&] {
    // 0.05 deg per frame about the vertical axis through the eye; the spectacles turn with the head.
    const Mat4 rot = glm::rotate(Mat4(1.0), radians(0.05 * (frame % 200)), s.observer.up);
    s.observer.target = eye0 + Vec3(rot * Vec4(target0 - eye0, 0.0));
    if (attached) {
      updateAttachedElements(s, desc);
      rays.updateElementPoses();
    }
    cache.environment_changed = false;
    ++frame;
  };
  int first_passes = 0;
  auto renderOnce = [&](Variant v) {
    gl::RasterFrame f;
    switch (v) {
      case Variant::Raster: f = r.render(RenderMode::Raster); break;
      case Variant::Fresh: f = r.render(RenderMode::Pvrr); break;
      case Variant::CachedOrbit: turnHead(); f = r.render(RenderMode::Pvrr, &cache); break;
      case Variant::CachedStill:
        cache.environment_changed = false;
        f = r.render(RenderMode::Pvrr, &cache);
        break;
    }
    for (const StageTiming& t : f.stages.stages) first_passes += t.name == "first-pass" && t.ran;
    return f.frame_ms;
  };
  renderOnce(Variant::Raster);  // warm-up: shader compilation, first cache fill
  renderOnce(variant);
  first_passes = 0;
  std::vector<double> mine, raster;
  for (auto _ : state) {
    mine.push_back(renderOnce(variant));
    state.PauseTiming();
    raster.push_back(renderOnce(Variant::Raster));  // the same scene as a plain raster frame (no first pass)
    state.ResumeTiming();
  }
  state.counters["frame_ms"] = medianMs(mine);
  state.counters["raster_ms"] = medianMs(raster);
  state.counters["ratio_vs_raster"] = medianMs(mine) / medianMs(raster);
  state.counters["mean_ratio_vs_raster"] = meanMs(mine) / meanMs(raster);
  state.counters["max_ms"] = mine.empty() ? 0.0 : *std::max_element(mine.begin(), mine.end());
  state.counters["first_pass_share"] = mine.empty() ? 0.0 : double(first_passes) / double(mine.size());
  state.SetLabel(ctx->backendName() + " " + ctx->glRenderer());
}
void BM_LensFrame(benchmark::State& state, Variant variant) {
  frameVsRaster(state, "spectacle-lens", {"observer.image_size=[1280,720]", "render.dispersion=rgb"}, variant);
}
// Issue 5: the default scene's car mirror at 1280 x 720 the same ways: every stage every frame (fresh), and
// the driver's head turning 0.05 deg a frame about the eye (orbit: the vertex stages every frame, the mirror's
// viewpoint unmoved, its maps reused while the view stays inside their margin).
void BM_CarMirrorFrame(benchmark::State& state, Variant variant) {
  frameVsRaster(state, "car-mirror", {"observer.image_size=[1280,720]"}, variant);
}

BENCHMARK_CAPTURE(BM_LensFrame, raster, Variant::Raster)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_LensFrame, pvrr_fresh, Variant::Fresh)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_LensFrame, pvrr_cached_orbit, Variant::CachedOrbit)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(200);
BENCHMARK_CAPTURE(BM_CarMirrorFrame, pvrr_fresh, Variant::Fresh)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_CarMirrorFrame, pvrr_orbit, Variant::CachedOrbit)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(200);
BENCHMARK_CAPTURE(BM_LensFrame, pvrr_cached_still, Variant::CachedStill)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
