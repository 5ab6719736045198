// The viewer's state and loop (app/view/viewer.cpp) and its panel (app/view/viewer_panel.cpp): internal to
// `pvrr view`, shared by those two files only.
#pragma once
#define GLFW_INCLUDE_NONE  // no GL header: the viewer itself makes no GL call
#include <GLFW/glfw3.h>

#include <chrono>
#include <cstdlib>
#include <deque>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "app/commands.h"
#include "app/view/fov_overlay.h"
#include "app/view/head.h"
#include "app/view/lens_probe.h"
#include "app/view/reference_tiles.h"
#include "app/view/script.h"
#include "app/view/seen_frames.h"
#include "app/view/window.h"
#include "app/view/wipe.h"

namespace pvrr::app::view {

using Clock = std::chrono::steady_clock;
using nlohmann::json;

// Eye steps (metres) and head turns (degrees) of one key press; Shift multiplies by kFast.
inline constexpr double kEyeStepM = 0.01, kTurnStepDeg = 1.0, kFast = 10.0;
// Mouse-look: degrees of head turn per pixel of drag.
inline constexpr double kLookDegPerPixel = 0.1;
// A left-button press within this many pixels of the wipe's split line drags the line, not the head.
inline constexpr double kWipeGrabPx = 8;
// The panel's step of moving an element (metres).
inline constexpr double kMoveStepM = 0.001;
// Playing time: how long the last key's pose is held before it starts again (s).
inline constexpr double kLoopPauseS = 0.5;
// How often the panel's planning lines are made anew (ms): text a reader can follow, not every frame's.
inline constexpr double kPlanningRefreshMs = 250;

// What a reference belongs to: the view it traced. Any change (the head, the eye, the window's size, the mode,
// a setting, which rebuilds the scene) makes it another view's reference, and it is discarded.
struct ViewKey {
  Vec3 eye{0}, target{0}, up{0};
  int width = 0, height = 0;
  RenderMode mode = RenderMode::Pvrr;
  int scene_build = 0;
  bool operator==(const ViewKey& o) const {
    return eye == o.eye && target == o.target && up == o.up && width == o.width && height == o.height &&
           mode == o.mode && scene_build == o.scene_build;
  }
};

class Viewer {
 public:
  Viewer(Window& window, std::string scene_path, std::vector<std::string> overrides, std::optional<RenderMode> mode,
         int width, int height, std::string script_path, Script script)
      : window_(window),
        scene_path_(std::move(scene_path)),
        overrides_(std::move(overrides)),
        cli_mode_(mode),
        width_(width),
        height_(height),
        script_path_(std::move(script_path)),
        script_(std::move(script)) {
    glfwSetWindowUserPointer(window_.handle(), this);
    glfwSetKeyCallback(window_.handle(), [](GLFWwindow* w, int key, int, int action, int mods) {
      static_cast<Viewer*>(glfwGetWindowUserPointer(w))->onKey(key, action, mods);
    });
    rebuild();
    prepareReference();
  }
  ~Viewer() {
    reference_.reset();               // cancels a running trace and joins its threads
    seen_.reset();                    // the seen-points worker: its GL objects go in its own context, on its thread
    window_.context().makeCurrent();  // GL objects go while their context is current
    wipe_.reset();
    renderer_.reset();
    glfwSetKeyCallback(window_.handle(), nullptr);
  }

  void run();
  json stats() const;
  json referenceStats() const;

