// pvrr caustic: the reference's caustic on a receiving surface (issue 23; the method: pvrr/trace/light_tracer.h,
// the figures: pvrr/analysis/caustic_metrics.h; docs/caustics.md).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "app/args.h"
#include "app/commands.h"
#include "app/sketch.h"
#include "pvrr/analysis/caustic_metrics.h"
#include "pvrr/base/error.h"
#include "pvrr/base/format.h"
#include "pvrr/method/caustic_mesh.h"
#include "pvrr/trace/light_tracer.h"

namespace fs = std::filesystem;
using nlohmann::json;

namespace pvrr::app {

namespace {

constexpr int kDefaultPhotonsPerSide = 512;
constexpr int kDefaultCells = 160;
// The automatic window: about the landed photons' power centroid, out to kWindowScale times the radius that
// holds kWindowQuantile of their power, at least kMinWindow_m across.
constexpr double kWindowQuantile = 0.99, kWindowScale = 1.3, kMinWindow_m = 0.004;
// How far from the receiver's plane a hit on its own mesh may lie (the mesh is that plane: rounding only).
constexpr double kSlab_m = 1e-3;

// printf into a string (pvrr::fmt takes one number).
template <typename... T>
std::string sfmt(const char* f, T... v) {
  char buf[512];
  std::snprintf(buf, sizeof buf, f, v...);
  return buf;
}

json vec3(const Vec3& v) { return json::array({v.x, v.y, v.z}); }
json vec2(const Vec2& v) { return json::array({v.x, v.y}); }
double mean3(const Vec3& v) { return (v.x + v.y + v.z) / 3.0; }

// A receiver: a quad or ground of the scene (their rectangles are the scene's own), or a curved mesh that is a
// height field over its best-fit plane (pvrr/method/caustic_mesh.h heightFieldReceivers: the rectangle in that
// plane; the map holds the irradiance per unit area of the surface).
// A mesh that is neither (a box, a sphere) is split into sheets (pvrr/method/receiver_sheets.h): the receiver is
// then one sheet, named "<mesh>-sheet<k>" as pvrr compare names it, and only photons hitting its triangles count.
struct Receiver {
  int index = -1;  // environment object = mesh index (a curved receiver: its mesh index)
  std::string name;
  ReceiverRect rect;
  bool curved = false;
  ReceiverSheet sheet;  // whole unless the mesh is split into sheets
};

// The sheets of the meshes split into sheets (none for a planar or one-sheet mesh), each with the scalar power of
// the photons landing on it: the meshes split once, the photons summed once.
std::vector<std::pair<Receiver, double>> litSheets(const Scene& scene, const PhotonBundle& b) {
  std::vector<std::pair<Receiver, double>> out;
  for (const CausticReceiver& c : sheetReceivers(scene))
    out.push_back({Receiver{c.mesh, scene.meshes[size_t(c.mesh)].name + "-sheet" + std::to_string(c.sheet.index),
                            c.full, c.curved, c.sheet},
                   0.0});
  for (const CausticPhoton& p : b.photons) {
    if (p.mesh < 0 || !std::isfinite(p.t_hit)) continue;
    for (auto& [sheet, power] : out)
      if (sheet.index == p.mesh && sheet.sheet.holds(p.triangle)) power += mean3(p.power);
  }
  return out;
}

// The height-field receiver of mesh `mesh`, if it is one.
std::optional<Receiver> curvedReceiver(const Scene& scene, int mesh) {
  for (const CausticReceiver& c : heightFieldReceivers(scene))
    if (c.mesh == mesh) return Receiver{mesh, scene.meshes[size_t(mesh)].name, c.full, true, ReceiverSheet{}};
  return std::nullopt;
}

Receiver receiverOf(const SceneDesc& desc, int index) {
  const EnvObjectDesc& o = desc.environment[size_t(index)];
  Receiver r;
  r.index = index;
  r.name = o.name.empty() ? std::string(nameOf(o.type)) + std::to_string(index) : o.name;
  r.rect.centre = o.position;
  r.rect.u_axis = glm::normalize(o.u_axis);
  r.rect.v_axis = glm::normalize(o.v_axis);
  r.rect.width_m = o.size.x;
  r.rect.height_m = o.size.y;
  return r;
}

bool isPlanar(const EnvObjectDesc& o) {
  return o.type == EnvObjectDesc::Type::Quad || o.type == EnvObjectDesc::Type::Ground;
}

// --receiver NAME, else the quad, ground or height-field mesh that receives the most caustic power.
Receiver chooseReceiver(const SceneDesc& desc, const Scene& scene, const PhotonBundle& b, const Args& a,
                        const std::string& path) {
  const std::optional<std::string> asked = a.get("receiver");
  if (asked) {
    std::vector<std::string> names;
    for (size_t i = 0; i < desc.environment.size(); ++i) {
      const EnvObjectDesc& o = desc.environment[i];
      if (o.name != *asked) {
        names.push_back(o.name);
        continue;
      }
      if (isPlanar(o)) return receiverOf(desc, int(i));
      for (size_t m = 0; m < scene.meshes.size(); ++m) {
        if (scene.meshes[m].name != *asked) continue;
        if (const std::optional<Receiver> c = curvedReceiver(scene, int(m))) return *c;
        // Split into sheets: the one the most caustic light lands on.
        std::vector<std::pair<Receiver, double>> sheets = litSheets(scene, b);
        sheets.erase(
            std::remove_if(sheets.begin(), sheets.end(), [&](const auto& x) { return x.first.index != int(m); }),
            sheets.end());
        const auto lit = std::max_element(sheets.begin(), sheets.end(),
                                          [](const auto& x, const auto& y) { return x.second < y.second; });
        if (lit != sheets.end() && lit->second > 0) return lit->first;
        if (lit != sheets.end())
          throw Error(path + ": environment[" + std::to_string(i) + "] (" + o.name + "): no caustic light lands on " +
                      "any of its " + std::to_string(sheets.size()) + " sheets");
      }
      throw Error(path + ": environment[" + std::to_string(i) + "] (" + o.name + "): a receiver must be a quad, a " +
                  "ground or a mesh with a sheet that is a height field over a plane, not this " +
                  std::string(nameOf(o.type)));
    }
    const std::string hint = nearest(*asked, names);
    throw Error(path + ": environment: no object named \"" + *asked + "\"" +
                (hint.empty() ? "" : "; did you mean \"" + hint + "\"?"));
  }
  std::vector<double> power(std::max(desc.environment.size(), scene.meshes.size()), 0.0);
  for (const CausticPhoton& p : b.photons)
    if (p.mesh >= 0 && size_t(p.mesh) < power.size()) power[size_t(p.mesh)] += mean3(p.power);
  int best = -1;
  for (size_t i = 0; i < desc.environment.size(); ++i)
    if (isPlanar(desc.environment[i]) && power[i] > 0 && (best < 0 || power[i] > power[size_t(best)])) best = int(i);
  std::optional<Receiver> curved;
  for (const CausticReceiver& c : heightFieldReceivers(scene))
    if (power[size_t(c.mesh)] > 0 && power[size_t(c.mesh)] > (best < 0 ? 0.0 : power[size_t(best)]) &&
        (!curved || power[size_t(c.mesh)] > power[size_t(curved->index)]))
      curved = Receiver{c.mesh, scene.meshes[size_t(c.mesh)].name, c.full, true, ReceiverSheet{}};
  // A sheet of a split mesh competes with the rest by its own landed power.
  double curved_power = curved ? power[size_t(curved->index)] : 0.0;
  for (const auto& [sheet, sheet_power] : litSheets(scene, b))
    if (sheet_power > 0 && sheet_power > (best < 0 ? 0.0 : power[size_t(best)]) && sheet_power > curved_power) {
      curved = sheet;
      curved_power = sheet_power;
    }
  if (curved) return *curved;
  if (best < 0)
    throw Error(path + ": environment: no quad, ground, height-field mesh or sheet of a mesh receives caustic light (" +
                std::to_string(b.photons.size()) + " photons left the elements); name a receiver with --receiver");
  return receiverOf(desc, best);
}

// The window over the receiver (receiver coordinates): --window CU,CV,W,H, else about the landed photons.
void chooseWindow(Receiver& r, const PhotonBundle& b, const Args& a, const std::string& path) {
  const ReceiverRect full = r.rect;
  Vec2 c(0);
  double w = 0, h = 0;
  if (a.has("window")) {
    const std::vector<double> v = a.getNumbers("window", 4);
    if (!(v[2] > 0) || !(v[3] > 0)) usageError("caustic", "--window: expected CU,CV,W,H with W, H > 0 (metres)");
    c = Vec2(v[0], v[1]), w = v[2], h = v[3];
  } else {
    std::vector<std::pair<Vec2, double>> landed;
    for (const CausticPhoton& p : b.photons) {
      if (p.mesh != r.index || !std::isfinite(p.t_hit) || !r.sheet.holds(p.triangle)) continue;
      const Vec2 uv = full.toReceiver(p.origin + p.t_hit * p.direction);
      if (full.contains(uv)) landed.push_back({uv, mean3(p.power)});
    }
    const std::optional<PowerWindow> window = powerWindow(landed, kWindowQuantile, kWindowScale, kMinWindow_m);
    if (!window) throw Error(path + ": environment (" + r.name + "): no caustic light lands on this receiver");
    c = window->centre;
    w = h = window->side_m;
  }
  // Clip to the receiver.
  const double u0 = std::max(c.x - 0.5 * w, -0.5 * full.width_m), u1 = std::min(c.x + 0.5 * w, 0.5 * full.width_m);
  const double v0 = std::max(c.y - 0.5 * h, -0.5 * full.height_m), v1 = std::min(c.y + 0.5 * h, 0.5 * full.height_m);
  if (!(u1 > u0) || !(v1 > v0)) usageError("caustic", "--window: it lies outside the receiver \"" + r.name + "\"");
  r.rect.centre = full.toWorld(Vec2(0.5 * (u0 + u1), 0.5 * (v0 + v1)));
  r.rect.width_m = u1 - u0;
  r.rect.height_m = v1 - v0;
}

const std::vector<Rgb> kHeat = {
    {0, 0, 0}, {0.33, 0.06, 0.42}, {0.73, 0.2, 0.33}, {0.98, 0.55, 0.04}, {0.99, 1.0, 0.64}};
Rgb heat(double t) {
  t = std::clamp(t, 0.0, 1.0) * double(kHeat.size() - 1);
  const size_t i = std::min(size_t(t), kHeat.size() - 2);
  const double f = t - double(i);
  const Rgb& a = kHeat[i];
  const Rgb& b = kHeat[i + 1];
  return {a.r + (b.r - a.r) * f, a.g + (b.g - a.g) * f, a.b + (b.b - a.b) * f};
}

// The false-colour map: scalar irradiance on a linear scale from 0 to the peak, +v up, axes in mm about the
// window's centre, a colour bar in W/m^2, the peak marked.
Sketch heatMap(const CausticResult& res, const SpotMetrics& s, const std::string& receiver) {
  const ReceiverRect& r = res.grid.rect;
  Sketch k;
  k.width = 760;
  k.height = 640;
  const double left = 90, top = 70, side = 480;
  const double scale = side / std::max(r.width_m, r.height_m);  // px per metre
  const double pw = r.width_m * scale, ph = r.height_m * scale;
  const double cw = pw / r.cells_u, ch = ph / r.cells_v;
  const double peak = std::max(s.peak_irradiance, 1e-300);
  k.rects.push_back({left, top, left + pw, top + ph, kBlack});
  for (int j = 0; j < r.cells_v; ++j)
    for (int i = 0; i < r.cells_u; ++i) {
      const double e = res.grid.scalar(i, j);
      if (!(e > 0)) continue;
      const double y0 = top + (r.cells_v - 1 - j) * ch;
      k.rects.push_back({left + i * cw, y0, left + (i + 1) * cw, y0 + ch, heat(e / peak)});
    }
  k.texts.push_back({k.width / 2.0, 26, "caustic irradiance on " + receiver, 17, 1, kBlack});
  k.texts.push_back({k.width / 2.0, 46,
                     sfmt("peak %.4g W/m^2 at (%.2f, %.2f) mm; %lld photons, %lld on the map", s.peak_irradiance,
                          1e3 * s.peak_uv_m.x, 1e3 * s.peak_uv_m.y, res.emitted, res.deposited),
                     12, 1, kDark});
  // Axes: mm from the window's centre.
  const double b = top + ph;
  k.lines.push_back(
      {{Vec2(left, top), Vec2(left + pw, top), Vec2(left + pw, b), Vec2(left, b), Vec2(left, top)}, kBlack, 1});
  for (int t = 0; t <= 4; ++t) {
    const double x = left + pw * t / 4, y = top + ph * t / 4;
    k.lines.push_back({{Vec2(x, b), Vec2(x, b + 5)}, kBlack, 1});
    k.texts.push_back({x, b + 18, fmt("%.1f", 1e3 * r.width_m * (t / 4.0 - 0.5)), 11, 1, kBlack});
    k.lines.push_back({{Vec2(left - 5, y), Vec2(left, y)}, kBlack, 1});
    k.texts.push_back({left - 8, y + 4, fmt("%.1f", 1e3 * r.height_m * (0.5 - t / 4.0)), 11, 2, kBlack});
  }
  k.texts.push_back({left + pw / 2, b + 38, "u (mm from the window centre)", 12, 1, kBlack});
  k.texts.push_back({left - 8, top - 8, "v (mm)", 12, 0, kBlack});
  // The peak: a cross in the window's coordinates.
  const double window_u0 = -0.5 * r.width_m, window_v1 = 0.5 * r.height_m;
  const Vec2 peak_local = r.toReceiver(s.peak_world);
  const Vec2 px(left + (peak_local.x - window_u0) * scale, top + (window_v1 - peak_local.y) * scale);
  const Rgb cyan{0.2, 0.9, 1.0};
  k.lines.push_back({{px - Vec2(8, 0), px + Vec2(8, 0)}, cyan, 1.5});
  k.lines.push_back({{px - Vec2(0, 8), px + Vec2(0, 8)}, cyan, 1.5});
  // Colour bar.
  const double bx = left + side + 40, bw = 22;
  constexpr int kSteps = 64;
  for (int t = 0; t < kSteps; ++t) {
    const double y1 = top + side * (1 - double(t) / kSteps), y0 = top + side * (1 - double(t + 1) / kSteps);
    k.rects.push_back({bx, y0, bx + bw, y1, heat((t + 0.5) / kSteps)});
  }
  k.lines.push_back(
      {{Vec2(bx, top), Vec2(bx + bw, top), Vec2(bx + bw, top + side), Vec2(bx, top + side), Vec2(bx, top)}, kBlack, 1});
  for (int t = 0; t <= 4; ++t) {
    const double y = top + side * (1 - t / 4.0);
    k.texts.push_back({bx + bw + 6, y + 4, fmt("%.3g", peak * t / 4.0), 11, 0, kBlack});
  }
  k.texts.push_back({bx + bw / 2, top - 8, "W/m^2", 12, 1, kBlack});
  return k;
}

// The irradiance in colour, normalised to the brightest channel of the brightest cell (row 0 at +v).
std::vector<Vec3> colourPicture(const IrradianceGrid& g) {
  double top = 0;
  for (const Vec3& e : g.irradiance) top = std::max({top, e.x, e.y, e.z});
  std::vector<Vec3> px(g.irradiance.size());
  for (int j = 0; j < g.rect.cells_v; ++j)
    for (int i = 0; i < g.rect.cells_u; ++i)
      px[size_t(g.rect.cells_v - 1 - j) * size_t(g.rect.cells_u) + size_t(i)] =
          top > 0 ? g.irradiance[g.index(i, j)] / top : Vec3(0);
  return px;
}

std::string gridCsv(const CausticResult& res) {
  const IrradianceGrid& g = res.grid;
  std::string s = "i,j,u_m,v_m,x_m,y_m,z_m,irradiance_r,irradiance_g,irradiance_b,irradiance,stderr\n";
  for (int j = 0; j < g.rect.cells_v; ++j)
    for (int i = 0; i < g.rect.cells_u; ++i) {
      const Vec2 uv = g.rect.cellCentre(i, j);
      const Vec3 p = g.rect.toWorld(uv);
      const Vec3& e = g.irradiance[g.index(i, j)];
      s += sfmt("%d,%d,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.6g\n", i, j, uv.x, uv.y, p.x, p.y, p.z, e.x, e.y,
                e.z, g.scalar(i, j), std::sqrt(g.variance[g.index(i, j)]));
    }
  return s;
}

json resultJson(const std::string& scene_path, const Scene& scene, const Receiver& rec, const ReceiverRect& full,
                const CausticOptions& o, const PhotonBundle& b, const CausticResult& res, const SpotMetrics& s) {
  json j;
  j["scene"] = scene_path;
  j["receiver"] = {{"name", rec.name},
                   {"curved", rec.curved},
                   {"centre", vec3(full.centre)},
                   {"u_axis", vec3(full.u_axis)},
                   {"v_axis", vec3(full.v_axis)},
                   {"size_m", {full.width_m, full.height_m}},
                   {"window",
                    {{"centre_uv_m", vec2(full.toReceiver(rec.rect.centre))},
                     {"size_m", {rec.rect.width_m, rec.rect.height_m}},
                     {"cells", {rec.rect.cells_u, rec.rect.cells_v}},
                     {"cell_m", {rec.rect.cellWidth(), rec.rect.cellHeight()}}}}};
  j["method"] = {{"photons_per_side", o.photons_per_side},
                 {"wavelength_samples", b.samples_per_photon},
                 {"dispersion", nameOf(o.dispersion)},
                 {"seed", o.seed},
                 {"max_depth", o.max_depth},
                 {"kernel", rec.curved ? "tent (bilinear) one cell wide over the receiver's best-fit plane; irradiance "
                                         "per unit area of the curved surface (each photon weighed by cos between "
                                         "the surface's normal and the plane's)"
                                       : "tent (bilinear) one cell wide; irradiance per unit area of the receiver"},
                 {"paths", "light -> mirrors/lenses (specular only) -> receiver; direct light not included"}};
  j["photons"] = {{"emitted", b.emitted},
                  {"entered_elements", b.entered},
                  {"absorbed", b.absorbed},
                  {"left_elements", b.photons.size()},
                  {"on_window", res.deposited}};
  j["power_w"] = {{"meaning", "scene light units: a directional light's intensity x colour is its irradiance (W/m^2)"},
                  {"entering_elements", mean3(b.entering_power)},
                  {"leaving_elements", mean3(b.leaving_power)},
                  {"on_window", mean3(res.landed_power)},
                  {"on_grid", mean3(res.grid.power())},
                  {"on_grid_rgb", vec3(res.grid.power())}};
  if (rec.curved)
    j["power_w"]["on_grid_meaning"] = "sum of irradiance x cell area of the plane; the curved surface over a cell is "
                                      "larger (cell area / cos), so this is under the surface's power (on_window)";
  j["peak"] = {{"irradiance_w_m2", s.peak_irradiance},
               {"uv_m", vec2(full.toReceiver(s.peak_world))},
               {"world", vec3(s.peak_world)},
               {"relative_stderr", res.peak_rel_stderr}};
  // The concentration against the strongest directional light's own irradiance (a burning glass's figure).
  double sun = 0;
  for (const Light& l : scene.lights)
    if (l.type == Light::Type::Directional) sun = std::max(sun, mean3(l.radiance));
  if (sun > 0) j["peak"]["concentration"] = s.peak_irradiance / sun;
  j["spot"] = {{"fraction_of_peak", kSpotFraction},
               {"cells", s.spot_cells},
               {"area_m2", s.spot_area_m2},
               {"power_w", s.spot_power},
               {"centroid_uv_m", vec2(full.toReceiver(rec.rect.toWorld(s.centroid_uv_m)))},
               {"relative_stderr", res.spot_rel_stderr}};
  j["notes"] = b.notes;
  j["raster_modes"] = "this is the reference; the raster modes draw caustics for lights with \"caustics\": true "
                      "(pvrr compare compares their maps with this light tracer)";
  j["elapsed_ms"] = b.elapsed_ms;
  return j;
}

}  // namespace

int cmdCaustic(const std::vector<std::string>& argv) {
  Args a("caustic", argv, {"receiver", "window", "cells", "photons", "seed", "element", "out", "set"}, {}, {"set"});
  if (a.positional().size() != 1) usageError("caustic", "expected one SCENE");
  const auto out = a.get("out");
  if (!out) usageError("caustic", "--out DIR is required");
  const std::string scene_path = a.positional()[0];
  CausticOptions o;
  o.photons_per_side = a.getInt("photons", kDefaultPhotonsPerSide, 1);
  // Photons are kept until deposited (about 100 bytes each): 2048^2 x 3 samples is about 1.3 GB.
  if (o.photons_per_side > 2048) usageError("caustic", "--photons: expected at most 2048 (per side)");
  o.seed = uint64_t(a.getInt("seed", 1, 0));
  const int cells = a.getInt("cells", kDefaultCells, 4);
  if (cells > 2000) usageError("caustic", "--cells: expected at most 2000");

  LoadedScene ls = loadScene(scene_path, a.all("set"));
  const Scene& scene = ls.scene;
  o.dispersion = scene.render.dispersion;
  o.spectral_samples = scene.render.spectral_samples;
  if (scene.elements.empty()) throw Error(scene_path + ": elements: none; a caustic needs a mirror or a lens");
  if (a.has("element")) o.element = chooseElement(scene, a, scene_path, ElementType::Mirror, "none", "elements");
  RayScene rays(scene);
  const PhotonBundle b = shootCausticPhotons(rays, o);
  if (b.photons.empty())
    throw Error(scene_path + ": lights: no photon from a directional or point light leaves an element (" +
                std::to_string(b.emitted) + " shot, " + std::to_string(b.entered) + " met an element, " +
                std::to_string(b.absorbed) + " absorbed)");
  Receiver rec = chooseReceiver(ls.desc, scene, b, a, scene_path);
  const ReceiverRect full = rec.rect;
  chooseWindow(rec, b, a, scene_path);
  const double cell = std::max(rec.rect.width_m, rec.rect.height_m) / cells;
  rec.rect.cells_u = std::max(1, int(std::lround(rec.rect.width_m / cell)));
  rec.rect.cells_v = std::max(1, int(std::lround(rec.rect.height_m / cell)));
  DepositOptions dep;
  dep.mesh = rec.index;
  dep.slab_m = kSlab_m;
  dep.height_field = rec.curved;
  dep.sheet = rec.sheet;
  const CausticResult res = depositPhotons(b, rec.rect, dep);
  const SpotMetrics s = spotMetrics(res.grid);
  if (!s.found) throw Error(scene_path + ": environment (" + rec.name + "): no caustic light inside the window");

  const json j = resultJson(scene_path, scene, rec, full, o, b, res, s);
  const std::string dir = *out;
  // All or nothing: the command runs inside cli.cpp's OutputTransaction.
  writePng((fs::path(dir) / "caustic.png").string(), heatMap(res, s, rec.name));
  writeLinearPng((fs::path(dir) / "caustic-colour.png").string(), rec.rect.cells_u, rec.rect.cells_v,
                 colourPicture(res.grid));
  writeFileAtomic((fs::path(dir) / "caustic.csv").string(), gridCsv(res));
  writeFileAtomic((fs::path(dir) / "caustic.json").string(), j.dump(2) + "\n");
  std::printf(
      "%s: caustic on %s: peak %.4g W/m^2 at (%.4f, %.4f, %.4f) m, %.4g W on the window; %lld photons "
      "(%d wavelength sample%s), %.0f ms -> %s\n",
      scene_path.c_str(), rec.name.c_str(), s.peak_irradiance, s.peak_world.x, s.peak_world.y, s.peak_world.z,
      mean3(res.landed_power), b.emitted, b.samples_per_photon, b.samples_per_photon == 1 ? "" : "s", b.elapsed_ms,
      dir.c_str());
  return 0;
}

}  // namespace pvrr::app
