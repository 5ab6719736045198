#include "app/view/fov_overlay.h"

#include <imgui.h>

#include <algorithm>
#include <array>
#include <cmath>

#include "pvrr/analysis/fov_eyes.h"

namespace pvrr::app::view {

namespace {
// Colours (RGBA 0-255): the left eye's cells blue, the right eye's orange (as in pvrr fov's plan view), obstructed
// purple; translucent so the road shows through.
constexpr ImU32 kLeftCell = IM_COL32(40, 110, 255, 110), kRightCell = IM_COL32(255, 140, 20, 110),
                kObstructedCell = IM_COL32(200, 40, 200, 110);
// Vertices nearer than this in front of the observer (or behind it) leave their cell undrawn.
constexpr double kNearM = 0.01;

double cross(Vec2 a, Vec2 b, Vec2 c) { return (b.x - a.x) * (c.y - b.y) - (b.y - a.y) * (c.x - b.x); }

// Whether p lies in triangle abc (counter-clockwise), its boundary included.
bool inTriangle(Vec2 p, Vec2 a, Vec2 b, Vec2 c) {
  return cross(a, b, p) >= 0 && cross(b, c, p) >= 0 && cross(c, a, p) >= 0;
}

// A simple polygon cut into triangles by ear clipping (counter-clockwise triangles; the polygon in either
// orientation). Points repeated in a row are dropped, and so are vertices on the line through their neighbours
// (within 1e-12 of the product of the two edges' lengths): they add no area. Should no ear be found (a polygon
// that is not simple), what is left is not filled.
std::vector<std::array<Vec2, 3>> triangulate(const std::vector<Vec2>& poly) {
  std::vector<Vec2> p;
  for (const Vec2& v : poly)
    if (p.empty() || glm::length(v - p.back()) > 1e-9) p.push_back(v);
  while (p.size() > 1 && glm::length(p.front() - p.back()) <= 1e-9) p.pop_back();
  std::vector<std::array<Vec2, 3>> out;
  if (p.size() < 3) return out;
  if (signedArea(p) < 0) std::reverse(p.begin(), p.end());
  std::vector<size_t> prev(p.size()), next(p.size());
  for (size_t i = 0; i < p.size(); ++i) {
    prev[i] = (i + p.size() - 1) % p.size();
    next[i] = (i + 1) % p.size();
  }
  size_t left = p.size(), v = 0, since_ear = 0;
  while (left > 3 && since_ear < left) {
    const size_t a = prev[v], c = next[v];
    const double k = cross(p[a], p[v], p[c]);
    const double scale = glm::length(p[v] - p[a]) * glm::length(p[c] - p[v]);
    bool cut = std::abs(k) <= 1e-12 * scale;  // on the line through its neighbours: dropped, no triangle
    bool ear = false;
    if (!cut && k > 0) {
      ear = true;
      for (size_t w = next[c]; w != a && ear; w = next[w])
        if (p[w] != p[a] && p[w] != p[v] && p[w] != p[c] && inTriangle(p[w], p[a], p[v], p[c])) ear = false;
      cut = ear;
    }
    if (!cut) {
      v = c;
      ++since_ear;
      continue;
    }
    if (ear) out.push_back({p[a], p[v], p[c]});
    next[a] = c;
    prev[c] = a;
    --left;
    since_ear = 0;
    v = a;  // the neighbour may have become an ear
  }
  if (left == 3 && cross(p[prev[v]], p[v], p[next[v]]) > 0) out.push_back({p[prev[v]], p[v], p[next[v]]});
  return out;
}
}  // namespace

void FovOverlay::trace(const Scene& scene, const SceneDesc& desc, const RayScene& rays, int element) {
  ++traces_;
  traced_ = true;
  cells_.clear();
  triangles_.clear();
  per_sample_ = false;
  eye_samples_ = 0;
  ellipse_ = has_ellipse_ = false;
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
  has_ellipse_ = bool(desc.vehicle->eye_ellipse);
  ellipse_ = has_ellipse_ && ellipse_choice_ != 0;
  if (ellipse_) {
    // Per eye, the union of its samples' footprints (pvrr fov --eyes ellipse's footprint.<eye>.polygon), cut into
    // triangles on the road.
    const std::vector<EyeSample> samples = eyeEllipseSamples(frame, *desc.vehicle->eye_ellipse);
    eye_samples_ = int(samples.size());
    for (const bool left : {true, false}) {
      std::vector<std::vector<Vec2>> polys;
      for (const EyeSample& e : samples)
        if ((e.eye == "left") == left) polys.push_back(traceFootprint(rays, index, frame, e.world, e.eye, o).outline);
      std::vector<std::vector<Vec2>> fill = {unionOfPolygons(polys)};
      if (fill[0].empty() && !polys.empty()) {
        per_sample_ = true;
        fill = polys;
      }
      for (const std::vector<Vec2>& poly : fill)
        for (const std::array<Vec2, 3>& t : triangulate(poly)) {
          Triangle tri{};
          for (int c = 0; c < 3; ++c) tri.world[c] = frame.toWorld(Vec3(t[size_t(c)], 0.0));
          tri.left = left;
          triangles_.push_back(tri);
        }
    }
    return;
  }
  eye_samples_ = 2;
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
  const bool ellipse = desc.vehicle && desc.vehicle->eye_ellipse && ellipse_choice_ != 0;
  if (!traced_ || scene_build != build_ || element != asked_ || pose != pose_ || ellipse != asked_ellipse_) {
    // Once per mirror pose (a turn of the element or a setting rebuilds the scene), not per frame.
    trace(scene, desc, rays, element);
    build_ = scene_build;
    asked_ = element;
    asked_ellipse_ = ellipse;
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
  for (const Triangle& t : triangles_) {
    // Clipped in camera space at kNearM in front of the observer (Sutherland-Hodgman, one plane): at most 4 points.
    Vec3 cam[3];
    for (int k = 0; k < 3; ++k) cam[k] = Vec3(view * Vec4(t.world[k], 1.0));
    Vec3 poly[4];
    int n = 0;
    for (int k = 0; k < 3; ++k) {
      const Vec3 &a = cam[k], &b = cam[(k + 1) % 3];
      const double da = -a.z - kNearM, db = -b.z - kNearM;
      if (da >= 0) poly[n++] = a;
      if ((da >= 0) != (db >= 0)) poly[n++] = a + (b - a) * (da / (da - db));
    }
    if (n < 3) continue;
    ImVec2 px[4];
    for (int k = 0; k < n; ++k) {
      const double x = poly[k].x / (-poly[k].z * th * aspect), y = poly[k].y / (-poly[k].z * th);
      px[k] = ImVec2(float(0.5 * (x + 1) * ob.width), float(0.5 * (1 - y) * ob.height));
    }
    dl->AddConvexPolyFilled(px, n, t.left ? kLeftCell : kRightCell);
    ++drawn_;
  }
}

void FovOverlay::panel() {
  ImGui::Checkbox("field of view on the road (O)", &on_);
  if (!on_) return;
  ImGui::SameLine();
  if (!why_.empty()) {
    ImGui::TextWrapped("nothing to show: %s", why_.c_str());
    return;
  }
  if (!has_ellipse_) {
    ImGui::Text("%zu cells, %d in view (left eye blue, right orange, obstructed purple)", cells_.size(), drawn_);
    return;
  }
  // Offered where the scene has an eye ellipse (used unless turned off here); what is shown on a line of its own.
  bool ellipse = ellipse_;
  if (ImGui::Checkbox("eye ellipse", &ellipse)) ellipse_choice_ = ellipse ? 1 : 0;
  if (ellipse_)
    ImGui::TextWrapped("%d eye positions, %zu triangles, %d in view (left eye blue, right orange; obstruction not "
                       "shown%s)",
                       eye_samples_, triangles_.size(), drawn_, per_sample_ ? "; filled per sample" : "");
  else
    ImGui::TextWrapped("the ocular points: %zu cells, %d in view (left eye blue, right orange, obstructed purple)",
                       cells_.size(), drawn_);
}

nlohmann::json FovOverlay::stats() const {
  nlohmann::json j = {{"on", on_},
                      {"traces", traces_},
                      {"eyes", ellipse_ ? "ellipse" : "ocular points"},
                      {"eye_samples", eye_samples_},
                      {"cells", cells_.size()},
                      {"cells_drawn", drawn_}};
  if (ellipse_) {
    j["triangles"] = triangles_.size();
    j["per_sample"] = per_sample_;
  }
  if (!why_.empty()) j["note"] = why_;
  return j;
}

}  // namespace pvrr::app::view
