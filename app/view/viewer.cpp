#include "app/view/viewer.h"

#define GLFW_INCLUDE_NONE  // no GL header: the viewer itself makes no GL call
#include <GLFW/glfw3.h>
#include <imgui.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <deque>
#include <optional>
#include <thread>

#include <time.h>

#include "app/args.h"
#include "app/commands.h"
#include "app/report.h"
#include "app/view/element_pose.h"
#include "app/view/head.h"
#include "app/view/lens_probe.h"
#include "app/view/reference_tiles.h"
#include "app/view/save_view.h"
#include "app/view/script.h"
#include "app/view/viewer_impl.h"
#include "app/view/window.h"
#include "app/view/wipe.h"
#include "pvrr/analysis/accuracy.h"
#include "pvrr/base/error.h"
#include "pvrr/base/format.h"
#include "pvrr/gl/program.h"
#include "pvrr/scene/scene_json.h"

namespace pvrr::app {
namespace view {
namespace {

// A rectangle of window pixels (rows top-down) in GL's window coordinates (rows bottom-up): x0, y0, x1, y1; all
// zero for an empty one.
std::array<int, 4> glRect(const PixelRect& r, int height) {
  if (r.empty()) return {};
  return {r.x0, height - r.y1, r.x1, height - r.y0};
}

}  // namespace

namespace {

// This thread's CPU time (ms): what a step costs the window's thread, apart from the time others held the cores.
double threadCpuMs() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return double(ts.tv_sec) * 1e3 + double(ts.tv_nsec) * 1e-6;
}

}  // namespace

void Viewer::rebuild(bool keep_mode) {
  if (reference_) discardReference("discarded: the scene was rebuilt (a setting changed)");
  const auto t0 = Clock::now();
  window_.context().makeCurrent();
  renderer_.reset();
  ++scene_builds_;
  rays_.reset();
  lensmaps_.reset();  // its lens map read the old ray scene
  planning_lines_.clear();
  ls_ = loadScene(scene_path_, overrides_, width_, height_);
  design_ = ls_.scene.observer;
  if (!keep_mode || scene_builds_ == 1) mode_ = cli_mode_ ? *cli_mode_ : ls_.scene.render.mode;
  selected_ = std::clamp(selected_, 0, std::max(0, int(ls_.scene.elements.size()) - 1));
  if (!isRasterMode(mode_))
    throw Error("pvrr view: mode " + std::string(nameOf(mode_)) + " is not a live mode; expected one of " +
                nameListIf<RenderMode>(isRasterMode));
  has_lens_ = std::any_of(ls_.scene.elements.begin(), ls_.scene.elements.end(),
                          [](const Element& e) { return e.type == ElementType::Lens; });
  probe_fresh_ = false;
  any_attached_ = std::any_of(ls_.scene.elements.begin(), ls_.scene.elements.end(),
                              [](const Element& e) { return e.attached_to_observer; });
  animated_ = isAnimated(ls_.desc);
  duration_s_ = 0;
  for (const EnvObjectDesc& o : ls_.desc.environment)
    if (o.animation) duration_s_ = std::max(duration_s_, o.animation->keys.back().time_s);
  for (const ElementDesc& e : ls_.desc.elements)
    if (e.animation) duration_s_ = std::max(duration_s_, e.animation->keys.back().time_s);
  if (animated_) applyAnimation(ls_.scene, ls_.desc, time_s_);  // the time shown stays
  buildRenderer();
  if (scene_builds_ > 1)
    rebuild_ms_max_ = std::max(rebuild_ms_max_, std::chrono::duration<double, std::milli>(Clock::now() - t0).count());
}

void Viewer::buildRenderer() {
  window_.context().makeCurrent();
  renderer_.reset();  // before the ray scene it refers to
  rays_.reset();
  lensmaps_.reset();
  RaySceneOptions ro;
  ro.moving_elements = any_attached_;  // the head moves them
  rays_ = std::make_unique<RayScene>(ls_.scene, ro);
  gl::RendererOptions opt = gl::rendererOptionsFor(ls_.scene);
  opt.seen_points = false;  // the picture only, as pvrr render draws it
  opt.read_back = false;    // presented from the GPU
  renderer_ = std::make_unique<gl::Renderer>(ls_.scene, *rays_, opt);
  cache_ = gl::FrameCache{};
  probe_fresh_ = false;
  ++pose_builds_;
}

void Viewer::setTime(double t_s) {
  time_s_ = std::max(0.0, t_s);
  if (!animated_) return;
  updateObserver();  // attached elements are posed from the observer as it stands
  if (applyAnimation(ls_.scene, ls_.desc, time_s_)) buildRenderer();
}

void Viewer::runEvents() {
  // A script waiting for its reference: the window draws on, and the later events move by the frames it waited.
  if (waiting_reference_ && reference_ && !reference_->finished()) {
    ++waited_frames_;
    return;
  }
  waiting_reference_ = false;
  while (next_event_ < script_.events.size() && script_.events[next_event_].at_frame + waited_frames_ <= frames_) {
    if (waiting_reference_) return;
    const ScriptEvent& e = script_.events[next_event_++];
    try {
      switch (e.kind) {
        case EventKind::Set:
          overrides_.push_back(e.path + "=" + e.value_json);
          if (e.path.rfind("render.mode", 0) == 0) cli_mode_.reset();
          rebuild();
          break;
        case EventKind::TurnElement:
          turnElement(elementIndex(e.element), radians(e.yaw_deg), radians(e.pitch_deg));
          break;
        case EventKind::MoveElement:
          moveElement(elementIndex(e.element), e.by_m);
          break;
        case EventKind::TurnHead: turnHead(pose_, radians(e.yaw_deg), radians(e.pitch_deg)); break;
        case EventKind::MoveEye: moveEye(pose_, design_, e.by_m); break;
        case EventKind::Screenshot:
          (e.shown ? shown_screenshots_ : e.with_panel ? panel_screenshots_ : pending_screenshots_).push_back(e.file);
          break;
        case EventKind::SaveView: saveViewTo(e.file); break;
        case EventKind::Quit: quit_ = true; break;
        case EventKind::Key: onKey(e.key, GLFW_PRESS, e.shift ? GLFW_MOD_SHIFT : 0); break;  // the keyboard's path
        case EventKind::Reference:
          startReference();
          waiting_reference_ = true;
          break;
        case EventKind::Time:
          setTime(e.time_s);
          playing_ = e.on;
          played_at_ = Clock::now();
          break;
        case EventKind::Cursor:
          probe_asked_ = true;
          probe_x_ = int(std::floor(e.at_px.x));
          probe_y_ = int(std::floor(e.at_px.y));
          break;
        case EventKind::Wipe:
          wipe_x_ = e.wipe_x;
          break;
        case EventKind::Overlay:
          overlay_ = e.on;
          break;
        case EventKind::Drag:  // the mouse's path
          pointerPress(e.from_px.x, e.from_px.y);
          pointerMove(e.to_px.x, e.to_px.y);
          pointerRelease();
          break;
      }
    } catch (const Error& err) {
      throw Error(script_path_ + ": " + e.where + ": " + err.what());
    }
    if (quit_) return;
  }
}

void Viewer::frame() {
  int fw = 0, fh = 0;
  window_.framebufferSize(&fw, &fh);
  if (fw > 0 && fh > 0 && (fw != design_.width || fh != design_.height)) {
    // The window was resized: the picture follows it (the maps are sized from the picture).
    design_.width = width_ = fw;
    design_.height = height_ = fh;
    cache_ = gl::FrameCache{};
  }
  const auto t0 = Clock::now();
  if (pending_yaw_rad_ != 0 || pending_pitch_rad_ != 0) {
    turnElement(selected_, pending_yaw_rad_, pending_pitch_rad_);
    pending_yaw_rad_ = pending_pitch_rad_ = 0;
  }
  if (pending_move_m_ != Vec3(0)) {
    moveElement(selected_, pending_move_m_);
    pending_move_m_ = Vec3(0);
  }
  if (!pending_overrides_.empty()) {
    overrides_.insert(overrides_.end(), pending_overrides_.begin(), pending_overrides_.end());
    pending_overrides_.clear();
    rebuild(true);
  }
  if (pending_time_s_) {
    setTime(*pending_time_s_);
    pending_time_s_.reset();
  }
  if (playing_ && animated_) {
    // Real time; after the last key (and half a second of its pose) it starts again.
    const auto now = Clock::now();
    double t = time_s_ + std::chrono::duration<double>(now - played_at_).count();
    if (t > duration_s_ + kLoopPauseS) t = 0;
    played_at_ = now;
    setTime(t);
  }
  if (reference_requested_) {
    reference_requested_ = false;
    if (reference_ && !reference_->finished())
      discardReference("cancelled: T pressed");
    else
      startReference();
  }
  const Observer ob = updateObserver();
  if (reference_ && !(viewKey() == reference_key_)) discardReference("discarded: the view changed");
  if (reference_ && reference_->failed()) discardReference("failed: " + reference_->failure());
  const bool tracing = reference_ && !reference_->finished();
  if (has_lens_ && probe_asked_ &&
      (!probe_fresh_ || !(viewKey() == probe_key_) || int(probe_.px) != probe_x_ || int(probe_.py) != probe_y_)) {
    probe_ = probeLens(ls_.scene, *rays_, probe_x_, probe_y_, &lensmaps_);
    probe_key_ = viewKey();
    probe_fresh_ = true;
  }
  window_.context().makeCurrent();
  if (!wipe_drawn_) {
    // The wipe's first draw, where a software GL compiles its shaders' code: here, of the first frame, into the
    // back buffer that the frame (drawn into it, or presented) then overwrites, not at the first reference.
    wipe_->present(renderer_->colorTexture(), ob.width, ob.height, 0.5 * ob.width, true);
    wipe_drawn_ = true;
  }
  {
    // The renderer's second pass straight into the back buffer (no present pass), but while the wipe shows the
    // frame beside the reference (it reads the frame's texture), where the window cannot take it, and on a frame
    // with a screenshot of the frame alone: that one is drawn into the texture and presented, as pvrr render
    // draws it. In the back buffer GL rasterizes the frame mirrored (a window's rows are stored top-down, a
    // texture's bottom-up), so a pixel whose centre lies exactly on a triangle's edge can fall to the other
    // triangle (1-3 pixels of 76,800 at 320 x 240 in the tests' views), and GL's sRGB encode is a code off the
    // exact one for about 6 % of values (docs/performance.md); the frame-alone screenshot is render's picture.
    int fw = 0, fh = 0;
    window_.framebufferSize(&fw, &fh);
    const bool direct = direct_allowed_ && window_.takesFrameDirectly() && !reference_ &&
                        pending_screenshots_.empty() && fw == ob.width && fh == ob.height;
    renderer_->setIntoDefaultFramebuffer(direct);
    // Drawn into the window, the frame leaves out the panel's opaque rectangle as the last frame drew it (the
    // panel is made after the frame, which it describes); checked against this frame's panel below.
    covered_ = direct && panelDrawn() ? panel_rect_ : PixelRect{};
    renderer_->setCoveredRect(glRect(covered_, ob.height));
  }
  // A screenshot frame is drawn whole, every stage run (its own empty cache), so that it is what pvrr render
  // draws of the saved view: frames that reuse earlier maps (map reuse, render.map_reuse_margin_deg) differ
  // from a fresh frame in places, as they do in pvrr render --frames --orbit.
  gl::FrameCache whole;
  const double render_cpu0_ms = threadCpuMs();
  gl::RasterFrame f = renderer_->render(mode_, pending_screenshots_.empty() ? &cache_ : &whole);
  renderer_cpu_ms_.push_back(threadCpuMs() - render_cpu0_ms);
  cache_.environment_changed = false;  // the environment never changes while the window is open
  for (const StageTiming& st : f.stages.stages)
    if (st.ran) {
      auto& [ran, sum_ms] = stage_ms_[st.name];
      ++ran;
      sum_ms += st.ms;
    }
  if (!renderer_->drewIntoDefaultFramebuffer()) covered_ = {};  // drawn into its texture, whole
  const auto t_render = Clock::now();
  // The panel first made (no GL), then the frame presented around its opaque rectangle, then the panel drawn.
  window_.beginPanel();
  fov_overlay_.draw(ls_.scene, ls_.desc, *rays_, selected_, scene_builds_, ob);  // under the panel, in panel shots
  const double shown_ms = recent_ms_.empty() ? f.frame_ms : recent_ms_.back();
  panel_list_ = nullptr;
  if (show_panel_) panel(f, shown_ms);
  window_.endPanel();
  if (!covered_.empty() && !(panelDrawn() && panel_rect_.contains(covered_))) {
    // The panel moved, shrank, collapsed or went this frame: the frame drawn again, whole (rare: the panel's
    // size follows its sections).
    renderer_->setCoveredRect({});
    f = renderer_->render(mode_, &cache_);
    covered_ = {};
    ++panel_redraws_;
  }
  panel_covered_frames_ += covered_.empty() ? 0 : 1;
  const auto t_panel_made = Clock::now();
  presentFrame(ob);
  const auto t_present = Clock::now();
  if (!pending_screenshots_.empty()) {
    // Screenshots show the frame alone: taken before the panel is drawn over it (that frame presented whole).
    const ImageRGB8 img = window_.readBackBuffer(ob.width, ob.height);
    for (const std::string& file : pending_screenshots_) writePngAtomic(file, img, MissingFolder::Create);
    pending_screenshots_.clear();
  }
  {
    // The panel from its picture (panel_cache.h) unless it is being worked (a screenshot with the panel shows
    // what the window shows).
    const ImGuiIO& io = ImGui::GetIO();
    const bool worked = io.WantCaptureMouse || io.WantCaptureKeyboard || ImGui::IsAnyItemActive() ||
                        ImGui::IsPopupOpen("", ImGuiPopupFlags_AnyPopupId);
    if (panelDrawn() && !worked)
      window_.drawPanel(panel_list_, panel_outer_, /*may_keep=*/panel_screenshots_.empty());
    else
      window_.drawPanel();
  }
  if (!panel_screenshots_.empty()) {
    const ImageRGB8 img = window_.readBackBuffer(ob.width, ob.height);
    for (const std::string& file : panel_screenshots_) writePngAtomic(file, img, MissingFolder::Create);
    panel_screenshots_.clear();
  }
  const auto t_panel = Clock::now();
  const int part_shows = window_.partShows();
  window_.swapAndPoll();
  if (!shown_screenshots_.empty()) {
    const ImageRGB8 img = window_.readShown(ob.width, ob.height);
    for (const std::string& file : shown_screenshots_) {
      writePngAtomic(file, img, MissingFolder::Create);
      shown_shots_.push_back({{"file", file}, {"frame", frames_ + 1}, {"panel_kept", window_.partShows() > part_shows}});
    }
    shown_screenshots_.clear();
  }

  // The mouse: a left-button drag outside the panel turns the head, or moves the wipe's split line.
  double x = 0, y = 0;
  glfwGetCursorPos(window_.handle(), &x, &y);
  const bool down = glfwGetMouseButton(window_.handle(), GLFW_MOUSE_BUTTON_LEFT) == GLFW_PRESS;
  if (down && !mouse_down_ && !ImGui::GetIO().WantCaptureMouse) pointerPress(x, y);
  if (down) pointerMove(x, y);
  if (!down && mouse_down_) pointerRelease();
  mouse_down_ = down;
  // The lens probe follows the mouse when it moves over the picture (not at startup, where it was put).
  if (cursor_seen_ && (x != cursor_x_ || y != cursor_y_) && !ImGui::GetIO().WantCaptureMouse) {
    probe_asked_ = true;
    probe_x_ = int(std::floor(x));
    probe_y_ = int(std::floor(y));
  }
  cursor_seen_ = true;
  cursor_x_ = x;
  cursor_y_ = y;

  const double ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
  frame_ms_.push_back(ms);
  const auto span = [](Clock::time_point a, Clock::time_point b) {
    return std::chrono::duration<double, std::milli>(b - a).count();
  };
  render_ms_.push_back(span(t0, t_render));
  renderer_ms_.push_back(f.frame_ms);
  present_ms_.push_back(span(t_panel_made, t_present));
  panel_ms_.push_back(span(t_render, t_panel_made) + span(t_present, t_panel));
  panel_make_ms_.push_back(span(t_render, t_panel_made));
  swap_ms_.push_back(span(t_panel, Clock::now()));
  if (tracing) {
    ++frames_while_tracing_;
    frame_ms_max_while_tracing_ = std::max(frame_ms_max_while_tracing_, ms);
  }
  recent_ms_.push_back(ms);
  if (recent_ms_.size() > 60) recent_ms_.pop_front();
  ++frames_;
}

int Viewer::elementIndex(const std::string& name) const {
  for (size_t i = 0; i < ls_.scene.elements.size(); ++i)
    if (ls_.scene.elements[i].name == name) return int(i);
  throw Error("no element named \"" + name + "\"");  // checked before the window opened
}

void Viewer::moveElement(int index, const Vec3& by_m) {
  if (index < 0 || size_t(index) >= ls_.desc.elements.size()) return;
  const PoseDesc& p = ls_.desc.elements[size_t(index)].pose;
  overrides_.push_back(
      positionOverride(index, movedElementPosition(p.position, p.normal, p.up, by_m), ls_.desc.unit_m));
  rebuild(true);
}

void Viewer::turnElement(int index, double yaw_rad, double pitch_rad) {
  if (index < 0 || size_t(index) >= ls_.desc.elements.size()) return;
  const PoseDesc& p = ls_.desc.elements[size_t(index)].pose;
  for (const std::string& o : poseOverrides(index, turnElementPose(p.normal, p.up, yaw_rad, pitch_rad)))
    overrides_.push_back(o);
  rebuild(true);
}

json Viewer::probeStats() const {
  if (!probe_asked_ || !probe_fresh_) return nullptr;
  json j = {{"pixel", {probe_.px, probe_.py}},
            {"valid", probe_.valid},
            {"reason", probe_.reason},
            {"lensmaps_built", lensmaps_.builds}};  // lens maps the probe built (LensmapCache)
  if (probe_.element >= 0) j["element"] = ls_.scene.elements[size_t(probe_.element)].name;
  if (!probe_.valid) return j;
  const LensmapPoint& r = probe_.reading;
  j["lens_point_local_m"] = {probe_.lens_point_local.x, probe_.lens_point_local.y, probe_.lens_point_local.z};
  for (const auto& [name, v] :
       {std::pair{"gaze_x_deg", r.gaze_x_deg}, std::pair{"gaze_y_deg", r.gaze_y_deg},
        std::pair{"lens_x_mm", r.lens_x_mm}, std::pair{"lens_y_mm", r.lens_y_mm}, std::pair{"sphere_d", r.sphere_d},
        std::pair{"cylinder_d", r.cylinder_d}, std::pair{"axis_deg", r.axis_deg},
        std::pair{"mean_power_d", r.mean_power_d}, std::pair{"power_error_d", r.power_error_d},
        std::pair{"unwanted_cylinder_d", r.unwanted_cylinder_d}, std::pair{"prism_h", r.prism_h},
        std::pair{"prism_v", r.prism_v}})
    j[name] = v;
  return j;
}

const Observer& Viewer::updateObserver() {
  const Observer ob = headObserver(design_, pose_);
  Observer& current = ls_.scene.observer;
  const bool moved = ob.eye != current.eye || ob.target != current.target;
  current = ob;
  if (moved && any_attached_) {
    updateAttachedElements(ls_.scene, ls_.desc);
    rays_->updateElementPoses();
  }
  return current;
}

void Viewer::prepareReference() {
  seen_ = std::make_unique<SeenFrames>(window_);
  window_.context().makeCurrent();
  wipe_ = std::make_unique<Wipe>(window_);
  wipe_->reset(width_, height_);
}

void Viewer::startReference() {
  updateObserver();
  if (reference_ && (reference_->finished() || !(viewKey() == reference_key_))) reference_.reset();  // traced anew
  if (reference_ && viewKey() == reference_key_) return;  // this view's reference is being traced
  window_.context().makeCurrent();
  if (programs_at_first_reference_ < 0) programs_at_first_reference_ = gl::programsBuiltOnThisThread();
  const auto t0 = Clock::now();
  const double cpu0_ms = threadCpuMs();
  // One copy of the view's scene, shared by the tracer and the seen-points worker.
  auto snapshot = std::make_shared<const Scene>(ls_.scene);
  std::shared_future<Frame> seen = seen_->request(snapshot, ls_.desc, pose_builds_, mode_);
  const int threads = std::max(1, int(std::thread::hardware_concurrency()) - 1);  // one core for the window
  reference_ = std::make_unique<ReferenceRun>(std::move(snapshot), std::move(seen), threads);
  wipe_->reset(reference_->width(), reference_->height());
  heat_uploaded_ = false;
  reference_key_ = viewKey();
  reference_note_.clear();
  ++references_started_;
  reference_start_ms_ =
      std::max(reference_start_ms_, std::chrono::duration<double, std::milli>(Clock::now() - t0).count());
  reference_start_cpu_ms_ = std::max(reference_start_cpu_ms_, threadCpuMs() - cpu0_ms);
}

void Viewer::discardReference(const std::string& why) {
  reference_.reset();
  reference_note_ = why;
  waiting_reference_ = false;
}

bool Viewer::panelDrawn() const {
  // Not while the panel is hidden, collapsed or not drawn this frame (ImGui hides a window the frame it first
  // sizes itself).
  if (!show_panel_ || !panel_list_) return false;
  const ImDrawData* dd = ImGui::GetDrawData();
  if (!dd || !dd->Valid) return false;
  for (int i = 0; i < dd->CmdListsCount; ++i)
    if (dd->CmdLists[i] == panel_list_ && dd->CmdLists[i]->VtxBuffer.Size > 0) return true;
  return false;
}

std::optional<PixelRect> Viewer::panelHole() const {
  // Not under a screenshot of the frame alone.
  if (!pending_screenshots_.empty() || !panelDrawn()) return std::nullopt;
  return panel_rect_;
}

void Viewer::presentFrame(const Observer& ob) {
  if (!reference_ && renderer_->drewIntoDefaultFramebuffer()) {
    ++direct_frames_;  // the frame is in the back buffer already
    return;
  }
  if (!reference_) {
    const std::optional<PixelRect> hole = panelHole();
    panel_hole_frames_ += hole ? 1 : 0;
    window_.present(renderer_->colorTexture(), ob.width, ob.height, hole);
    return;
  }
  const bool finished = reference_->finished();  // first: every tile is queued once it says so
  wipe_->uploadTiles(reference_->takeTiles(), reference_->rgba());
  if (finished && !heat_uploaded_ && reference_->hasErrors()) {
    wipe_->uploadHeat(reference_->heatRgba());
    heat_uploaded_ = true;
  }
  wipe_->present(renderer_->colorTexture(), ob.width, ob.height, wipe_x_ * ob.width, overlay_ && heat_uploaded_);
}

void Viewer::pointerPress(double x, double y) {
  const bool on_line = reference_ && std::abs(x - wipe_x_ * double(ls_.scene.observer.width)) <= kWipeGrabPx;
  drag_ = on_line ? Drag::Wipe : Drag::Look;
  last_x_ = x;
  last_y_ = y;
}

void Viewer::pointerMove(double x, double y) {
  if (drag_ == Drag::Look)
    turnHead(pose_, -radians(kLookDegPerPixel * (x - last_x_)), -radians(kLookDegPerPixel * (y - last_y_)));
  else if (drag_ == Drag::Wipe)
    wipe_x_ = std::clamp(x / double(std::max(1, ls_.scene.observer.width)), 0.0, 1.0);
  last_x_ = x;
  last_y_ = y;
}

void Viewer::onKey(int key, int action, int mods) {
  if (action == GLFW_RELEASE || ImGui::GetIO().WantCaptureKeyboard) return;
  const double k = (mods & GLFW_MOD_SHIFT) ? kFast : 1.0;
  const double step = kEyeStepM * k, turn = radians(kTurnStepDeg * k);
  switch (key) {
    case GLFW_KEY_W: moveEye(pose_, design_, {0, 0, -step}); break;
    case GLFW_KEY_S: moveEye(pose_, design_, {0, 0, step}); break;
    case GLFW_KEY_A: moveEye(pose_, design_, {-step, 0, 0}); break;
    case GLFW_KEY_D: moveEye(pose_, design_, {step, 0, 0}); break;
    case GLFW_KEY_R: moveEye(pose_, design_, {0, step, 0}); break;
    case GLFW_KEY_F: moveEye(pose_, design_, {0, -step, 0}); break;
    case GLFW_KEY_LEFT: turnHead(pose_, turn, 0); break;
    case GLFW_KEY_RIGHT: turnHead(pose_, -turn, 0); break;
    case GLFW_KEY_UP: turnHead(pose_, 0, turn); break;
    case GLFW_KEY_DOWN: turnHead(pose_, 0, -turn); break;
    case GLFW_KEY_HOME:
    case GLFW_KEY_H: pose_ = HeadPose{}; break;
    case GLFW_KEY_1: setMode(RenderMode::Pvrr); break;
    case GLFW_KEY_2: setMode(RenderMode::Envmap); break;
    case GLFW_KEY_3: setMode(RenderMode::Impostor); break;
    case GLFW_KEY_4: setMode(RenderMode::Raster); break;
    case GLFW_KEY_TAB: show_panel_ = !show_panel_; break;
    case GLFW_KEY_SPACE:
      playing_ = animated_ && !playing_;
      played_at_ = Clock::now();
      break;
    case GLFW_KEY_T:
      reference_requested_ = true;
      break;
    case GLFW_KEY_J:
      pending_yaw_rad_ -= turn;
      break;
    case GLFW_KEY_L:
      pending_yaw_rad_ += turn;
      break;
    case GLFW_KEY_K:
      pending_pitch_rad_ -= turn;
      break;
    case GLFW_KEY_I:
      pending_pitch_rad_ += turn;
      break;
    case GLFW_KEY_E:
      overlay_ = !overlay_;
      break;
    case GLFW_KEY_O:
      fov_overlay_.toggle();
      break;
    case GLFW_KEY_F12: pending_screenshots_.push_back("out/view-" + std::to_string(++saved_) + ".png"); break;
    case GLFW_KEY_V: saveViewTo("out/view-" + std::to_string(++saved_) + ".json"); break;
    case GLFW_KEY_ESCAPE: quit_ = true; break;
    default: break;
  }
}

void Viewer::saveViewTo(const std::string& file) {
  // The head as it stands now (a turn among the same frame's events included): the view the next frame draws.
  saveView(file, scene_path_, overrides_, headObserver(design_, pose_), ls_.desc.unit_m);
  std::printf("%s\n", file.c_str());
}

void Viewer::run() {
  while (!quit_) {
    runEvents();
    if (quit_ || window_.closeRequested()) break;
    frame();
  }
  if (!pending_screenshots_.empty() || !panel_screenshots_.empty() || !shown_screenshots_.empty())
    frame();  // asked for on the last frame
  if (reference_ && !reference_->finished()) discardReference("cancelled: the window closed");
}

json Viewer::referenceStats() const {
  std::string state = "none";
  if (reference_)
    state = reference_->finished() ? "done" : "tracing";
  else if (references_started_ > 0)
    state = reference_note_.substr(0, reference_note_.find(':'));  // cancelled, discarded, failed
  json j = {{"state", state},
            {"note", reference_note_},
            {"started", references_started_},
            // The window thread's time to start one (the longest start): a copy of the scene and a request; the
            // mode's frame with seen points is drawn on the worker, which built `worker_programs` programs.
            {"start_ms", reference_start_ms_},
            {"start_cpu_ms", reference_start_cpu_ms_},  // the same in the thread's CPU time: without waits for a core
            {"worker_frames", seen_ ? seen_->framesDrawn() : 0},
            {"worker_programs", seen_ ? seen_->programsBuilt() : 0},
            // Programs the window's thread built from the first start to the end of the run: none, by design.
            {"window_programs_since_start",
             programs_at_first_reference_ < 0 ? 0 : gl::programsBuiltOnThisThread() - programs_at_first_reference_},
            {"frames_while_tracing", frames_while_tracing_},
            {"frame_ms_max_while_tracing", frame_ms_max_while_tracing_}};
  j["wipe_x"] = wipe_x_;
  j["overlay"] = overlay_;
  if (!reference_ || !reference_->finished()) return j;
  j["threads"] = reference_->threads();
  j["trace_ms"] = reference_->traceMs();
  // compare's reference.depth_limit_pixels: left out of the errors, as compare leaves them out.
  j["depth_limit_pixels"] = reference_->depthLimitPixels();
  if (reference_->hasErrors()) {
    const ErrorStats& st = reference_->stats();
    j["pixels"] = st.pixels;
    j["angular_error_arcmin"] = {{"median", st.median_arcmin}, {"p95", st.p95_arcmin}, {"max", st.max_arcmin}};
    j["heat_map_scale_arcmin"] = reference_->scaleArcmin();
    const DepthLimitColour& dl = reference_->depthLimit();  // compare's modes.MODE.depth_limit
    j["depth_limit"] = {{"pixels", dl.pixels}, {"drawn_lit", dl.drawn_lit}, {"psnr_db", dl.psnr_db}};
  }
  return j;
}

json Viewer::stats() const {
  std::vector<double> t = frame_ms_;
  const double med = t.empty() ? 0.0 : median(t);
  return {{"frames", frames_},
          {"fps_median", med > 0 ? 1000.0 / med : 0.0},
          {"frame_ms_median", med},
          {"frame_ms_max", t.empty() ? 0.0 : *std::max_element(t.begin(), t.end())},
          {"mode", nameOf(mode_)},
          {"fov_overlay", fov_overlay_.stats()},
          // Medians of the frame's parts (ms): the renderer's frame (as pvrr render times it, plus the head's
          // update), presenting it, the panel (with any screenshot), and the swap with the input.
          {"parts_ms_median",
           {{"render", t.empty() ? 0.0 : median(render_ms_)},
            // of which the renderer's frame itself, as pvrr render's frame_ms times it
            {"renderer", t.empty() ? 0.0 : median(renderer_ms_)},
            // and the window thread's CPU time in it (with LP_NUM_THREADS=0 llvmpipe draws on this thread: the
            // whole frame's CPU, whatever the load)
            {"renderer_thread_cpu", t.empty() ? 0.0 : median(renderer_cpu_ms_)},
            {"present", t.empty() ? 0.0 : median(present_ms_)},
            {"panel", t.empty() ? 0.0 : median(panel_ms_)},
            // of which making it (Dear ImGui's frame and the panel's items, no GL; and a frame drawn again)
            {"panel_make", t.empty() ? 0.0 : median(panel_make_ms_)},
            {"swap", t.empty() ? 0.0 : median(swap_ms_)}}},
          // Frames presented around the panel's opaque rectangle (the last frame's, window pixels, rows
          // top-down, [x0, x1) x [y0, y1)): the frame under it is not drawn.
          // Frames drawn by the renderer straight into the window's back buffer (no present pass), and that
          // buffer's depth bits and colour encoding (app/view/window.h takesFrameDirectly).
          // Of those, frames drawn less the panel's rectangle (its depth cleared to the near plane:
          // gl::RendererOptions::covered_rect), and frames drawn again whole because the panel had changed.
          {"present", {{"direct_frames", direct_frames_},
                       {"panel_covered_frames", panel_covered_frames_},
                       {"panel_redraws", panel_redraws_},
                       {"window_depth_bits", window_.depthBits()},
                       {"window_srgb", window_.srgbCapable()},
                       {"panel_hole_frames", panel_hole_frames_},
                       {"shows_part", window_.showsPart()},
                       {"part_shows", window_.partShows()},
                       {"panel_rect", {panel_rect_.x0, panel_rect_.y0, panel_rect_.x1, panel_rect_.y1}}}},
          // Screenshots of the window as shown ("panel": "shown"): the frame (1 the first) and whether it kept the
          // panel an earlier frame showed.
          {"shown_screenshots", shown_shots_},
          // The panel drawn from its picture (app/view/panel_cache.h): pictures made, frames copied from one, and
          // frames that kept the panel the window showed (not drawn; the frame shown less its rectangle:
          // present.part_shows, where the window shows part of its back buffer, present.shows_part).
          {"panel", {{"pictures", window_.panelCache().pictures()},
                     {"copies", window_.panelCache().copies()},
                     {"kept", window_.panelCache().kept()}}},
          // The renderer's stages that ran, as pvrr render --stats counts them (stage_frames): frames and mean ms.
          {"stages", [this] {
             json j = json::object();
             for (const auto& [name, v] : stage_ms_) j[name] = {{"frames_ran", v.first}, {"mean_ms", v.second / v.first}};
             return j;
           }()},
          {"size", {design_.width, design_.height}},
          {"reference", referenceStats()},
          {"lens_probe", probeStats()},
          // Rebuilds of the scene after the first (a "set", a panel setting, a turned element), and the slowest
          // one's time (ms; the renderer's first frame after it, with its programs, is in frame_ms_max).
          {"rebuilds", scene_builds_ - 1},
          // Animated scenes: the time shown (s) and whether it plays; renderers built (rebuilds and moving times).
          {"time_s", time_s_},
          {"playing", playing_},
          {"renderer_builds", pose_builds_},
          {"rebuild_ms_max", rebuild_ms_max_},
          {"gl", glName()}};
}

}  // namespace view

