// The live reference's other half: the mode's frame of the view with seen points (gl::RendererOptions::seen_points,
// read back, as pvrr compare draws the frame it measures), drawn off the window's thread. A worker thread owns a
// second context of the window's kind (app/view/window.h WorkerContext), a renderer with seen points, and its own
// copy of the scene and Embree scene. Building that renderer compiles its programs (about 2 s on llvmpipe); in
// the window's context that stalled the window at the first reference (issue 25). Now the window hands over the
// view and goes on drawing; the frame arrives in a future, which the reference's thread waits for.
//
// The renderer is kept for later views of the same scene: a new observer (and the elements attached to it) is
// applied to the worker's copy as the window applies it to its own. A request for another build of the scene
// (a setting, a turned element, another time) copies the scene anew and builds a renderer for it.
#pragma once
#include <condition_variable>
#include <future>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>

#include "pvrr/base/frame.h"
#include "pvrr/scene/scene.h"
#include "pvrr/scene/scene_desc.h"

namespace pvrr::app::view {

class Window;
class WorkerContext;

class SeenFrames {
 public:
  // Opens the worker's context (here, on the window's thread) and starts the worker, which builds nothing yet.
  explicit SeenFrames(Window& window);
  // Stops the worker after the frame it is drawing (if any) and joins it; its GL objects go in its context.
  ~SeenFrames();
  SeenFrames(const SeenFrames&) = delete;
  SeenFrames& operator=(const SeenFrames&) = delete;

  // Asks for `mode`'s frame of `scene` as its observer sees it (every stage run, as compare's frame). `build`
  // names the scene's geometry and settings: a request with the build of the last one reuses its renderer and
  // takes only the observer from `scene`. A request not yet started is replaced (its future gets an error).
  // Errors of the worker (a GL error, a failed build) arrive in the future.
  std::shared_future<Frame> request(std::shared_ptr<const Scene> scene, const SceneDesc& desc, long long build,
                                    RenderMode mode);

  // Frames drawn and programs the worker built so far (its renderer's, on its own thread).
  int framesDrawn() const;
  int programsBuilt() const;

 private:
  struct Job {
    std::shared_ptr<const Scene> scene;
    std::shared_ptr<const SceneDesc> desc;
    long long build = 0;
    RenderMode mode = RenderMode::Pvrr;
    std::promise<Frame> promise;
  };
  struct State;  // the worker's context, scene copy and renderer: touched only by the worker thread

  void work();
  Frame draw(State& state, Job& job);

  std::unique_ptr<WorkerContext> context_;
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  std::optional<Job> pending_;     // guarded by mutex_
  bool stop_ = false;              // guarded by mutex_
  int frames_ = 0, programs_ = 0;  // guarded by mutex_
  std::thread thread_;
};

}  // namespace pvrr::app::view
