// Tessellation speed: a 317 x 317 grid (~100k vertices) with positions, normals and (with arg 1) principal
// curvatures, for rational NURBS surfaces and a sag asphere; items/s counts vertices. Plus one adaptive case.
#include <benchmark/benchmark.h>

#include <cmath>

#include "cad/nurbs.h"
#include "cad/sag.h"
#include "cad/tessellate.h"

namespace {
using namespace pvrr;
using namespace pvrr::cad;

constexpr int kGrid = 317;

// A wavy rational bicubic patch, 8 x 8 poles, non-uniform knots: the general evaluation path.
NurbsSurface wavyBicubic() {
  NurbsDefinition d;
  d.degree_u = d.degree_v = 3;
  d.count_u = d.count_v = 8;
  d.knots_u = {0, 0, 0, 0, 0.1, 0.3, 0.45, 0.7, 1, 1, 1, 1};
  d.knots_v = {0, 0, 0, 0, 0.2, 0.4, 0.6, 0.8, 1, 1, 1, 1};
  for (int i = 0; i < 8; ++i)
    for (int j = 0; j < 8; ++j) {
      d.points.emplace_back(0.03 * i, 0.02 * j, 0.004 * std::sin(0.9 * i) * std::cos(0.7 * j));
      d.weights.push_back(1.0 + 0.2 * std::sin(1.3 * i + 0.4 * j));
    }
  return NurbsSurface(std::move(d), "wavy bicubic");
}

void run(benchmark::State& state, const Surface& s, const Outline* outline) {
  const TessellationOptions opt{state.range(0) != 0};
  for (auto _ : state) {
    Tessellation t = tessellateGrid(s, kGrid, kGrid, outline, opt);
    benchmark::DoNotOptimize(t.positions.data());
  }
  state.SetItemsProcessed(state.iterations() * int64_t(kGrid) * kGrid);
}

void BM_GridNurbsBicubic(benchmark::State& state) {
  const NurbsSurface s = wavyBicubic();
  run(state, s, nullptr);
}
BENCHMARK(BM_GridNurbsBicubic)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_GridNurbsSphereCap(benchmark::State& state) {
  const NurbsSurface s = makeSphereCap(Vec3(0), 1.2, radians(40));
  run(state, s, nullptr);
}
BENCHMARK(BM_GridNurbsSphereCap)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_GridAsphere(benchmark::State& state) {
  const Outline rect = Outline::rectangle(0.2, 0.1, 0.01);
  const SagSurfacePtr s = makeAsphere(1.2, -0.6, {1e-2, -3e-3, 1e-4}, rect);
  run(state, *s, &rect);
}
BENCHMARK(BM_GridAsphere)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();

// Adaptive to 1 µm on a 90 x 50 mm asphere; items/s counts output vertices.
void BM_AdaptiveAsphere(benchmark::State& state) {
  const Outline rect = Outline::rectangle(0.09, 0.05, 0.01);
  const SagSurfacePtr s = makeAsphere(0.12, -0.8, {30.0}, rect);
  size_t vertices = 0;
  for (auto _ : state) {
    Tessellation t = tessellateAdaptive(*s, 1e-6, radians(3), &rect);
    vertices = t.vertexCount();
    benchmark::DoNotOptimize(t.positions.data());
  }
  state.SetItemsProcessed(state.iterations() * int64_t(vertices));
  state.counters["vertices"] = double(vertices);
}
BENCHMARK(BM_AdaptiveAsphere)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
