// Stage benchmarks on the default scenes: the per-vertex stages (issue 5: 2,000 vertices, goal <= 1 ms),
// reference rays per second (issue 4: goal >= 20 M incoherent rays/s on 2 cores), and full frames at
// 1280 x 720 in each mode (issue 5: car mirror on OSMesa, goal >= 60 fps). Figures: docs/performance.md.
#include <benchmark/benchmark.h>

#include <random>

#include "pvrr/gl/context.h"
#include "pvrr/gl/renderer.h"
#include "pvrr/scene_build.h"
#include "pvrr/scene_json.h"
#include "pvrr/tracer.h"

namespace {

using namespace pvrr;

Scene loadDefault(const std::string& name, std::vector<std::string> sets = {}) {
  return buildScene(loadScene(std::string(PVRR_SOURCE_DIR) + "/models/" + name + ".json", sets));
}

// Per-vertex stages on the car mirror with a 45 x 45 grid (2,025 vertices).
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
  state.counters["rays_ms"] = rays_ms / double(state.iterations());
  state.counters["fit_ms"] = fit_ms / double(state.iterations());
}
BENCHMARK(BM_VertexStages)->Unit(benchmark::kMillisecond);

// Incoherent rays: random origins in the car-mirror street, random directions (one thread per core).
void BM_IncoherentRays(benchmark::State& state) {
  Scene s = loadDefault("car-mirror");
  RayScene rays(s);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  const Vec3 c = 0.5 * (s.bounds_min + s.bounds_max), half = 0.5 * (s.bounds_max - s.bounds_min);
  std::vector<std::pair<Vec3, Vec3>> batch(1 << 16);
  for (auto& r : batch) {
    r.first = c + Vec3(u(rng) * half.x, u(rng) * 0.5 * half.y, u(rng) * half.z);
    r.second = glm::normalize(Vec3(u(rng), u(rng), u(rng)) + Vec3(1e-9));
  }
  size_t hits = 0;
  for (auto _ : state)
    for (const auto& r : batch) hits += rays.intersect(r.first, r.second).hit();
  benchmark::DoNotOptimize(hits);
  state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(batch.size()));
}
BENCHMARK(BM_IncoherentRays)->Unit(benchmark::kMillisecond)->UseRealTime();

// The reference frame at 1280 x 720 (multithreaded).
void BM_ReferenceFrame(benchmark::State& state, const char* scene) {
  Scene s = loadDefault(scene, {"observer.image_size=[1280,720]"});
  RayScene rays(s);
  Tracer t(rays, TraceOptions{});
  for (auto _ : state) benchmark::DoNotOptimize(t.render().color.data());
  state.SetItemsProcessed(int64_t(state.iterations()) * 1280 * 720);
}
BENCHMARK_CAPTURE(BM_ReferenceFrame, car_mirror, "car-mirror")->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(3);
BENCHMARK_CAPTURE(BM_ReferenceFrame, spectacle_lens, "spectacle-lens")->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(3);

// A full raster frame at 1280 x 720 (GPU finished) on the backend named by PVRR_GL (default auto).
void BM_RasterFrame(benchmark::State& state, const char* scene, gl::RasterMode mode) {
  auto ctx = gl::GlContext::create(gl::glBackendFromEnvironment(gl::GlBackend::Auto));
  Scene s = loadDefault(scene, {"observer.image_size=[1280,720]"});
  RayScene rays(s);
  gl::RendererOptions opt;
  opt.read_back = false;
  gl::Renderer r(s, rays, opt);
  r.render(mode);  // warm-up: shader compilation
  for (auto _ : state) benchmark::DoNotOptimize(r.render(mode).frame_ms);
  state.SetLabel(ctx->backendName() + " " + ctx->glRenderer());
}
BENCHMARK_CAPTURE(BM_RasterFrame, car_mirror_pvrr, "car-mirror", gl::RasterMode::Pvrr)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_RasterFrame, car_mirror_envmap, "car-mirror", gl::RasterMode::Envmap)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_RasterFrame, car_mirror_raster, "car-mirror", gl::RasterMode::Raster)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
