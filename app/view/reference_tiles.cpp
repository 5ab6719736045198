#include "app/view/reference_tiles.h"

#include <pmmintrin.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>
#include <xmmintrin.h>

#include <algorithm>
#include <chrono>
#include <cmath>

#include "pvrr/base/image.h"
#include "pvrr/method/reference_setup.h"
#include "pvrr/trace/ray_scene.h"
#include "pvrr/trace/tracer.h"

namespace pvrr::app::view {
namespace {

// Nice value of the tracing threads: the window's own thread keeps its frame rate while they run.
constexpr int kTracingNice = 10;
// How often a run waiting for the mode's frame looks for a cancel (ms).
constexpr int kWaitStepMs = 5;

void prepareTracingThread() {
  // Denormals only slow the traversal down; flushed in every tracing thread, as Tracer::render does.
  _MM_SET_FLUSH_ZERO_MODE(_MM_FLUSH_ZERO_ON);
  _MM_SET_DENORMALS_ZERO_MODE(_MM_DENORMALS_ZERO_ON);
  setpriority(PRIO_PROCESS, id_t(syscall(SYS_gettid)), kTracingNice);  // best effort: this thread only
}

}  // namespace

ReferenceRun::ReferenceRun(std::shared_ptr<const Scene> scene, std::shared_future<Frame> mode_frame, int threads)
    : scene_(std::move(scene)),
      mode_frame_(std::move(mode_frame)),
      width_(scene_->observer.width),
      height_(scene_->observer.height),
      threads_(std::max(1, threads)) {
  tiles_x_ = (width_ + kTile - 1) / kTile;
  tile_count_ = tiles_x_ * ((height_ + kTile - 1) / kTile);
  thread_ = std::thread([this] { run(); });
}

void ReferenceRun::allocate() {
  const size_t n = size_t(width_) * size_t(height_);
  ref_.width = width_;
  ref_.height = height_;
  ref_.color.assign(n, Vec3(0));
  ref_.seen.assign(n, Vec3(0));
  ref_.element.assign(n, -1);
  ref_.element_point.assign(n, Vec3(0));
  ref_.bounces.assign(n, 0);
  ref_.depth_limited.assign(n, 0);
  rgba_.assign(n * 4, 0);
}

ReferenceRun::~ReferenceRun() {
  cancel_ = true;
  if (thread_.joinable()) thread_.join();
}

double ReferenceRun::fraction() const {
  return tile_count_ == 0 ? 1.0 : double(tiles_done_.load()) / double(tile_count_);
}

std::vector<TileRect> ReferenceRun::takeTiles() {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<TileRect> out;
  out.swap(new_tiles_);
  return out;
}

void ReferenceRun::run() {
  // An exception must not leave a thread: it is kept for the window to show.
  try {
    traceAndMeasure();
  } catch (const std::exception& e) {
    fail(e.what());
  }
}

void ReferenceRun::fail(const std::string& why) {
  std::lock_guard<std::mutex> lock(mutex_);
  cancel_ = true;  // the other threads stop after their tile
  if (failed_) return;
  failure_ = why;
  failed_.store(true, std::memory_order_release);
}

void ReferenceRun::traceAndMeasure() {
  prepareTracingThread();
  const auto t0 = std::chrono::steady_clock::now();
  allocate();
  // The scene's own Embree scene and tracer, set up as pvrr render and compare set up the reference: with the
  // caustic light of the lights with caustics on (seconds before the first tile, on this thread; a cancel is
  // heard after it).
  RayScene rays(*scene_);
  const ReferenceSetup setup(rays);
  if (cancel_) return;
  const Tracer tracer(rays, setup.options());
  const auto work = [this, &tracer] {
    try {
      traceTiles(tracer);
    } catch (const std::exception& e) {
      fail(e.what());
    }
  };
  std::vector<std::thread> helpers;
  for (int i = 1; i < threads_; ++i)
    helpers.emplace_back([&work] {
      prepareTracingThread();
      work();
    });
  work();
  for (std::thread& t : helpers) t.join();
  if (cancel_) return;
  trace_ms_ = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  ref_.frame_ms = trace_ms_;
  // compare's reference.depth_limit_pixels: the element pixels whose path ended at the depth limit.
  for (size_t i = 0; i < ref_.element.size(); ++i) depth_limit_pixels_ += ref_.element[i] >= 0 && depthLimited(ref_, i);
  // The mode's frame: drawn meanwhile by another thread; waited for in steps, so that a cancel is heard.
  while (mode_frame_.wait_for(std::chrono::milliseconds(kWaitStepMs)) != std::future_status::ready)
    if (cancel_) return;
  computeErrors(mode_frame_.get());  // rethrows the drawing's error: the run fails with it
  finished_.store(true, std::memory_order_release);
}

void ReferenceRun::traceTiles(const Tracer& tracer) {
  for (int t = next_tile_++; t < tile_count_ && !cancel_; t = next_tile_++) {
    TileRect r;
    r.x0 = (t % tiles_x_) * kTile;
    r.y0 = (t / tiles_x_) * kTile;
    r.x1 = std::min(width_, r.x0 + kTile);
    r.y1 = std::min(height_, r.y0 + kTile);
    for (int y = r.y0; y < r.y1; ++y)
      for (int x = r.x0; x < r.x1; ++x) {
        const TraceResult p = tracer.tracePixel(x + 0.5, y + 0.5);
        const size_t i = size_t(y) * size_t(width_) + size_t(x);
        ref_.color[i] = p.color;
        ref_.seen[i] = p.seen;
        ref_.element[i] = p.first_element;
        ref_.element_point[i] = p.element_point;
        ref_.bounces[i] = p.bounces;
        ref_.depth_limited[i] = p.depth_limited ? 1 : 0;  // as Tracer::render records it
        // As srgbPicture encodes a picture: non-finite colours black, each channel clamped to [0, 1].
        const Vec3 c = isFinite(p.color) ? p.color : Vec3(0);
        for (int k = 0; k < 3; ++k) rgba_[4 * i + size_t(k)] = linearToSrgb8(std::clamp(c[k], 0.0, 1.0));
        rgba_[4 * i + 3] = 255;
      }
    std::lock_guard<std::mutex> lock(mutex_);
    new_tiles_.push_back(r);
    ++tiles_done_;
  }
}

void ReferenceRun::computeErrors(const Frame& mode_frame) {
  const size_t n = size_t(width_) * size_t(height_);
  has_errors_ = mode_frame.seen.size() == n;
  heat_rgba_.assign(n * 4, 0);
  if (!has_errors_) return;
  // pvrr compare's figures: the angular error of the mode's seen points against the reference's, summarised. The
  // pixels whose reference path ended at the depth limit have no seen point: angularErrors leaves them out (NaN),
  // so they are in neither the figures nor the heat map ('not compared'), and are compared by colour only.
  errors_ = angularErrors(ref_, ref_.seen, mode_frame.seen);
  depth_limit_ = depthLimitColour(ref_, mode_frame);
  stats_ = summarizeErrors(errors_);
  scale_arcmin_ = heatMapScaleArcmin(stats_);
  for (size_t i = 0; i < n; ++i) {
    if (std::isnan(errors_[i])) continue;
    const Vec3 c = errorHeatColour(errors_[i] / scale_arcmin_);
    for (int k = 0; k < 3; ++k) heat_rgba_[4 * i + size_t(k)] = uint8_t(std::lround(255 * c[k]));
    heat_rgba_[4 * i + 3] = 255;
  }
}

}  // namespace pvrr::app::view
