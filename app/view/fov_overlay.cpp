#include "app/view/fov_overlay.h"

#include <imgui.h>

#include <cmath>

namespace pvrr::app::view {

namespace {
// Colours (RGBA 0-255): the left eye's cells blue, the right eye's orange (as in pvrr fov's plan view), obstructed
// purple; translucent so the road shows through.
constexpr ImU32 kLeftCell = IM_COL32(40, 110, 255, 110), kRightCell = IM_COL32(255, 140, 20, 110),
                kObstructedCell = IM_COL32(200, 40, 200, 110);
// Vertices nearer than this in front of the observer (or behind it) leave their cell undrawn.
constexpr double kNearM = 0.01;
}  // namespace

void FovOverlay::trace(const Scene& scene, const SceneDesc& desc, const RayScene& rays, int element) {
  ++traces_;
  traced_ = true;
  cells_.clear();
  why_.clear();
  element_ = -1;
  if (!desc.vehicle) {
    why_ = "the scene has no vehicle frame (docs/scene-format.md \"vehicle\")";
    return;
  }
  int index = -1;
  if (element >= 0 && size_t(element) < scene.elements.size() &&
      scene.elements[size_t(element)].type == ElementType::Mirror)
    index = element;
  for (size_t i = 0; index < 0 && i < scene.elements.size(); ++i)
    if (scene.elements[i].type == ElementType::Mirror) index = int(i);
  if (index < 0) {
    why_ = "the scene has no mirror";
    return;
  }
  element_ = index;
  const VehicleFrame frame(*desc.vehicle);
  FovOptions o;
  o.samples = kOverlaySamples;
  for (const bool left : {true, false}) {
    const EyeFootprint f = traceFootprint(rays, index, frame, left ? desc.vehicle->eye_left : desc.vehicle->eye_right,
                                          left ? "left" : "right", o);
    for (int j = 0; j + 1 < f.n; ++j)
      for (int i = 0; i + 1 < f.n; ++i) {
        const size_t k[4] = {size_t(j * f.n + i), size_t(j * f.n + i + 1), size_t((j + 1) * f.n + i + 1),
                             size_t((j + 1) * f.n + i)};
        bool road = true, obstructed = false;
        for (const size_t c : k) {
          road = road && (f.fate[c] == RayFate::Road || f.fate[c] == RayFate::Obstructed);
          obstructed = obstructed || f.fate[c] == RayFate::Obstructed;
        }
        if (!road) continue;
        Cell cell{};
        for (int c = 0; c < 4; ++c) cell.world[c] = frame.toWorld(Vec3(f.road[k[c]], 0.0));
        cell.left = left;
        cell.obstructed = obstructed;
        cells_.push_back(cell);
      }
  }
}

void FovOverlay::draw(const Scene& scene, const SceneDesc& desc, const RayScene& rays, int element, int scene_build,
                      const Observer& ob) {
  drawn_ = 0;
  if (!on_) return;
  int index = element;
  if (index < 0 || size_t(index) >= scene.elements.size()) index = 0;
  const Mat4 pose = scene.elements.empty() ? Mat4(1.0) : scene.elements[size_t(index)].local_to_world;
  if (!traced_ || scene_build != build_ || element != asked_ || pose != pose_) {
    // Once per mirror pose (a turn of the element or a setting rebuilds the scene), not per frame.
    trace(scene, desc, rays, element);
    build_ = scene_build;
    asked_ = element;
    pose_ = pose;
  }
  const Mat4 view = ob.view();
  const double th = std::tan(0.5 * ob.fov_y_rad), aspect = double(ob.width) / double(ob.height);
  ImDrawList* dl = ImGui::GetBackgroundDrawList();
  // Cells tile the footprint: no anti-aliased fringes, which would leave a lighter seam along every shared edge
  // (the list's flags are set afresh each frame).
  dl->Flags &= ~ImDrawListFlags_AntiAliasedFill;
  for (const Cell& c : cells_) {
    ImVec2 px[4];
    bool ok = true;
    for (int k = 0; k < 4 && ok; ++k) {
      const Vec3 v = Vec3(view * Vec4(c.world[k], 1.0));  // camera: x right, y up, -z forward
      if (-v.z < kNearM) ok = false;
      const double x = v.x / (-v.z * th * aspect), y = v.y / (-v.z * th);
      px[k] = ImVec2(float(0.5 * (x + 1) * ob.width), float(0.5 * (1 - y) * ob.height));
    }
    if (!ok) continue;
    const ImU32 col = c.obstructed ? kObstructedCell : c.left ? kLeftCell : kRightCell;
    dl->AddTriangleFilled(px[0], px[1], px[2], col);
    dl->AddTriangleFilled(px[0], px[2], px[3], col);
    ++drawn_;
  }
}

void FovOverlay::panel() {
  ImGui::Checkbox("field of view on the road (O)", &on_);
  if (!on_) return;
  ImGui::SameLine();
  if (!why_.empty())
    ImGui::TextWrapped("nothing to show: %s", why_.c_str());
  else
    ImGui::Text("%zu cells, %d in view (left eye blue, right orange, obstructed purple)", cells_.size(), drawn_);
}

nlohmann::json FovOverlay::stats() const {
  nlohmann::json j = {{"on", on_}, {"traces", traces_}, {"cells", cells_.size()}, {"cells_drawn", drawn_}};
  if (!why_.empty()) j["note"] = why_;
  return j;
}

}  // namespace pvrr::app::view
