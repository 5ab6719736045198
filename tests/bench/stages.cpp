// Stage benchmarks on the default scenes: the per-vertex stages (issue 5: 2,000 vertices, goal <= 1 ms) and
// full raster frames at 1280 x 720 in each mode (issue 5: car mirror on OSMesa, goal >= 60 fps). Reference
// rays per second and reference frames: bench/rays.cpp. Figures: docs/performance.md.
#include <benchmark/benchmark.h>

#include "pvrr/gl/context.h"
#include "pvrr/gl/renderer.h"
#include "pvrr/scene/scene_build.h"
#include "pvrr/scene/scene_json.h"

namespace {

using namespace pvrr;

Scene loadDefault(const std::string& name, std::vector<std::string> sets = {}) {
  return buildScene(loadScene(std::string(PVRR_SOURCE_DIR) + "/models/" + name + ".json", sets));
}

// Per-vertex stages on the car mirror with a 45 x 45 grid (2,025 vertices), as each frame runs them: the
// mirror's tangent clearance (RayScene::tangentClearance, which lets its rays be traced beside it) is computed
// in the first iteration and kept, as the renderer keeps it while the grid stays; BM_TangentClearance times it.
void BM_VertexStages(benchmark::State& state) {
  Scene s = loadDefault("car-mirror", {"elements[0].tessellation=45"});
  RayScene rays(s);
  ElementFrame f = prepareElement(s, 0);
  VertexStageOptions opt;
  double rays_ms = 0, fit_ms = 0;
  for (auto _ : state) {
    traceVertexRays(rays, f, s.observer.eye, opt);
    fitPatchViews(s, f, opt);
    rays_ms += f.rays_ms;
    fit_ms += f.fit_ms;
  }
  state.counters["vertices"] = double(f.world_pos.size());
  state.counters["beside"] = double(f.rays_beside);
  state.counters["rays_ms"] = rays_ms / double(state.iterations());
  state.counters["fit_ms"] = fit_ms / double(state.iterations());
}
BENCHMARK(BM_VertexStages)->Unit(benchmark::kMillisecond);

// RayScene::tangentClearance for the car mirror's 45 x 45 grid against its 96 x 96 candidates: computed once
// per grid (kept while the grid stays), here every iteration (two grids a micrometre apart, alternately).
void BM_TangentClearance(benchmark::State& state) {
  Scene s = loadDefault("car-mirror", {"elements[0].tessellation=45"});
  RayScene rays(s);
  const ElementFrame f = prepareElement(s, 0);
  std::vector<Vec3> moved = f.grid.positions;
  for (Vec3& p : moved) p.z += 1e-6;
  bool flip = false;
  for (auto _ : state) {
    benchmark::DoNotOptimize(rays.tangentClearance(0, flip ? moved : f.grid.positions, f.grid.normals));
    flip = !flip;
  }
}
BENCHMARK(BM_TangentClearance)->Unit(benchmark::kMillisecond);

// A full raster frame at 1280 x 720 (GPU finished) on the backend named by PVRR_GL (default auto).
void BM_RasterFrame(benchmark::State& state, const char* scene, RenderMode mode) {
  auto ctx = gl::GlContext::create(gl::glBackendFromEnvironment(gl::GlBackend::Auto));
  Scene s = loadDefault(scene, {"observer.image_size=[1280,720]"});
  RayScene rays(s);
  gl::RendererOptions opt;
  opt.read_back = false;
  opt.seen_points = false;  // the picture only, as pvrr render draws it
  gl::Renderer r(s, rays, opt);
  r.render(mode);  // warm-up: shader compilation
  for (auto _ : state) benchmark::DoNotOptimize(r.render(mode).frame_ms);
  state.SetLabel(ctx->backendName() + " " + ctx->glRenderer());
}
BENCHMARK_CAPTURE(BM_RasterFrame, car_mirror_pvrr, "car-mirror", RenderMode::Pvrr)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_RasterFrame, car_mirror_envmap, "car-mirror", RenderMode::Envmap)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_RasterFrame, car_mirror_raster, "car-mirror", RenderMode::Raster)->Unit(benchmark::kMillisecond)->UseRealTime();
// The distance-impostor glass mode: six cube faces at the scene's map size, then per-fragment searches (a
// spectacle lens fills the image).
BENCHMARK_CAPTURE(BM_RasterFrame, car_mirror_impostor, "car-mirror", RenderMode::Impostor)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_RasterFrame, spectacle_lens_impostor, "spectacle-lens", RenderMode::Impostor)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_RasterFrame, spectacle_lens_pvrr, "spectacle-lens", RenderMode::Pvrr)->Unit(benchmark::kMillisecond)->UseRealTime();
// A mirror seen in a mirror: pvrr's nested first passes, and the impostor's two elements' cubes with the other
// mirror drawn in each (a third cube of normals), followed per fragment.
BENCHMARK_CAPTURE(BM_RasterFrame, mirror_pair_pvrr, "mirror-pair", RenderMode::Pvrr)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_RasterFrame, mirror_pair_impostor, "mirror-pair", RenderMode::Impostor)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
