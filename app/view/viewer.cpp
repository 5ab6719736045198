#include "app/view/viewer.h"

#define GLFW_INCLUDE_NONE  // no GL header: the viewer itself makes no GL call
#include <GLFW/glfw3.h>
#include <imgui.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <deque>
#include <optional>
#include <thread>

#include "app/args.h"
#include "app/commands.h"
#include "app/report.h"
#include "app/view/element_pose.h"
#include "app/view/head.h"
#include "app/view/lens_probe.h"
#include "app/view/reference_tiles.h"
#include "app/view/save_view.h"
#include "app/view/script.h"
#include "app/view/window.h"
#include "app/view/wipe.h"
#include "pvrr/analysis/accuracy.h"
#include "pvrr/base/error.h"
#include "pvrr/base/format.h"
#include "pvrr/scene/scene_json.h"

namespace pvrr::app {
namespace view {
namespace {

using Clock = std::chrono::steady_clock;
using nlohmann::json;

// Eye steps (metres) and head turns (degrees) of one key press; Shift multiplies by kFast.
constexpr double kEyeStepM = 0.01, kTurnStepDeg = 1.0, kFast = 10.0;
// Mouse-look: degrees of head turn per pixel of drag.
constexpr double kLookDegPerPixel = 0.1;
// A left-button press within this many pixels of the wipe's split line drags the line, not the head.
constexpr double kWipeGrabPx = 8;
// The panel's step of moving an element (metres).
constexpr double kMoveStepM = 0.001;

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
      : window_(window), scene_path_(std::move(scene_path)), overrides_(std::move(overrides)), cli_mode_(mode),
        width_(width), height_(height), script_path_(std::move(script_path)), script_(std::move(script)) {
    glfwSetWindowUserPointer(window_.handle(), this);
    glfwSetKeyCallback(window_.handle(), [](GLFWwindow* w, int key, int, int action, int mods) {
      static_cast<Viewer*>(glfwGetWindowUserPointer(w))->onKey(key, action, mods);
    });
    rebuild();
  }
  ~Viewer() {
    reference_.reset();               // cancels a running trace and joins its threads
    window_.context().makeCurrent();  // GL objects go while their context is current
    wipe_.reset();
    seen_renderer_.reset();
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
  // Element `index` moved by `by_m` in its own frame (x right, y up, z along its normal), rebuilt likewise.
  void moveElement(int index, const Vec3& by_m);
  int elementIndex(const std::string& name) const;
  void elementsPanel();
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
    return {ob.eye, ob.target, ob.up, ob.width, ob.height, mode_, scene_builds_};
  }
  // The live reference: startReference traces the current view in the background (and draws the mode's frame
  // of it once with seen points, for the errors); discardReference cancels or drops it, saying why.
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
  std::string glName() const {
    return window_.context().backendName() + " (" + window_.context().glRenderer() + ")";
  }

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
  std::vector<std::string> pending_screenshots_, panel_screenshots_;
  int frames_ = 0, saved_ = 0;
  std::vector<double> frame_ms_;   // every frame, for --stats
  // Where each frame's time went: the renderer's frame, presenting it, the panel, the swap and input.
  std::vector<double> render_ms_, present_ms_, panel_ms_, swap_ms_;
  std::deque<double> recent_ms_;   // the last frames, for the panel
  enum class Drag { None, Look, Wipe };
  Drag drag_ = Drag::None;
  bool mouse_down_ = false;
  double last_x_ = 0, last_y_ = 0;

