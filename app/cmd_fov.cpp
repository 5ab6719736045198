// pvrr fov: a mirror's field of view on the road, checked against regulation zones (issue 21; the computation
// and its conventions: pvrr/analysis/fov.h; the zones: models/regulations/*.json, docs/fov.md).
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "app/args.h"
#include "app/commands.h"
#include "app/fov_plot.h"
#include "app/fov_regulation.h"
#include "app/progress.h"
#include "pvrr/analysis/fov.h"
#include "pvrr/base/atomic_file.h"
#include "pvrr/base/error.h"
#include "pvrr/base/format.h"

namespace fs = std::filesystem;
using nlohmann::json;

namespace pvrr::app {

namespace {

// A plane mirror's principal magnifications are 1 to rounding (the test measures 1e-6 at most); a mirror
// within this of 1 everywhere is of unit magnification.
constexpr double kUnitMagnificationTol = 1e-4;

json num(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }

json polygonJson(const std::vector<Vec2>& p) {
  json a = json::array();
  for (const Vec2& v : p) a.push_back({v.x, v.y});
  return a;
}

const char* eyesName(FovZone::Eyes e) {
  switch (e) {
    case FovZone::Eyes::Either:
      return "either";
    case FovZone::Eyes::Both:
      return "both";
    case FovZone::Eyes::Left:
      return "left";
    case FovZone::Eyes::Right:
      return "right";
  }
  return "";
}

// Each eye's footprint (polygon and ray counts) and the union of the eyes' footprints: its outer loops (and any
// holes, clockwise).
json footprintJson(const std::vector<EyeFootprint>& feet) {
  json fp = json::object();
  for (const EyeFootprint& f : feet)
    fp[f.eye] = {{"polygon", polygonJson(f.outline)},
                 {"rays", f.fate.size()},
                 {"road", f.count(RayFate::Road)},
                 {"horizon", f.count(RayFate::Horizon)},
                 {"obstructed", f.count(RayFate::Obstructed)},
                 {"back", f.count(RayFate::Back)},
                 {"road_reach_m", f.reach_m},
                 {"sees_horizon", f.sees_horizon}};
  json un = json::array();
  if (feet.size() == 2)
    for (const std::vector<Vec2>& loop : polygonUnion(feet[0].outline, feet[1].outline))
      un.push_back(polygonJson(loop));
  else
    un.push_back(polygonJson(feet[0].outline));
  fp["union"] = {{"polygons", un}};
  return fp;
}

}  // namespace

int cmdFov(const std::vector<std::string>& argv) {
  Args a("fov", argv, {"element", "regulation", "eyes", "samples", "out", "set"}, {}, {"set", "regulation"});
  if (a.positional().size() != 1) usageError("fov", "expected one SCENE");
  const auto out = a.get("out");
  if (!out) usageError("fov", "--out DIR is required");
  const std::string eyes_opt = a.get("eyes", "both");
  if (eyes_opt != "both" && eyes_opt != "left" && eyes_opt != "right")
    usageError("fov", "--eyes: expected both, left or right, got \"" + eyes_opt + "\"");
  FovOptions options;
  options.samples = a.getInt("samples", options.samples, 2);
  if (options.samples > 1001) usageError("fov", "--samples: expected at most 1001");
  const std::string scene_path = a.positional()[0];

  LoadedScene ls = loadScene(scene_path, a.all("set"));
  if (!ls.desc.vehicle)
    throw Error(scene_path + ": vehicle: missing; pvrr fov needs the vehicle frame (docs/scene-format.md \"vehicle\")");
  const VehicleDesc& vehicle = *ls.desc.vehicle;
  const Scene& scene = ls.scene;
  const int index = chooseElement(scene, a, scene_path, ElementType::Mirror, "no mirror", "mirrors");
  const Element& el = scene.elements[size_t(index)];
  const std::string el_path = scene_path + ": elements[" + std::to_string(index) + "] (" + el.name + ")";
  if (el.type != ElementType::Mirror) throw Error(el_path + ": pvrr fov maps a mirror, not a lens");

  // Regulations: --regulation, else the scene's vehicle.regulations.
  std::vector<std::string> ids = a.all("regulation");
  if (ids.empty()) ids = vehicle.regulations;
  const std::vector<std::string> folders = {(fs::path(scene_path).parent_path() / "regulations").string(),
                                            "models/regulations"};
  std::vector<Regulation> regs;
  for (const std::string& id : ids) regs.push_back(loadRegulation(id, folders));

  const VehicleFrame frame(vehicle);
  RayScene rays(scene);
  Progress progress("fov", 3.0);  // the surface's figures, then each eye's footprint
  const SurfaceFigures figures = surfaceFigures(rays, index, 0.5 * (vehicle.eye_left + vehicle.eye_right), options);
  progress.update(1);
  std::vector<EyeFootprint> feet;
  if (eyes_opt != "right") feet.push_back(traceFootprint(rays, index, frame, vehicle.eye_left, "left", options));
  progress.update(2);
  if (eyes_opt != "left") feet.push_back(traceFootprint(rays, index, frame, vehicle.eye_right, "right", options));
  progress.finish();
  std::vector<const EyeFootprint*> eyes;
  int road = 0;
  for (const EyeFootprint& f : feet) {
    eyes.push_back(&f);
    road += f.count(RayFate::Road);
  }
  if (road == 0) {
    const EyeFootprint& f = feet.front();
    throw Error(el_path + ": the mirror sees no road from the " + f.eye + " ocular point (of " +
                std::to_string(f.fate.size()) + " rays: " + std::to_string(f.count(RayFate::Horizon)) +
                " above the horizon, " + std::to_string(f.count(RayFate::Obstructed)) + " obstructed, " +
                std::to_string(f.count(RayFate::Back)) + " on its back)");
  }

  json j;
  j["scene"] = scene_path;
  j["element"] = el.name;
  j["eyes"] = json::array();
  for (const EyeFootprint& f : feet) j["eyes"].push_back(f.eye);
  j["conventions"] = {
      {"frame",
       "vehicle frame: metres, origin on the road below the midpoint of the ocular points, x forward, y to "
       "the left, z up"},
      {"footprint",
       "the image on the road of the mirror's boundary, counter-clockwise; rays beyond horizon_m "
       "(horizontally from the mirror) or above the horizon are placed horizon_m away along their "
       "horizontal direction"},
      {"coverage",
       "zone samples uniform across the zone and in the angle of depression from the ocular points; "
       "a zone 'to the horizon' is checked out to zone_horizon_m behind the ocular points"}};
  j["horizon_m"] = options.horizon_m;
  j["zone_horizon_m"] = options.zone_horizon_m;
  j["samples"] = options.samples;
  j["footprint"] = footprintJson(feet);
  j["zones"] = json::array();
  j["regulations"] = json::array();
  std::vector<ZoneResult> results;
  results.reserve(64);
  std::vector<FovPlotZone> plot_zones;
  bool all_pass = true;
  std::string summary;
  for (const Regulation& r : regs) {
    json mirror = json::array();
    for (const MirrorRequirement& q : r.mirror) {
      json req = {{"name", q.name},     {"value", q.value},       {"meaning", q.meaning},
                  {"source", q.source}, {"verified", q.verified}, {"checked", false}};
      // The requirements the surface figures answer; the others are listed, not checked.
      if (q.name == "min_mean_radius_m") {
        req["checked"] = true;
        req["pass"] = figures.mean_radius_m >= q.value;
      } else if (q.name == "unit_magnification") {
        req["checked"] = true;
        req["pass"] = std::abs(figures.magnification_min - 1) <= kUnitMagnificationTol &&
                      std::abs(figures.magnification_max - 1) <= kUnitMagnificationTol;
      }
      if (req["checked"].get<bool>()) {
        all_pass = all_pass && req["pass"].get<bool>();
        summary += r.id + " / mirror " + q.name + ": " + (req["pass"].get<bool>() ? "pass" : "FAIL") +
                   (q.verified ? "" : " (value unverified)") + "\n";
      }
      mirror.push_back(req);
    }
    j["regulations"].push_back({{"id", r.id},
                                {"title", r.title},
                                {"document", r.document},
                                {"file", r.path},
                                {"verified", r.verified},
                                {"mirror_requirements", mirror}});
    for (const FovZone& z : r.zones) {
      results.push_back(evaluateZone(z, frame, eyes, options));
      const ZoneResult& zr = results.back();
      plot_zones.push_back({&z, &zr});
      all_pass = all_pass && zr.pass;
      j["zones"].push_back({{"regulation", r.id},
                            {"zone", z.name},
                            {"eyes", eyesName(z.eyes)},
                            {"covered_fraction", zr.covered_fraction},
                            {"obstructed_fraction", zr.obstructed_fraction},
                            {"allowed_obstructed_fraction", z.allowed_obstructed_fraction},
                            {"samples", zr.samples},
                            {"pass", zr.pass},
                            {"verified", z.verified},
                            {"polygon", polygonJson(zr.polygon)}});
      summary += r.id + " / " + z.name + ": covered " + fmt("%.1f", 100 * zr.covered_fraction) + " %, obstructed " +
                 fmt("%.1f", 100 * zr.obstructed_fraction) + " %: " + (zr.pass ? "pass" : "FAIL") +
                 (z.verified ? "" : " (values unverified)") + "\n";
    }
  }
  j["pass"] = regs.empty() ? json(nullptr) : json(all_pass);
  j["surface"] = {{"mean_radius_m", num(figures.mean_radius_m)},
                  {"principal_radius_min_m", num(figures.principal_radius_min_m)},
                  {"principal_radius_max_m", num(figures.principal_radius_max_m)},
                  {"magnification_min", num(figures.magnification_min)},
                  {"magnification_max", num(figures.magnification_max)},
                  {"eye", "the midpoint of the ocular points"},
                  {"definitions",
                   "radii 1/k (> 0 convex, null where flat); mean_radius_m: the average over the grid of each "
                   "sample's (r1 + r2) / 2; magnification: principal angular magnifications of distant objects "
                   "relative to a plane mirror (pvrr/analysis/fov.h)"}};

  writeFileAtomic((fs::path(*out) / "fov.json").string(), j.dump(2) + "\n");
  std::string title = el.name + " field of view";
  for (const Regulation& r : regs) title += (&r == &regs.front() ? ": " : ", ") + r.title;
  const bool driver_side = regs.empty() || regs.front().driver_side;
  const std::vector<std::string> plots = writeFovPlot(*out, title, frame, driver_side, eyes, plot_zones, options);
  const std::vector<std::string> mag = writeMagnificationPlot(*out, el.name + " magnification", figures);
  std::printf("%s\n", (fs::path(*out) / "fov.json").string().c_str());
  for (const std::string& p : plots) std::printf("%s\n", p.c_str());
  for (const std::string& p : mag) std::printf("%s\n", p.c_str());
  std::printf("%s", summary.c_str());
  return 0;
}

}  // namespace pvrr::app
