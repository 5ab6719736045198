#include "app/view/seen_frames.h"

#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <algorithm>
#include <exception>
#include <utility>

#include "app/view/window.h"
#include "pvrr/base/error.h"
#include "pvrr/gl/context.h"
#include "pvrr/gl/program.h"
#include "pvrr/gl/renderer.h"
#include "pvrr/scene/scene_build.h"
#include "pvrr/trace/ray_scene.h"

namespace pvrr::app::view {
namespace {

// Nice value of the worker (as the reference's tracing threads, app/view/reference_tiles.cpp).
constexpr int kWorkerNice = 10;

}  // namespace

struct SeenFrames::State {
  std::unique_ptr<gl::GlContext> context;
  long long build = -1;
  bool any_attached = false;
  // In this order: the renderer refers to the ray scene, both to the scene.
  std::unique_ptr<Scene> scene;
  std::shared_ptr<const SceneDesc> desc;
  std::unique_ptr<RayScene> rays;
  std::unique_ptr<gl::Renderer> renderer;
};

SeenFrames::SeenFrames(Window& window) : context_(std::make_unique<WorkerContext>(window)) {
  thread_ = std::thread([this] { work(); });
}

SeenFrames::~SeenFrames() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  wake_.notify_one();
  thread_.join();
  context_.reset();  // current on no thread now: the worker released it
}

std::shared_future<Frame> SeenFrames::request(std::shared_ptr<const Scene> scene, const SceneDesc& desc,
                                              long long build, RenderMode mode) {
  Job job;
  job.scene = std::move(scene);
  job.desc = std::make_shared<const SceneDesc>(desc);
  job.build = build;
  job.mode = mode;
  std::shared_future<Frame> frame = job.promise.get_future().share();
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (pending_)
      pending_->promise.set_exception(std::make_exception_ptr(Error("superseded by a later view's request")));
    pending_ = std::move(job);
  }
  wake_.notify_one();
  return frame;
}

int SeenFrames::framesDrawn() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return frames_;
}

int SeenFrames::programsBuilt() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return programs_;
}

void SeenFrames::work() {
  // Below the window's thread, as the tracing threads are: the window keeps its frame rate (the software GL's
  // threads that this thread's context starts inherit it).
  setpriority(PRIO_PROCESS, id_t(syscall(SYS_gettid)), kWorkerNice);  // best effort: this thread only
  State state;
  for (;;) {
    Job job;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      wake_.wait(lock, [this] { return stop_ || pending_; });
      if (stop_) break;
      job = std::move(*pending_);
      pending_.reset();
    }
    bool drawn = false;
    try {
      Frame f = draw(state, job);
      job.promise.set_value(std::move(f));
      drawn = true;
    } catch (...) {
      job.promise.set_exception(std::current_exception());
      state.build = -1;  // built anew at the next request
    }
    std::lock_guard<std::mutex> lock(mutex_);
    frames_ += drawn ? 1 : 0;
    programs_ = gl::programsBuiltOnThisThread();
  }
  // The GL objects go while their context is current, on this thread; then the context is released here.
  try {
    if (state.context) state.context->makeCurrent();
  } catch (...) {
  }
  state.renderer.reset();
  state.context.reset();
  std::lock_guard<std::mutex> lock(mutex_);
  if (pending_) pending_->promise.set_exception(std::make_exception_ptr(Error("the window closed")));
}

Frame SeenFrames::draw(State& state, Job& job) {
  if (!state.context)
    state.context = gl::GlContext::adopt(context_->foreign());
  else
    state.context->makeCurrent();
  if (state.build != job.build || !state.renderer) {
    state.renderer.reset();
    state.rays.reset();
    state.scene = std::make_unique<Scene>(*job.scene);
    state.desc = job.desc;
    state.any_attached = std::any_of(state.scene->elements.begin(), state.scene->elements.end(),
                                     [](const Element& e) { return e.attached_to_observer; });
    RaySceneOptions ro;
    ro.moving_elements = state.any_attached;  // later views of this build move them with the head
    state.rays = std::make_unique<RayScene>(*state.scene, ro);
    gl::RendererOptions opt = gl::rendererOptionsFor(*state.scene);
    opt.seen_points = true;  // as pvrr compare draws the frame it measures
    opt.read_back = true;
    state.renderer = std::make_unique<gl::Renderer>(*state.scene, *state.rays, opt);
    state.build = job.build;
  } else {
    // The window's updateObserver, on the worker's copy.
    state.scene->observer = job.scene->observer;
    if (state.any_attached) {
      updateAttachedElements(*state.scene, *state.desc);
      state.rays->updateElementPoses();
    }
  }
  gl::FrameCache fresh;  // every stage run, as compare's frame
  gl::RasterFrame f = state.renderer->render(job.mode, &fresh);
  return std::move(static_cast<Frame&>(f));
}

}  // namespace pvrr::app::view
