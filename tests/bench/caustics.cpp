// The raster caustics' CPU plan (planCaustics, pvrr/method/caustic_mesh.h: the photon meshes traced with Embree,
// the receivers and their windows) on the curved-receiver and sheet scenes of tests/gl/caustic/caustic_test.cpp,
// against the same beam on a flat receiver. CPU time is the process's (the TBB workers included). Counters: exact
// photons traced, receivers mapped. Figures:
// docs/performance.md "Caustics".
#include <benchmark/benchmark.h>

#include "pvrr/method/caustic_mesh.h"
#include "pvrr/method/receiver_sheets.h"
#include "support/height_field.h"

namespace {

using namespace pvrr;

// The plane mirror's beam along +x onto a receiver at x = 0.4 (test::addBeamOnReceiver).
Scene beamScene(const char* which) {
  Scene s;
  s.observer.eye = Vec3(0.3, 0.3, 0.3);
  s.observer.target = Vec3(0.4, 0, 0);
  const std::string w = which;
  test::addBeamOnReceiver(s, test::grazingWaves(w == "flat" ? 0.0 : 0.002), 240, 60, "receiver");
  if (w == "box") {
    const double t = radians(30);
    const Mat3 rot(Vec3(std::cos(t), std::sin(t), 0), Vec3(-std::sin(t), std::cos(t), 0), Vec3(0, 0, 1));
    s.meshes[0] = makeBoxMesh(Vec3(0.4, 0, 0), Vec3(0.04), rot);
  } else if (w == "sphere") {
    s.meshes[0] = makeSphereMesh(Vec3(0.45, 0, 0), 0.03, 96, 48);
  }
  s.updateBounds();
  return s;
}

void BM_CausticPlan(benchmark::State& state, const char* which) {
  const Scene s = beamScene(which);
  RayScene rays(s);
  CausticPlan plan;
  for (auto _ : state) plan = planCaustics(rays, CausticPlanOptions{});
  state.counters["traced"] = double(plan.traced);
  state.counters["receivers"] = double(plan.receivers.size());
}
BENCHMARK_CAPTURE(BM_CausticPlan, flat, "flat")->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime();
BENCHMARK_CAPTURE(BM_CausticPlan, waves, "waves")->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime();
BENCHMARK_CAPTURE(BM_CausticPlan, box_sheets, "box")->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime();
BENCHMARK_CAPTURE(BM_CausticPlan, sphere_sheets, "sphere")->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime();

// The split alone: a sphere of 96 x 48 and of 256 x 128 facets.
void BM_SplitIntoSheets(benchmark::State& state) {
  const EnvMesh m = makeSphereMesh(Vec3(0), 0.05, int(state.range(0)), int(state.range(0)) / 2);
  for (auto _ : state) benchmark::DoNotOptimize(splitIntoSheets(m));
  state.counters["triangles"] = double(m.triangles.size());
}
BENCHMARK(BM_SplitIntoSheets)->Arg(96)->Arg(256)->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime();

}  // namespace
BENCHMARK_MAIN();