int cmdView(const std::vector<std::string>& argv) {
  Args a("view", argv, {"gl", "size", "script", "stats", "set", "mode"}, {}, {"set"});
  if (a.positional().size() > 1) usageError("view", "expected at most one scene file");
  const std::string scene_path = a.positional().empty() ? kDefaultScene : a.positional()[0];
  const view::WindowGl api = view::parseWindowGl(a.get("gl", "auto"));
  const std::optional<RenderMode> mode =
      a.get("mode") ? std::optional<RenderMode>(parseModeOption(*a.get("mode"), false)) : std::nullopt;
  // Everything is validated before the window opens: the script, the scene, each "set" the script makes.
  const std::string script_path = a.get("script", "");
  view::Script script = script_path.empty() ? view::Script{} : view::loadScript(script_path);
  std::vector<std::string> overrides = a.all("set");
  {
    std::vector<std::string> checked = overrides;
    for (const view::ScriptEvent& e : script.events) {
      if (e.kind != view::EventKind::Set) continue;
      checked.push_back(e.path + "=" + e.value_json);
      try {
        pvrr::loadScene(scene_path, checked);
      } catch (const Error& err) {
        throw Error(script_path + ": " + e.where + ": " + err.what());
      }
    }
  }
  const SceneDesc desc = pvrr::loadScene(scene_path, overrides);
  for (const view::ScriptEvent& e : script.events) {
    if (e.kind != view::EventKind::TurnElement && e.kind != view::EventKind::MoveElement) continue;
    std::vector<std::string> names;
    for (const ElementDesc& el : desc.elements) names.push_back(el.name);
    if (std::find(names.begin(), names.end(), e.element) != names.end()) continue;
    const std::string hint = nearest(e.element, names);
    throw Error(script_path + ": " + e.where + ".element: " + scene_path + " has no element named \"" + e.element +
                "\"" + (hint.empty() ? std::string() : "; did you mean \"" + hint + "\"?"));
  }
  const auto size = a.getSize("size");
  const int width = size ? size->first : script.width ? script.width : desc.observer.image_width;
  const int height = size ? size->second : script.height ? script.height : desc.observer.image_height;

  view::Window window(width, height, api, /*vsync=*/script_path.empty(), "pvrr view: " + scene_path);
  nlohmann::json stats;
  {
    view::Viewer viewer(window, scene_path, overrides, mode, width, height, script_path, std::move(script));
    viewer.run();
    stats = viewer.stats();
  }
  if (auto file = a.get("stats")) writeFileAtomic(*file, stats.dump(2) + "\n");
  return 0;
}

}  // namespace pvrr::app
