// Reference-tracer ray throughput (issue 4): exact RayScene::intersect() queries per second, incoherent and
// secondary rays on one thread and on all threads (TBB), primary rays as single rays and as 4 x 4 packets,
// and the reference frame at 1280 x 720 for every default scene (car mirror and spectacle lens also without
// primary packets).
// Incoherent and secondary rays are also measured as incoherent 16-ray packets (what Embree's packet
// kernels give without the coherent flag; the tracer itself traces secondary rays one by one).
// Goal: >= 20 M incoherent rays/s on 2 cores. The figure of interest is items_per_second (rays/s, or
// pixels/s for frames). Arg "threads": the number of TBB threads (counter tbb_threads), 0 = all (std::thread::hardware_concurrency()).
#include <benchmark/benchmark.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>
#include <xmmintrin.h>
#include <pmmintrin.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <random>
#include <string>
#include <thread>
#include <vector>
#include <time.h>

#include "pvrr/optics/optics.h"
#include "pvrr/scene/scene_build.h"
#include "pvrr/scene/scene_json.h"
#include "pvrr/trace/tracer.h"

namespace {

using namespace pvrr;

Scene loadDefault(const std::string& name, std::vector<std::string> sets = {}) {
  return buildScene(loadScene(std::string(PVRR_SOURCE_DIR) + "/models/" + name + ".json", sets));
}

int threadsOf(const benchmark::State& state) {
  const int n = int(state.range(0));
  return n > 0 ? n : int(std::max(1u, std::thread::hardware_concurrency()));
}

// CPU time of the whole process (all threads), in seconds. The machine is shared: where other work competes
// for the cores, wall-clock rates drop but the CPU time per item stays put, so both are reported
// ("cpu_ns_per_item": process CPU nanoseconds per ray or pixel, summed over threads).
double processCpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

void setCpuPerItem(benchmark::State& state, double cpu_s, double items_per_iteration) {
  state.counters["cpu_ns_per_item"] = 1e9 * cpu_s / (double(state.iterations()) * items_per_iteration);
}

struct Ray {
  Vec3 o, d;
  double t_min;
};

// Runs f(i) for i in [0, n) on `threads` TBB workers, FTZ/DAZ set in each (as Tracer::render does); returns
// the number of rays that hit something.
template <class F>
size_t parallelCount(int threads, size_t n, size_t grain, const F& f) {
  tbb::task_arena arena(threads);
  std::atomic<size_t> hits{0};
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, grain), [&](const tbb::blocked_range<size_t>& r) {
      _MM_SET_FLUSH_ZERO_MODE(_MM_FLUSH_ZERO_ON);
      _MM_SET_DENORMALS_ZERO_MODE(_MM_DENORMALS_ZERO_ON);
      size_t local = 0;
      for (size_t i = r.begin(); i < r.end(); ++i) local += f(i);
      hits += local;
    });
  });
  return hits.load();
}

// Arg 0: threads (0 = all); arg 1: 1 = 16-ray packets without the coherent flag (RayScene::intersectPacket),
// 0 = one intersect() per ray (what the tracer does for secondary rays).
void runRays(benchmark::State& state, const RayScene& rays, const std::vector<Ray>& batch) {
  const int threads = threadsOf(state);
  const bool packets = state.range(1) != 0;
  size_t hits = 0;
  constexpr size_t P = RayScene::kPacketSize;
  const double cpu0 = processCpuSeconds();
  for (auto _ : state) {
    if (!packets) {
      hits += parallelCount(threads, batch.size(), 1024,
                            [&](size_t i) { return rays.intersect(batch[i].o, batch[i].d, batch[i].t_min).hit(); });
      continue;
    }
    // The batch's t_min is one value (0 or the scene epsilon), so a packet can share it.
    hits += parallelCount(threads, (batch.size() + P - 1) / P, 64, [&](size_t p) {
      std::array<Vec3, P> o, d;
      std::array<RayHit, P> h;
      const size_t first = p * P, count = std::min(P, batch.size() - first);
      for (size_t k = 0; k < count; ++k) {
        o[k] = batch[first + k].o;
        d[k] = batch[first + k].d;
      }
      rays.intersectPacket(o.data(), d.data(), int(count), h.data(), batch[first].t_min, kInf, false);
      size_t n = 0;
      for (size_t k = 0; k < count; ++k) n += h[k].hit();
      return n;
    });
  }
  setCpuPerItem(state, processCpuSeconds() - cpu0, double(batch.size()));
  state.counters["tbb_threads"] = threads;
  state.counters["hit_fraction"] = double(hits) / double(state.iterations()) / double(batch.size());
  state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(batch.size()));
}