 private:
  // Loads and builds the scene with overrides_. `keep_mode`: the mode shown stays (a setting or a turned element),
  // else it is the command line's or the scene's.
  void rebuild(bool keep_mode = false);
  // Element `index` turned about its vertex (app/view/element_pose.h): its pose written as overrides, rebuilt.
  void turnElement(int index, double yaw_rad, double pitch_rad);
  // An animated scene's time (issue 24 item 1): the scene posed at t_s as pvrr render --time poses it; where
  // anything moved, the renderer and the ray scene are built again (they hold the geometry), as render does.
  void setTime(double t_s);
  // The renderer and the Embree scene of ls_.scene as it stands, with a fresh frame cache.
  void buildRenderer();
  void timePanel();
  // Element `index` moved by `by_m` in its own frame (x right, y up, z along its normal), rebuilt likewise.
  void moveElement(int index, const Vec3& by_m);
  int elementIndex(const std::string& name) const;
  void elementsPanel();
  // The panel's lines on each element's planning: made anew at most every kPlanningRefreshMs (and after a
  // rebuild or a mode change), not every frame.
  void planningLines(const gl::RasterFrame& f);
  void lensPanel();
  json probeStats() const;
  void runEvents();
  void frame();
  void panel(const gl::RasterFrame& f, double frame_ms);
  void onKey(int key, int action, int mods);
  const Observer& updateObserver();
  ViewKey viewKey() const {
    const Observer& ob = ls_.scene.observer;
    return {ob.eye, ob.target, ob.up, ob.width, ob.height, mode_, pose_builds_};
  }
  // The live reference: startReference traces the current view in the background, and has the mode's frame of
  // it drawn with seen points for the errors on the seen-points worker (app/view/seen_frames.h), so that the
  // window's thread builds no program for it; discardReference cancels or drops it, saying why.
  // prepareReference, at startup: the worker and the wipe's program (its first draw too), built before any frame.
  void prepareReference();
  void startReference();
  void discardReference(const std::string& why);
  void presentFrame(const Observer& ob);
  void referencePanel();
  // The pointer's path, shared by the mouse and the script's drag: a left-button press (not over the panel), moves
  // while held, release.
  void pointerPress(double x, double y);
  void pointerMove(double x, double y);
  void pointerRelease() { drag_ = Drag::None; }
  void setMode(RenderMode m) {
    if (m == mode_) return;
    mode_ = m;
    cache_ = gl::FrameCache{};  // the cache holds the last mode's maps
  }
  void screenshot(const std::string& file);
  void saveViewTo(const std::string& file);
  std::string glName() const { return window_.context().backendName() + " (" + window_.context().glRenderer() + ")"; }

  Window& window_;
  std::string scene_path_;
  std::vector<std::string> overrides_;  // --set, then the script's "set" events
  std::optional<RenderMode> cli_mode_;
  int width_, height_;
  std::string script_path_;
  Script script_;
  size_t next_event_ = 0;
  int waited_frames_ = 0;  // frames drawn while the script waited for a reference

  LoadedScene ls_;
  Observer design_;  // the scene's observer: the design eye point
  HeadPose pose_;
  RenderMode mode_ = RenderMode::Pvrr;
  bool any_attached_ = false;
  std::unique_ptr<RayScene> rays_;
  std::unique_ptr<gl::Renderer> renderer_;
  gl::FrameCache cache_;

