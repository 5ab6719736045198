// Ambient occlusion from displacement fields (issue 24: "costs under 2 ms a frame at 1280 x 720 on llvmpipe;
// the field's precomputation time and size recorded"). Figures: docs/performance.md "Ambient occlusion".
//
// BM_AoFrame: the same frame with and without ambient occlusion, interleaved in one run (A B A B ...), so that
// the machine's load affects both alike; counters: the median frame of each and their difference (ao_ms), in
// wall-clock and in CPU time of the whole process (cpu_*: llvmpipe's threads included), and the median of the
// pairs' CPU differences (cpu_ao_pair_ms). 60 pairs (20 until the fourth round).
// BM_AoFieldBuild: one occluder's field (the overtaking car's six boxes) at the default sampling.
#include <benchmark/benchmark.h>

#include <sys/resource.h>

#include <algorithm>
#include <vector>

#include "pvrr/gl/context.h"
#include "pvrr/gl/renderer.h"
#include "pvrr/method/ao_field.h"
#include "pvrr/scene/scene_build.h"
#include "pvrr/scene/scene_json.h"

namespace {

using namespace pvrr;

// The scene at t = 1.2 s: the overtaking car beside the driver, seen directly and in the mirror.
Scene load(const std::string& name, std::vector<std::string> sets) {
  const SceneDesc desc = loadScene(std::string(PVRR_SOURCE_DIR) + "/models/" + name + ".json", sets);
  Scene s = buildScene(desc);
  applyAnimation(s, desc, 1.2);
  return s;
}

// The process's CPU time (user + system, every thread: llvmpipe's rasterizer threads included), ms.
double cpuMs() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return (u.ru_utime.tv_sec + u.ru_stime.tv_sec) * 1e3 + (u.ru_utime.tv_usec + u.ru_stime.tv_usec) * 1e-3;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0 : v[v.size() / 2];
}

// `sets`: the view.
void BM_AoFrame(benchmark::State& state, const char* name, RenderMode mode, std::vector<std::string> sets) {
  auto ctx = gl::GlContext::create(gl::glBackendFromEnvironment(gl::GlBackend::Auto));
  sets.push_back("observer.image_size=[1280,720]");
  Scene off = load(name, sets);
  sets.push_back("render.ambient_occlusion=true");
  Scene on = load(name, sets);
  RayScene rays_off(off), rays_on(on);
  gl::RendererOptions opt;
  opt.read_back = false;
  opt.seen_points = false;  // the picture only, as pvrr render draws it
  gl::Renderer r_off(off, rays_off, opt), r_on(on, rays_on, opt);
  r_off.render(mode);  // warm-up: shader compilation (and, with ambient occlusion, the fields)
  r_on.render(mode);  // (the vertex-value grids are made while the first frame draws: noted from the second)
  const gl::RasterFrame first = r_on.render(mode);
  std::vector<double> with, without, cpu_with, cpu_without;
  for (auto _ : state) {
    double c0 = cpuMs();
    without.push_back(r_off.render(mode).frame_ms);
    double c1 = cpuMs();
    with.push_back(r_on.render(mode).frame_ms);
    cpu_without.push_back(c1 - c0);
    cpu_with.push_back(cpuMs() - c1);
  }
  const StageTiming* stage = first.stages.find("ambient-occlusion");
  state.counters["frame_ms"] = median(without);
  state.counters["frame_ao_ms"] = median(with);
  state.counters["ao_ms"] = median(with) - median(without);
  // CPU time, which the machine's load inflates less than the wall clock.
  state.counters["cpu_frame_ms"] = median(cpu_without);
  state.counters["cpu_frame_ao_ms"] = median(cpu_with);
  state.counters["cpu_ao_ms"] = median(cpu_with) - median(cpu_without);
  // The median of the pairs' differences (each frame with against the frame without just before it): steadier
  // than the difference of the medians where the load drifts during the run.
  std::vector<double> pairs(cpu_with.size());
  for (size_t i = 0; i < pairs.size(); ++i) pairs[i] = cpu_with[i] - cpu_without[i];
  state.counters["cpu_ao_pair_ms"] = median(pairs);
  state.counters["fields"] = stage && stage->ran ? stage->count : 0;
  state.SetLabel(ctx->backendName() + " " + ctx->glRenderer() + (stage ? "; " + stage->note + stage->reason : ""));
}
const std::vector<std::string> kOvertaking = {};
// The driver looking at the overtaking car beside the mirror (its ground fills a quarter of the image).
const std::vector<std::string> kLookAtCar = {"observer.target=[-3.2, 0.5, 4]", "observer.fov_y_deg=60"};
BENCHMARK_CAPTURE(BM_AoFrame, overtaking_pvrr, "overtaking-car", RenderMode::Pvrr, kOvertaking)
    ->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(60);
BENCHMARK_CAPTURE(BM_AoFrame, overtaking_raster_car_in_view, "overtaking-car", RenderMode::Raster, kLookAtCar)
    ->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(60);

// One renderer alone (with or without ambient occlusion), for a profiler (perf record, one run each): not part of
// the measured figures.
void BM_AoProfile(benchmark::State& state, const char* name, RenderMode mode, std::vector<std::string> sets, bool ao) {
  auto ctx = gl::GlContext::create(gl::glBackendFromEnvironment(gl::GlBackend::Auto));
  sets.push_back("observer.image_size=[1280,720]");
  if (ao) sets.push_back("render.ambient_occlusion=true");
  Scene s = load(name, sets);
  RayScene rays(s);
  gl::RendererOptions opt;
  opt.read_back = false;
  opt.seen_points = false;
  gl::Renderer r(s, rays, opt);
  r.render(mode);
  r.render(mode);
  for (auto _ : state) r.render(mode);
}
BENCHMARK_CAPTURE(BM_AoProfile, pvrr_on, "overtaking-car", RenderMode::Pvrr, kOvertaking, true)
    ->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(200);
BENCHMARK_CAPTURE(BM_AoProfile, pvrr_off, "overtaking-car", RenderMode::Pvrr, kOvertaking, false)
    ->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(200);
BENCHMARK_CAPTURE(BM_AoProfile, raster_on, "overtaking-car", RenderMode::Raster, kLookAtCar, true)
    ->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(200);
BENCHMARK_CAPTURE(BM_AoProfile, raster_off, "overtaking-car", RenderMode::Raster, kLookAtCar, false)
    ->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(200);

void BM_AoFieldBuild(benchmark::State& state) {
  Scene s = load("overtaking-car", {"render.ambient_occlusion=true"});
  const AmbientOcclusionDesc& a = s.render.ambient_occlusion;
  size_t bytes = 0;
  for (auto _ : state) {
    const AoField f = buildAoField(s, 0, a.positions, a.directions);
    bytes = f.bytes();
    benchmark::DoNotOptimize(f.data.data());
  }
  state.counters["bytes"] = double(bytes);
  state.counters["rays"] = double(bytes);
}
BENCHMARK(BM_AoFieldBuild)->Unit(benchmark::kMillisecond)->Iterations(3);

}  // namespace

BENCHMARK_MAIN();
