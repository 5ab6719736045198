// The viewer's panel (Dear ImGui): the frame's time and stages, the planning of each element, the live
// reference, the lens under the cursor, the elements' poses and settings, the keys.
#include <imgui.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <tuple>

#include "app/view/viewer_impl.h"
#include "pvrr/base/format.h"

namespace pvrr::app::view {

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

void Viewer::planningLines(const gl::RasterFrame& f) {
  // What the pvrr mode's planning made of each element (nothing where another mode drew it).
  const auto now = Clock::now();
  if (planning_lines_.empty() || planning_mode_ != mode_ ||
      std::chrono::duration<double, std::milli>(now - planning_made_).count() >= kPlanningRefreshMs) {
    planning_lines_.clear();
    planning_made_ = now;
    planning_mode_ = mode_;
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
      char line[512];
      std::snprintf(line, sizeof line,
                    "%s: %zu patch%s, %zu vertices; maps %d..%d texels (longer side); viewpoint fit condition at "
                    "most %.3g, %d fallbacks",
                    ls_.scene.elements[size_t(ef.element)].name.c_str(), ef.views.size(),
                    ef.views.size() == 1 ? "" : "es", ef.world_pos.size(), smallest, largest, worst, fallbacks);
      planning_lines_.push_back(line);
    }
  }
  for (const std::string& line : planning_lines_) ImGui::TextWrapped("%s", line.c_str());
}

void Viewer::timePanel() {
  if (!animated_) return;
  float t = float(time_s_);
  if (ImGui::SliderFloat("time (s)", &t, 0.0f, float(duration_s_), "%.2f")) {
    playing_ = false;
    pending_time_s_ = double(t);  // at the next frame
  }
  ImGui::SameLine();
  if (ImGui::Button(playing_ ? "pause (Space)" : "play (Space)")) {
    playing_ = !playing_;
    played_at_ = Clock::now();
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
  // Pixels whose reference path ended at the depth limit have no seen point: not compared (as pvrr compare).
  const size_t limited = reference_->depthLimitPixels();
  if (!reference_->hasErrors()) {
    ImGui::TextWrapped("no error figures: the mode's frame has no seen points");
    if (limited > 0)
      ImGui::TextWrapped("%zu px where the reference's path ended at the depth limit (render.max_depth %d)", limited,
                         ls_.scene.render.max_depth);
    return;
  }
  const ErrorStats& st = reference_->stats();
  ImGui::Text("angular error (as pvrr compare): median %.3f', p95 %.3f', max %.2f' over %zu px", st.median_arcmin,
              st.p95_arcmin, st.max_arcmin, st.pixels);
  if (limited > 0) {
    const DepthLimitColour& dl = reference_->depthLimit();
    ImGui::TextWrapped("not compared: %zu px where the reference's path ended at the depth limit (render.max_depth "
                       "%d; no seen point, drawn black); by colour: %zu drawn lit, PSNR %.1f dB",
                       limited, ls_.scene.render.max_depth, dl.drawn_lit, dl.psnr_db);
  }
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
  ImGui::SetNextWindowBgAlpha(1.0f);  // opaque: the frame under it is not presented (panelHole)
  ImGui::Begin("pvrr view");
  {
    // Its rectangle less a pixel all round (the border's half pixels), while the window is drawn whole: not
    // collapsed (a collapsed title bar is translucent). In framebuffer pixels (ImGui's are the screen's).
    const ImVec2 scale = ImGui::GetIO().DisplayFramebufferScale, at = ImGui::GetWindowPos(),
                 extent = ImGui::GetWindowSize();
    const ImVec2 pos(at.x * scale.x, at.y * scale.y), size(extent.x * scale.x, extent.y * scale.y);
    panel_list_ = ImGui::IsWindowCollapsed() ? nullptr : ImGui::GetWindowDrawList();
    panel_rect_ = {int(std::ceil(pos.x)) + 1, int(std::ceil(pos.y)) + 1, int(std::floor(pos.x + size.x)) - 1,
                   int(std::floor(pos.y + size.y)) - 1};
    panel_outer_ = {int(std::floor(pos.x)), int(std::floor(pos.y)), int(std::ceil(pos.x + size.x)),
                    int(std::ceil(pos.y + size.y))};
  }
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
  if (ImGui::Button("screenshot (F12)"))
    pending_screenshots_.push_back("out/view-" + std::to_string(++saved_) + ".png");
  ImGui::SameLine();
  if (ImGui::Button("save view (V)")) saveViewTo("out/view-" + std::to_string(++saved_) + ".json");
  if (ImGui::BeginTable("stages", 3,
                        ImGuiTableFlags_Borders | ImGuiTableFlags_RowBg | ImGuiTableFlags_SizingStretchProp)) {
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
      const std::string what =
          s.ran ? "ran" + (s.note.empty() ? std::string() : ": " + s.note) : "skipped: " + s.reason;
      ImGui::TextWrapped("%s", what.c_str());
    }
    ImGui::EndTable();
  }
  timePanel();
  planningLines(f);
  referencePanel();
  lensPanel();
  elementsPanel();
  fov_overlay_.panel();
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
        "O                   field of view on the road (the mirror's footprint) on or off\n"
        "drag the split line wipe between the mode and the reference\n"
        "Space               play or pause an animated scene's time\n"
        "Tab                 hide or show this panel\n"
        "F12 / V             screenshot / save view (out/view-N.png, .json)\n"
        "Esc                 quit");
  }
  ImGui::End();
}

}  // namespace pvrr::app::view