  bool quit_ = false, show_panel_ = true;
  // The panel as this frame drew it (panel()): its opaque rectangle, and its draw list (null when collapsed);
  // the present pass leaves that rectangle out when the list is in the frame's draw data (panelHole).
  PixelRect panel_rect_, panel_outer_;  // less a pixel all round; and all its pixels
  const ImDrawList* panel_list_ = nullptr;
  int panel_hole_frames_ = 0;  // frames presented around the panel
  int direct_frames_ = 0;      // frames the renderer drew into the back buffer (no present pass)
  PixelRect covered_;          // the panel's rectangle that this frame's renderer left out
  int panel_covered_frames_ = 0, panel_redraws_ = 0;
  // The renderer may draw into the back buffer; PVRR_VIEW_PRESENT_PASS=1 turns it off (the present pass
  // every frame), to measure the two against each other in one build (docs/performance.md).
  bool direct_allowed_ = !std::getenv("PVRR_VIEW_PRESENT_PASS") || std::string(std::getenv("PVRR_VIEW_PRESENT_PASS")) != "1";
  bool panelDrawn() const;     // the panel is in this frame's draw data
  std::optional<PixelRect> panelHole() const;
  std::vector<std::string> pending_screenshots_, panel_screenshots_, shown_screenshots_;
  json shown_shots_ = json::array();  // the shown screenshots taken: file, frame, panel_kept
  int frames_ = 0, saved_ = 0;
  std::vector<double> frame_ms_;  // every frame, for --stats
  // Where each frame's time went: the renderer's frame, presenting it, the panel, the swap and input.
  std::vector<double> render_ms_, renderer_ms_, renderer_cpu_ms_, present_ms_, panel_ms_, panel_make_ms_, swap_ms_;
  std::deque<double> recent_ms_;  // the last frames, for the panel
  std::map<std::string, std::pair<int, double>> stage_ms_;  // the renderer's stages: frames ran, their ms summed
  enum class Drag { None, Look, Wipe };
  Drag drag_ = Drag::None;
  bool mouse_down_ = false;
  double last_x_ = 0, last_y_ = 0;

  int scene_builds_ = 0;
  int pose_builds_ = 0;  // renderers built (a rebuild, or a time that moved something): the geometry's version
  // Time: animated scenes only (isAnimated). Playing advances it by the wall clock, looping after the last key.
  bool animated_ = false, playing_ = false;
  double time_s_ = 0, duration_s_ = 0;
  Clock::time_point played_at_{};
  double rebuild_ms_max_ = 0;  // the slowest rebuild after the first (a setting, a turned element)
  // The lens probe (scenes with a lens): the pixel under the cursor (the mouse when it moves, or a script's
  // "cursor"), read again when that pixel or the view changes.
  bool has_lens_ = false;
  bool probe_asked_ = false, cursor_seen_ = false;
  int probe_x_ = 0, probe_y_ = 0;
  double cursor_x_ = 0, cursor_y_ = 0;
  LensProbe probe_;
  LensmapCache lensmaps_;
  bool probe_fresh_ = false;
  ViewKey probe_key_;
  std::vector<std::string> planning_lines_;
  Clock::time_point planning_made_{};
  RenderMode planning_mode_ = RenderMode::Pvrr;
  int selected_ = 0;  // the element the panel and the keys I/K/J/L turn
  // Changes asked for by the panel or the keys, applied at the next frame (not inside the panel's frame).
  std::vector<std::string> pending_overrides_;
  double pending_yaw_rad_ = 0, pending_pitch_rad_ = 0;
  Vec3 pending_move_m_{0};
  std::optional<double> pending_time_s_;
  std::unique_ptr<SeenFrames> seen_;  // the mode's frame with seen points, for the reference's errors
  std::unique_ptr<ReferenceRun> reference_;
  std::unique_ptr<Wipe> wipe_;
  ViewKey reference_key_;
  bool reference_requested_ = false;  // by key or panel: started at the next frame
  bool waiting_reference_ = false;    // a script's "reference" event: later events wait for it
  bool heat_uploaded_ = false;
  bool wipe_drawn_ = false;  // the wipe drawn once (prepareReference)
  double wipe_x_ = 0.5;  // the split line: 0 all reference, 1 all mode
  bool overlay_ = false;
  FovOverlay fov_overlay_;  // the mirror's road footprint over the frame (O)
  std::string reference_note_;  // why there is no reference now (cancelled, discarded)
  int references_started_ = 0, frames_while_tracing_ = 0;
  // Programs the window's thread had built when the first reference started (gl::programsBuiltOnThisThread),
  // -1 before: what it built since is in the stats (none, by design).
  int programs_at_first_reference_ = -1;
  double frame_ms_max_while_tracing_ = 0, reference_start_ms_ = 0, reference_start_cpu_ms_ = 0;
};

}  // namespace pvrr::app::view
