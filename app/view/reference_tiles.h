// The viewer's live reference (issue 25 item 4): the exact Embree tracer (pvrr/trace/tracer.h) of one view,
// traced in background threads tile by tile, so that the window shows it progressively and never waits for it;
// then the per-pixel angular error of the mode's frame of the same view against it, as `pvrr compare` computes
// it (pvrr/analysis/accuracy.h: angularErrors of the reference's seen points and the mode's, summarised), and
// compare's heat map of it.
//
// Each pixel is Tracer::tracePixel at its centre, which is what Tracer::render computes (its packets give the
// same exact primary hits), with the tracer set up as render and compare set it up (pvrr/method/reference_setup.h:
// the caustic light of the lights with caustics on), so the finished reference is compare's reference picture. The run holds a copy of
// the scene as it was (shared with whoever draws the mode's frame, app/view/seen_frames.h) and its own Embree
// scene: the window's may move while it traces. The mode's frame may arrive while the tiles are traced; the
// errors wait for it. Destroying a run cancels it (the threads stop after their current tile, or stop waiting)
// and joins; a run writes no file. The window's thread only starts it: every allocation is on the run's thread.
#pragma once
#include <atomic>
#include <cstdint>
#include <future>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "pvrr/analysis/accuracy.h"
#include "pvrr/base/frame.h"
#include "pvrr/scene/scene.h"

namespace pvrr {
class Tracer;
}

namespace pvrr::app::view {

// A rectangle of pixels [x0, x1) x [y0, y1), rows top-down.
struct TileRect {
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
};

class ReferenceRun {
 public:
  // Side of the square tiles (pixels): small enough that a cancelled run stops within a few milliseconds.
  static constexpr int kTile = 32;

  // Starts tracing `scene` as its observer sees it, in `threads` threads (at least 1) of lowered priority.
  // `mode_frame`: the mode's frame of the same view with seen points (gl::RendererOptions::seen_points), or a
  // frame without them (no error figures then); an error in it fails the run, saying so.
  ReferenceRun(std::shared_ptr<const Scene> scene, std::shared_future<Frame> mode_frame, int threads);
  ~ReferenceRun();
  ReferenceRun(const ReferenceRun&) = delete;
  ReferenceRun& operator=(const ReferenceRun&) = delete;

  int width() const { return width_; }
  int height() const { return height_; }
  int threads() const { return threads_; }
  // Fraction of the pixels traced, 0..1.
  double fraction() const;
  // Traced, and the errors computed: what follows may be read.
  bool finished() const { return finished_.load(std::memory_order_acquire); }
  // The run stopped on an error (e.g. the scene's Embree build): finished() stays false; the message says why.
  bool failed() const { return failed_.load(std::memory_order_acquire); }
  const std::string& failure() const { return failure_; }  // after failed()
  // The tiles finished since the last call; their pixels of rgba() are final once returned here.
  std::vector<TileRect> takeTiles();
  // The reference's 8-bit picture as pvrr compare writes it (srgbPicture), RGBA with alpha 255 where traced.
  const std::vector<std::uint8_t>& rgba() const { return rgba_; }

  // After finished(): the reference frame, the trace's wall time, the errors (arcmin per pixel, NaN where the
  // reference sees no element or its path ended at the depth limit, as compare leaves them out), their summary, compare's heat map scale and its RGBA picture (alpha 255 at the
  // pixels with a finite error, 0 elsewhere).
  const Frame& reference() const { return ref_; }
  double traceMs() const { return trace_ms_; }
  const std::vector<double>& errors() const { return errors_; }
  const ErrorStats& stats() const { return stats_; }
  bool hasErrors() const { return has_errors_; }
  double scaleArcmin() const { return scale_arcmin_; }
  const std::vector<std::uint8_t>& heatRgba() const { return heat_rgba_; }
  // After finished(): the element pixels whose reference path ended at the depth limit (render.max_depth reached
  // on an element: no seen point, drawn black), left out of the errors as compare leaves them out; compare's
  // reference.depth_limit_pixels. With errors, compare's colour check of them (depthLimitColour) against the
  // mode's frame (zero when that frame has no colours).
  std::size_t depthLimitPixels() const { return depth_limit_pixels_; }
  const DepthLimitColour& depthLimit() const { return depth_limit_; }

 private:
  void run();
  void allocate();
  void traceAndMeasure();
  void fail(const std::string& why);
  void traceTiles(const Tracer& tracer);
  void computeErrors(const Frame& mode_frame);

  std::shared_ptr<const Scene> scene_;
  std::shared_future<Frame> mode_frame_;
  int width_ = 0, height_ = 0, threads_ = 1, tiles_x_ = 0, tile_count_ = 0;
  Frame ref_;
  std::vector<std::uint8_t> rgba_;
  std::atomic<int> next_tile_{0}, tiles_done_{0};
  std::atomic<bool> cancel_{false}, finished_{false}, failed_{false};
  std::string failure_;
  std::mutex mutex_;
  std::vector<TileRect> new_tiles_;  // guarded by mutex_
  double trace_ms_ = 0;
  std::vector<double> errors_;
  ErrorStats stats_;
  bool has_errors_ = false;
  double scale_arcmin_ = 1;
  std::size_t depth_limit_pixels_ = 0;
  DepthLimitColour depth_limit_;
  std::vector<std::uint8_t> heat_rgba_;
  std::thread thread_;
};

}  // namespace pvrr::app::view
