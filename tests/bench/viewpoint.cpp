// Virtual viewpoint fit and view volume: closed form alone, the default (closed form + own Gauss-Newton),
// Ceres (autodiff, DENSE_QR) as the refining solver, and the view volume, for 49, 2000 and 10000 rays.
// Rays: a convex spherical cap (R = 1.2 m, 0.2 m across, Fibonacci-spiral vertices) reflecting an eye 1 m
// off-axis; hit distances 1-25 m.
#include <benchmark/benchmark.h>

#include <cmath>

#include "pvrr/method/view_volume.h"
#include "pvrr/method/viewpoint.h"

namespace {

using namespace pvrr;

std::vector<ViewpointRay> convexCap(int n) {
  const double R = 1.2, half_m = 0.1;
  const Vec3 centre(0, 0, -R), eye(0.3, 0.2, 1.0);
  std::vector<ViewpointRay> rays;
  rays.reserve(size_t(n));
  const double golden = kPi * (3.0 - std::sqrt(5.0));
  for (int k = 0; k < n; ++k) {
    const double r = half_m * std::sqrt((k + 0.5) / n), a = golden * k;
    const Vec3 radial = glm::normalize(Vec3(r * std::cos(a), r * std::sin(a), 0.0) - centre);
    const Vec3 o = centre + R * radial;
    const Vec3 i = glm::normalize(o - eye);
    const Vec3 d = i - 2.0 * glm::dot(i, radial) * radial;
    const double t = 1.0 + 24.0 * std::fmod(0.618034 * (k + 1), 1.0);
    rays.push_back({o, d, o + t * d});
  }
  return rays;
}

void fit(benchmark::State& state, ViewpointSolver solver) {
  const auto rays = convexCap(int(state.range(0)));
  ViewpointOptions opt;
  opt.solver = solver;
  int iterations = 0;
  bool accepted = true;
  for (auto _ : state) {
    const ViewpointFit f = fitViewpoint(rays, opt);
    benchmark::DoNotOptimize(f.eye);
    iterations = f.iterations;
    accepted = accepted && f.accepted;
  }
  state.counters["iterations"] = iterations;
  state.counters["accepted"] = accepted;
  state.SetItemsProcessed(state.iterations() * state.range(0));
}

void BM_ClosedForm(benchmark::State& s) { fit(s, ViewpointSolver::kClosedForm); }
void BM_DefaultGaussNewton(benchmark::State& s) { fit(s, ViewpointSolver::kAuto); }
void BM_Ceres(benchmark::State& s) { fit(s, ViewpointSolver::kCeres); }

void BM_ViewVolume(benchmark::State& state) {
  const auto rays = convexCap(int(state.range(0)));
  const Vec3 eye = fitViewpoint(rays).eye;
  for (auto _ : state) {
    const ViewVolume vv = buildViewVolume(eye, rays);
    benchmark::DoNotOptimize(vv.projection);
  }
  state.SetItemsProcessed(state.iterations() * state.range(0));
}

BENCHMARK(BM_ClosedForm)->Arg(49)->Arg(2000)->Arg(10000)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_DefaultGaussNewton)->Arg(49)->Arg(2000)->Arg(10000)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Ceres)->Arg(49)->Arg(2000)->Arg(10000)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_ViewVolume)->Arg(49)->Arg(2000)->Arg(10000)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