  int scene_builds_ = 0;
  double rebuild_ms_max_ = 0;  // the slowest rebuild after the first (a setting, a turned element)
  // The lens probe (scenes with a lens): the pixel under the cursor (the mouse when it moves, or a script's
  // "cursor"), read again when that pixel or the view changes.
  bool has_lens_ = false;
  bool probe_asked_ = false, cursor_seen_ = false;
  int probe_x_ = 0, probe_y_ = 0;
  double cursor_x_ = 0, cursor_y_ = 0;
  LensProbe probe_;
  bool probe_fresh_ = false;
  ViewKey probe_key_;
  int selected_ = 0;  // the element the panel and the keys I/K/J/L turn
  // Changes asked for by the panel or the keys, applied at the next frame (not inside the panel's frame).
  std::vector<std::string> pending_overrides_;
  double pending_yaw_rad_ = 0, pending_pitch_rad_ = 0;
  Vec3 pending_move_m_{0};
  std::unique_ptr<gl::Renderer> seen_renderer_;  // the mode's frame with seen points, for the reference's errors
  std::unique_ptr<ReferenceRun> reference_;
  std::unique_ptr<Wipe> wipe_;
  ViewKey reference_key_;
  bool reference_requested_ = false;  // by key or panel: started at the next frame
  bool waiting_reference_ = false;    // a script's "reference" event: later events wait for it
  bool heat_uploaded_ = false;
  double wipe_x_ = 0.5;  // the split line: 0 all reference, 1 all mode
  bool overlay_ = false;
  std::string reference_note_;  // why there is no reference now (cancelled, discarded)
  int references_started_ = 0, frames_while_tracing_ = 0;
  double frame_ms_max_while_tracing_ = 0, reference_start_ms_ = 0;
};

void Viewer::rebuild(bool keep_mode) {
  if (reference_) discardReference("discarded: the scene was rebuilt (a setting changed)");
  const auto t0 = Clock::now();
  window_.context().makeCurrent();
  seen_renderer_.reset();
  renderer_.reset();
  ++scene_builds_;
  rays_.reset();
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
  RaySceneOptions ro;
  ro.moving_elements = any_attached_;  // the head moves them
  rays_ = std::make_unique<RayScene>(ls_.scene, ro);
  gl::RendererOptions opt = gl::rendererOptionsFor(ls_.scene);
  opt.seen_points = false;  // the picture only, as pvrr render draws it
  opt.read_back = false;    // presented from the GPU
  renderer_ = std::make_unique<gl::Renderer>(ls_.scene, *rays_, opt);
  cache_ = gl::FrameCache{};
  if (scene_builds_ > 1)
    rebuild_ms_max_ = std::max(rebuild_ms_max_, std::chrono::duration<double, std::milli>(Clock::now() - t0).count());
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
        case EventKind::Screenshot: (e.with_panel ? panel_screenshots_ : pending_screenshots_).push_back(e.file); break;
        case EventKind::SaveView: saveViewTo(e.file); break;
        case EventKind::Quit: quit_ = true; break;
        case EventKind::Key: onKey(e.key, GLFW_PRESS, e.shift ? GLFW_MOD_SHIFT : 0); break;  // the keyboard's path
        case EventKind::Reference:
          startReference();
          waiting_reference_ = true;
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
    probe_ = probeLens(ls_.scene, *rays_, probe_x_, probe_y_);
    probe_key_ = viewKey();
    probe_fresh_ = true;
  }
  window_.context().makeCurrent();
  // A screenshot frame is drawn whole, every stage run (its own empty cache), so that it is what pvrr render
  // draws of the saved view: frames that reuse earlier maps (map reuse, render.map_reuse_margin_deg) differ
  // from a fresh frame in places, as they do in pvrr render --frames --orbit.
  gl::FrameCache whole;
  const gl::RasterFrame f = renderer_->render(mode_, pending_screenshots_.empty() ? &cache_ : &whole);
  cache_.environment_changed = false;  // the environment never changes while the window is open
  const auto t_render = Clock::now();
  presentFrame(ob);
  const auto t_present = Clock::now();
  if (!pending_screenshots_.empty()) {
    // Screenshots show the frame alone: taken before the panel is drawn over it.
    const ImageRGB8 img = window_.readBackBuffer(ob.width, ob.height);
    for (const std::string& file : pending_screenshots_) writePngAtomic(file, img, MissingFolder::Create);
    pending_screenshots_.clear();
  }
  window_.beginPanel();
  const double shown_ms = recent_ms_.empty() ? f.frame_ms : recent_ms_.back();
  if (show_panel_) panel(f, shown_ms);
  window_.endPanel();
  if (!panel_screenshots_.empty()) {
    const ImageRGB8 img = window_.readBackBuffer(ob.width, ob.height);
    for (const std::string& file : panel_screenshots_) writePngAtomic(file, img, MissingFolder::Create);
    panel_screenshots_.clear();
  }
  const auto t_panel = Clock::now();
  window_.swapAndPoll();

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
  present_ms_.push_back(span(t_render, t_present));
  panel_ms_.push_back(span(t_present, t_panel));
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

void Viewer::lensPanel() {
  if (!has_lens_ || !ImGui::CollapsingHeader("lens under the cursor (as pvrr lensmap)", ImGuiTreeNodeFlags_DefaultOpen))
    return;
  if (!probe_asked_ || !probe_fresh_) {
    ImGui::TextUnformatted("move the mouse over the lens");
    return;
  }
  if (!probe_.valid) {
    ImGui::Text("pixel (%d, %d): %s", probe_x_, probe_y_, probe_.reason.c_str());
    return;
  }
  const LensmapPoint& r = probe_.reading;
  ImGui::Text("%s at lens (%.2f, %.2f) mm, gaze (%.2f, %.2f) deg",
              ls_.scene.elements[size_t(probe_.element)].name.c_str(), r.lens_x_mm, r.lens_y_mm, r.gaze_x_deg,
              r.gaze_y_deg);
  ImGui::Text("sphere %+.2f D  cyl %+.2f D  axis %.0f deg (TABO)  mean %+.2f D", r.sphere_d, r.cylinder_d, r.axis_deg,
              r.mean_power_d);
  ImGui::Text("power error %+.2f D, unwanted cyl %.2f D; prism %.2f (h, base right +) %.2f (v, base up +) pd",
              r.power_error_d, r.unwanted_cylinder_d, r.prism_h, r.prism_v);
}

json Viewer::probeStats() const {
  if (!probe_asked_ || !probe_fresh_) return nullptr;
  json j = {{"pixel", {probe_.px, probe_.py}}, {"valid", probe_.valid}, {"reason", probe_.reason}};
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

void Viewer::planningLines(const gl::RasterFrame& f) {
  // What the pvrr mode's planning made of each element this frame (nothing where another mode drew it).
  const gl::RendererOptions opt = gl::rendererOptionsFor(ls_.scene);
  for (const ElementFrame& ef : f.elements) {
    if (ef.views.empty()) continue;
    double worst = 0;
    int fallbacks = 0, smallest = 1 << 30, largest = 0;
    for (const PatchView& pv : ef.views) {
      worst = std::max(worst, pv.fit.condition_number);
      fallbacks += pv.fit.fallback.empty() ? 0 : 1;
      const int side = gl::topLevelMapSide(ls_.scene, ef, pv, opt);
      smallest = std::min(smallest, side);
      largest = std::max(largest, side);
    }
    ImGui::TextWrapped(
        "%s: %zu patch%s, %zu vertices; maps %d..%d texels (longer side); viewpoint fit condition "
        "at most %.3g, %d fallbacks",
        ls_.scene.elements[size_t(ef.element)].name.c_str(), ef.views.size(), ef.views.size() == 1 ? "" : "es",
        ef.world_pos.size(), smallest, largest, worst, fallbacks);
  }
}

void Viewer::elementsPanel() {
  if (ls_.scene.elements.empty() || !ImGui::CollapsingHeader("elements and settings")) return;
  const Element& sel = ls_.scene.elements[size_t(selected_)];
  if (ImGui::BeginCombo("element", sel.name.c_str())) {
    for (size_t i = 0; i < ls_.scene.elements.size(); ++i)
      if (ImGui::Selectable(ls_.scene.elements[i].name.c_str(), int(i) == selected_)) selected_ = int(i);
    ImGui::EndCombo();
  }
  const PoseDesc& pose = ls_.desc.elements[size_t(selected_)].pose;
  ImGui::Text("normal [%.4f, %.4f, %.4f]%s", pose.normal.x, pose.normal.y, pose.normal.z,
              sel.attached_to_observer ? " (observer frame)" : "");
  ImGui::Text("turn about its vertex:");
  for (const auto& [label, yaw, pitch] :
       {std::tuple{"yaw -1 (J)", -1.0, 0.0}, std::tuple{"yaw +1 (L)", 1.0, 0.0}, std::tuple{"pitch -1 (K)", 0.0, -1.0},
        std::tuple{"pitch +1 (I)", 0.0, 1.0}}) {
    ImGui::SameLine();
    if (ImGui::Button(label)) pending_yaw_rad_ += radians(yaw), pending_pitch_rad_ += radians(pitch);
  }
  ImGui::Text("move 1 mm in its frame:");
  for (int k = 0; k < 6; ++k) {
    static const char* const kLabels[6] = {"x-", "x+", "y-", "y+", "z-", "z+"};
    ImGui::SameLine();
    if (ImGui::Button(kLabels[k])) pending_move_m_[k / 2] += (k % 2 ? 1 : -1) * kMoveStepM;
  }
  const std::string el = "elements[" + std::to_string(selected_) + "].";
  const TessellationDesc& t = ls_.desc.elements[size_t(selected_)].tessellation;
  int n = t.n_u;
  if (t.mode == TessellationDesc::Mode::Grid &&
      ImGui::InputInt("tessellation (N x N)", &n, 2, 8, ImGuiInputTextFlags_EnterReturnsTrue))
    pending_overrides_.push_back(el + "tessellation=" + std::to_string(std::clamp(n, 2, 1024)));
  int map_size = ls_.scene.render.map_size;
  if (ImGui::InputInt("map size (texels)", &map_size, 256, 1024, ImGuiInputTextFlags_EnterReturnsTrue))
    pending_overrides_.push_back("render.map_size=" + std::to_string(std::clamp(map_size, 64, 8192)));
  int depth = ls_.scene.render.max_depth;
  if (ImGui::SliderInt("max depth", &depth, 1, 16))
    pending_overrides_.push_back("render.max_depth=" + std::to_string(depth));
  ImGui::Text("dispersion:");
  for (DispersionMode d : {DispersionMode::Off, DispersionMode::Rgb, DispersionMode::Spectral}) {
    ImGui::SameLine();
    if (ImGui::RadioButton(nameOf(d), ls_.scene.render.dispersion == d) && ls_.scene.render.dispersion != d)
      pending_overrides_.push_back(std::string("render.dispersion=\"") + nameOf(d) + "\"");
  }
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

void Viewer::startReference() {
  updateObserver();
  if (reference_ && (reference_->finished() || !(viewKey() == reference_key_))) reference_.reset();  // traced anew
  if (reference_ && viewKey() == reference_key_) return;  // this view's reference is being traced
  window_.context().makeCurrent();
  const auto t0 = Clock::now();
  if (!seen_renderer_) {
    gl::RendererOptions opt = gl::rendererOptionsFor(ls_.scene);
    opt.seen_points = true;  // as pvrr compare draws the frame it measures
    opt.read_back = true;
    seen_renderer_ = std::make_unique<gl::Renderer>(ls_.scene, *rays_, opt);
  }
  gl::FrameCache fresh;  // every stage run, as compare's frame
  gl::RasterFrame f = seen_renderer_->render(mode_, &fresh);
  const int threads = std::max(1, int(std::thread::hardware_concurrency()) - 1);  // one core for the window
  reference_ = std::make_unique<ReferenceRun>(ls_.scene, std::move(static_cast<Frame&>(f)), threads);
  if (!wipe_) wipe_ = std::make_unique<Wipe>(window_);
  wipe_->reset(reference_->width(), reference_->height());
  heat_uploaded_ = false;
  reference_key_ = viewKey();
  reference_note_.clear();
  ++references_started_;
  reference_start_ms_ = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

void Viewer::discardReference(const std::string& why) {
  reference_.reset();
  reference_note_ = why;
  waiting_reference_ = false;
}

void Viewer::presentFrame(const Observer& ob) {
  if (!reference_) {
    window_.present(renderer_->colorTexture(), ob.width, ob.height);
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

void Viewer::referencePanel() {
  if (!ImGui::CollapsingHeader("reference (Embree, exact)", ImGuiTreeNodeFlags_DefaultOpen)) return;
  if (!reference_) {
    if (ImGui::Button("trace this view (T)")) reference_requested_ = true;
    if (!reference_note_.empty()) {
      ImGui::SameLine();
      ImGui::TextWrapped("last: %s", reference_note_.c_str());
    }
    return;
  }
  if (!reference_->finished()) {
    ImGui::ProgressBar(float(reference_->fraction()), ImVec2(260, 0));
    ImGui::SameLine();
    if (ImGui::Button("cancel (T)")) reference_requested_ = true;
    ImGui::Text("tracing in %d background threads; drag the line to compare", reference_->threads());
  } else {
    ImGui::Text("traced in %.0f ms (%d threads); left: %s, right: reference", reference_->traceMs(),
                reference_->threads(), nameOf(mode_));
  }
  float wipe = float(wipe_x_);
  if (ImGui::SliderFloat("wipe", &wipe, 0.0f, 1.0f, "%.2f")) wipe_x_ = double(wipe);
  ImGui::Checkbox("error overlay (E)", &overlay_);
  if (!reference_->finished()) return;
  if (!reference_->hasErrors()) {
    ImGui::TextWrapped("no error figures: the mode's frame has no seen points");
    return;
  }
  const ErrorStats& st = reference_->stats();
  ImGui::Text("angular error (as pvrr compare): median %.3f', p95 %.3f', max %.2f' over %zu px", st.median_arcmin,
              st.p95_arcmin, st.max_arcmin, st.pixels);
  // The heat map's colour bar: errorHeatColour is linear in each third, so three gradients draw it exactly.
  ImDrawList* dl = ImGui::GetWindowDrawList();
  const ImVec2 p = ImGui::GetCursorScreenPos();
  const float w = 300, h = 12;
  for (int k = 0; k < 3; ++k) {
    const Vec3 a = errorHeatColour(k / 3.0), b = errorHeatColour((k + 1) / 3.0);
    const ImU32 ca = ImGui::GetColorU32(ImVec4(float(a.r), float(a.g), float(a.b), 1)),
                cb = ImGui::GetColorU32(ImVec4(float(b.r), float(b.g), float(b.b), 1));
    dl->AddRectFilledMultiColor(ImVec2(p.x + w * float(k) / 3, p.y), ImVec2(p.x + w * float(k + 1) / 3, p.y + h), ca,
                                cb, cb, ca);
  }
  ImGui::Dummy(ImVec2(w, h));
  ImGui::Text("0'");
  ImGui::SameLine(w - 40);
  ImGui::Text("%.3g'", reference_->scaleArcmin());
}

void Viewer::panel(const gl::RasterFrame& f, double frame_ms) {
  ImGui::SetNextWindowPos(ImVec2(8, 8), ImGuiCond_FirstUseEver);
  ImGui::SetNextWindowSize(ImVec2(460, 0), ImGuiCond_FirstUseEver);
  ImGui::SetNextWindowBgAlpha(0.85f);
  ImGui::Begin("pvrr view");
  const double med = median(std::vector<double>(recent_ms_.begin(), recent_ms_.end()));
  ImGui::Text("frame %.2f ms, %.1f fps (median of the last %zu: %.2f ms)", frame_ms, med > 0 ? 1000.0 / med : 0.0,
              recent_ms_.size(), med);
  ImGui::Text("renderer %.2f ms; %dx%d", f.frame_ms, f.width, f.height);
  ImGui::TextWrapped("GL: %s, %s", glName().c_str(), window_.context().glVersion().c_str());
  ImGui::Text("mode:");
  for (RenderMode m : {RenderMode::Pvrr, RenderMode::Envmap, RenderMode::Impostor, RenderMode::Raster}) {
    ImGui::SameLine();
    if (ImGui::RadioButton(nameOf(m), mode_ == m)) setMode(m);
  }
  const Observer& ob = ls_.scene.observer;
  ImGui::Text("eye [%.3f, %.3f, %.3f] m, head yaw %.1f, pitch %.1f deg", ob.eye.x, ob.eye.y, ob.eye.z,
              degrees(pose_.yaw_rad), degrees(pose_.pitch_rad));
  if (ImGui::Button("design eye (Home)")) pose_ = HeadPose{};
  ImGui::SameLine();
  if (ImGui::Button("screenshot (F12)")) pending_screenshots_.push_back("out/view-" + std::to_string(++saved_) + ".png");
  ImGui::SameLine();
  if (ImGui::Button("save view (V)")) saveViewTo("out/view-" + std::to_string(++saved_) + ".json");
  if (ImGui::BeginTable("stages", 3, ImGuiTableFlags_Borders | ImGuiTableFlags_RowBg | ImGuiTableFlags_SizingStretchProp)) {
    ImGui::TableSetupColumn("stage", ImGuiTableColumnFlags_WidthStretch, 1.0f);
    ImGui::TableSetupColumn("ms", ImGuiTableColumnFlags_WidthFixed, 50.0f);
    ImGui::TableSetupColumn("ran, or why not", ImGuiTableColumnFlags_WidthStretch, 2.2f);
    ImGui::TableHeadersRow();
    for (const StageTiming& s : f.stages.stages) {
      ImGui::TableNextRow();
      ImGui::TableNextColumn();
      ImGui::TextUnformatted(s.name.c_str());
      ImGui::TableNextColumn();
      if (s.ran) ImGui::Text("%.2f", s.ms);
      ImGui::TableNextColumn();
      const std::string what = s.ran ? "ran" + (s.note.empty() ? std::string() : ": " + s.note) : "skipped: " + s.reason;
      ImGui::TextWrapped("%s", what.c_str());
    }
    ImGui::EndTable();
  }
  planningLines(f);
  referencePanel();
  lensPanel();
  elementsPanel();
  if (ImGui::CollapsingHeader("keys")) {
    ImGui::TextUnformatted(
        "drag (left button)  turn the head\n"
        "arrows              turn the head 1 deg (Shift: 10)\n"
        "W/S A/D R/F         eye forward/back, left/right, up/down 1 cm (Shift: 10)\n"
        "Home or H           back to the design eye point\n"
        "1 2 3 4             mode pvrr, envmap, impostor, raster\n"
        "J/L I/K             turn the selected element 1 deg in yaw / pitch (Shift: 10)\n"
        "T                   trace the reference of this view (again: cancel)\n"
        "E                   error overlay on or off\n"
        "drag the split line wipe between the mode and the reference\n"
        "Tab                 hide or show this panel\n"
        "F12 / V             screenshot / save view (out/view-N.png, .json)\n"
        "Esc                 quit");
  }
  ImGui::End();
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
    case GLFW_KEY_F12: pending_screenshots_.push_back("out/view-" + std::to_string(++saved_) + ".png"); break;
    case GLFW_KEY_V: saveViewTo("out/view-" + std::to_string(++saved_) + ".json"); break;
    case GLFW_KEY_ESCAPE: quit_ = true; break;
    default: break;
  }
}

void Viewer::saveViewTo(const std::string& file) {
  saveView(file, scene_path_, overrides_, ls_.scene.observer, ls_.desc.unit_m);
  std::printf("%s\n", file.c_str());
}

void Viewer::run() {
  while (!quit_) {
    runEvents();
    if (quit_ || window_.closeRequested()) break;
    frame();
  }
  if (!pending_screenshots_.empty() || !panel_screenshots_.empty()) frame();  // asked for on the last frame
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
            // Starting costs one frame of the mode drawn with seen points (the first time, its programs built too).
            {"start_ms", reference_start_ms_},
            {"frames_while_tracing", frames_while_tracing_},
            {"frame_ms_max_while_tracing", frame_ms_max_while_tracing_}};
  j["wipe_x"] = wipe_x_;
  j["overlay"] = overlay_;
  if (!reference_ || !reference_->finished()) return j;
  j["threads"] = reference_->threads();
  j["trace_ms"] = reference_->traceMs();
  if (reference_->hasErrors()) {
    const ErrorStats& st = reference_->stats();
    j["pixels"] = st.pixels;
    j["angular_error_arcmin"] = {{"median", st.median_arcmin}, {"p95", st.p95_arcmin}, {"max", st.max_arcmin}};
    j["heat_map_scale_arcmin"] = reference_->scaleArcmin();
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
          // Medians of the frame's parts (ms): the renderer's frame (as pvrr render times it, plus the head's
          // update), presenting it, the panel (with any screenshot), and the swap with the input.
          {"parts_ms_median",
           {{"render", t.empty() ? 0.0 : median(render_ms_)},
            {"present", t.empty() ? 0.0 : median(present_ms_)},
            {"panel", t.empty() ? 0.0 : median(panel_ms_)},
            {"swap", t.empty() ? 0.0 : median(swap_ms_)}}},
          {"size", {design_.width, design_.height}},
          {"reference", referenceStats()},
          {"lens_probe", probeStats()},
          // Rebuilds of the scene after the first (a "set", a panel setting, a turned element), and the slowest
          // one's time (ms; the renderer's first frame after it, with its programs, is in frame_ms_max).
          {"rebuilds", scene_builds_ - 1},
          {"rebuild_ms_max", rebuild_ms_max_},
          {"gl", glName()}};
}

}  // namespace
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