// Incoherent rays: random origins in the car-mirror street, uniformly random directions.
void BM_IncoherentRays(benchmark::State& state) {
  Scene s = loadDefault("car-mirror");
  RayScene rays(s);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  const Vec3 c = 0.5 * (s.bounds_min + s.bounds_max), half = 0.5 * (s.bounds_max - s.bounds_min);
  std::vector<Ray> batch(1 << 18);
  for (Ray& r : batch) {
    r.o = c + Vec3(u(rng) * half.x, u(rng) * 0.5 * half.y, u(rng) * half.z);
    Vec3 d;
    do d = Vec3(u(rng), u(rng), u(rng));
    while (glm::dot(d, d) > 1.0 || glm::dot(d, d) < 1e-6);
    r.d = glm::normalize(d);
    r.t_min = 0;
  }
  runRays(state, rays, batch);
}
BENCHMARK(BM_IncoherentRays)
    ->ArgsProduct({{1, 0}, {0, 1}})->ArgNames({"threads", "packets"})->Unit(benchmark::kMillisecond)->UseRealTime();

// Secondary rays as the tracer makes them: the reflections of the car mirror's primary hits at 1280 x 720
// (origins on the mirror, t_min = the scene epsilon).
void BM_SecondaryRays(benchmark::State& state) {
  Scene s = loadDefault("car-mirror", {"observer.image_size=[1280,720]"});
  RayScene rays(s);
  const Observer& ob = s.observer;
  std::vector<Ray> batch;
  for (int y = 0; y < ob.height; ++y)
    for (int x = 0; x < ob.width; ++x) {
      const Vec3 d = ob.pixelDirection(x + 0.5, y + 0.5);
      const RayHit h = rays.intersect(ob.eye, d);
      if (h.kind == HitKind::Element) batch.push_back({h.point, reflect(d, h.normal), rays.epsilon()});
    }
  state.counters["rays"] = double(batch.size());
  runRays(state, rays, batch);
}
BENCHMARK(BM_SecondaryRays)
    ->ArgsProduct({{1, 0}, {0, 1}})->ArgNames({"threads", "packets"})->Unit(benchmark::kMillisecond)->UseRealTime();

// Primary rays of a 1280 x 720 frame, in 4 x 4 tiles: one intersect() per ray, or one intersectPacket() per
// tile. Arg 0: threads (0 = all); arg 1: 1 = packets.
void BM_PrimaryRays(benchmark::State& state, const char* scene) {
  Scene s = loadDefault(scene, {"observer.image_size=[1280,720]"});
  RayScene rays(s);
  const Observer& ob = s.observer;
  const bool packets = state.range(1) != 0;
  const int threads = threadsOf(state);
  const int tiles_x = ob.width / 4, tiles = tiles_x * (ob.height / 4);
  std::vector<std::array<Vec3, 16>> dirs(static_cast<size_t>(tiles));
  for (int t = 0; t < tiles; ++t)
    for (int k = 0; k < 16; ++k)
      dirs[size_t(t)][size_t(k)] =
          ob.pixelDirection((t % tiles_x) * 4 + k % 4 + 0.5, (t / tiles_x) * 4 + k / 4 + 0.5);
  std::array<Vec3, 16> origins;
  origins.fill(ob.eye);
  size_t hits = 0;
  const double cpu0 = processCpuSeconds();
  for (auto _ : state)
    hits += parallelCount(threads, size_t(tiles), 16, [&](size_t t) {
      std::array<RayHit, 16> h;
      if (packets) {
        rays.intersectPacket(origins.data(), dirs[t].data(), 16, h.data());
      } else {
        for (size_t k = 0; k < 16; ++k) h[k] = rays.intersect(ob.eye, dirs[t][k]);
      }
      size_t n = 0;
      for (const RayHit& r : h) n += r.hit();
      return n;
    });
  benchmark::DoNotOptimize(hits);
  setCpuPerItem(state, processCpuSeconds() - cpu0, double(tiles) * 16);
  state.counters["tbb_threads"] = threads;
  state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(tiles) * 16);
}
BENCHMARK_CAPTURE(BM_PrimaryRays, car_mirror, "car-mirror")
    ->ArgsProduct({{1, 0}, {0, 1}})->ArgNames({"threads", "packets"})->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_PrimaryRays, spectacle_lens, "spectacle-lens")
    ->ArgsProduct({{1, 0}, {0, 1}})->ArgNames({"threads", "packets"})->Unit(benchmark::kMillisecond)->UseRealTime();

// The reference frame at 1280 x 720 on all threads (Tracer::render, the scene's own settings except the
// dispersion mode, which is off). Arg: 1 = primary packets.
void BM_ReferenceFrame(benchmark::State& state, const char* scene) {
  Scene s = loadDefault(scene, {"observer.image_size=[1280,720]"});
  RayScene rays(s);
  TraceOptions opt;
  opt.max_depth = s.render.max_depth;
  opt.primary_packets = state.range(0) != 0;
  Tracer t(rays, opt);
  const double cpu0 = processCpuSeconds();
  for (auto _ : state) benchmark::DoNotOptimize(t.render().color.data());
  setCpuPerItem(state, processCpuSeconds() - cpu0, 1280.0 * 720.0);
  state.counters["cpu_ms_per_frame"] = 1e3 * (processCpuSeconds() - cpu0) / double(state.iterations());
  state.counters["tbb_threads"] = double(tbb::this_task_arena::max_concurrency());
  state.SetItemsProcessed(int64_t(state.iterations()) * 1280 * 720);
}
BENCHMARK_CAPTURE(BM_ReferenceFrame, car_mirror, "car-mirror")
    ->Arg(0)->Arg(1)->ArgName("packets")->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(1.0);
BENCHMARK_CAPTURE(BM_ReferenceFrame, spectacle_lens, "spectacle-lens")
    ->Arg(0)->Arg(1)->ArgName("packets")->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(1.0);
// The other default scenes, with primary packets (the tracer's default).
BENCHMARK_CAPTURE(BM_ReferenceFrame, plane_mirror, "plane-mirror")->Arg(1)->ArgName("packets")->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(1.0);
BENCHMARK_CAPTURE(BM_ReferenceFrame, concave_mirror, "concave-mirror")->Arg(1)->ArgName("packets")->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(1.0);
BENCHMARK_CAPTURE(BM_ReferenceFrame, saddle_mirror, "saddle-mirror")->Arg(1)->ArgName("packets")->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(1.0);
BENCHMARK_CAPTURE(BM_ReferenceFrame, mirror_pair, "mirror-pair")->Arg(1)->ArgName("packets")->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(1.0);
BENCHMARK_CAPTURE(BM_ReferenceFrame, reading_lens, "reading-lens")->Arg(1)->ArgName("packets")->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(1.0);
BENCHMARK_CAPTURE(BM_ReferenceFrame, progressive_lens, "progressive-lens")->Arg(1)->ArgName("packets")->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(1.0);

}  // namespace

BENCHMARK_MAIN();
