// pvrr fov: a mirror's field of view on the road, checked against regulation zones (issue 21; the computation
// and its conventions: pvrr/analysis/fov.h; the zones: models/regulations/*.json, docs/fov.md).
#include <algorithm>
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
#include "app/view/save_view.h"
#include "pvrr/analysis/fov.h"
#include "pvrr/analysis/fov_aim.h"
#include "pvrr/analysis/fov_eyes.h"
#include "pvrr/analysis/fov_radius.h"
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
// The aim search's sampling (each of its ~200 evaluations traces both eyes): 41 x 41 rays and 40 x 12 zone samples
// place a footprint's edge to about 2.5 % of the mirror, ample for a search on a 0.5 deg grid; its answer is then
// checked at the command's own sampling.
constexpr int kAimSamples = 41, kAimZoneSamplesX = 40, kAimZoneSamplesY = 12;

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

// The union of several footprints' outlines as "polygons" (one loop), or null and why.
json unionJson(const std::vector<const EyeFootprint*>& feet) {
  std::vector<std::vector<Vec2>> polys;
  for (const EyeFootprint* f : feet) polys.push_back(f->outline);
  const std::vector<Vec2> u = unionOfPolygons(polys);
  if (u.empty())
    return {{"polygons", nullptr},
            {"note",
             "the union is not one simple loop (it has a hole or disjoint parts): not represented; the zones' "
             "coverage uses every sample's footprint (footprint.samples)"}};
  return {{"polygons", json::array({polygonJson(u)})}};
}

// An eye ellipse's footprints (--eyes ellipse): per eye the union over its samples and the ray counts summed, each
// sample's footprint, and the union over every sample.
json ellipseFootprintJson(const std::vector<EyeFootprint>& feet, const VehicleFrame& frame) {
  json fp = json::object();
  json samples = json::array();
  for (const char* eye : {"left", "right"}) {
    std::vector<const EyeFootprint*> mine;
    int road = 0, horizon = 0, obstructed = 0, back = 0;
    double reach = 0;
    bool sees_horizon = false;
    for (const EyeFootprint& f : feet)
      if (f.eye == eye) {
        mine.push_back(&f);
        road += f.count(RayFate::Road);
        horizon += f.count(RayFate::Horizon);
        obstructed += f.count(RayFate::Obstructed);
        back += f.count(RayFate::Back);
        reach = std::max(reach, f.reach_m);
        sees_horizon = sees_horizon || f.sees_horizon;
        samples.push_back({{"eye", f.eye},
                           {"position", {f.eye_vehicle.x, f.eye_vehicle.y, f.eye_vehicle.z}},
                           {"polygon", polygonJson(f.outline)},
                           {"outline_cut_area_m2", f.outline_cut_area_m2}});
      }
    if (mine.empty()) continue;
    json u = unionJson(mine);
    fp[eye] = {{"polygon", u["polygons"].is_null() ? json(nullptr) : u["polygons"][0]},
               {"samples", mine.size()},
               {"road", road},
               {"horizon", horizon},
               {"obstructed", obstructed},
               {"back", back},
               {"road_reach_m", reach},
               {"sees_horizon", sees_horizon}};
  }
  std::vector<const EyeFootprint*> all;
  for (const EyeFootprint& f : feet) all.push_back(&f);
  fp["union"] = unionJson(all);
  fp["samples"] = samples;
  const auto& e = *frame.desc().eye_ellipse;
  fp["eye_ellipse"] = {{"axes_m", {e.axes_m.x, e.axes_m.y, e.axes_m.z}},
                       {"tilt_deg", e.tilt_deg},
                       {"definition",
                        "one ellipsoid per eye centred on its ocular point, full axes along the vehicle's forward, "
                        "left and up, sampled at its centre, its 6 axis ends and 8 octant points "
                        "(pvrr/analysis/fov_eyes.h); each eye's polygon is the union over its samples"}};
  return fp;
}

// Each eye's footprint (polygon and ray counts) and the union of the eyes' footprints: its outer loops (and any
// holes, clockwise).
json footprintJson(const std::vector<EyeFootprint>& feet, const VehicleFrame& frame, bool ellipse) {
  if (ellipse) return ellipseFootprintJson(feet, frame);
  json fp = json::object();
  for (const EyeFootprint& f : feet)
    fp[f.eye] = {{"polygon", polygonJson(f.outline)},
                 {"outline_cut_area_m2", f.outline_cut_area_m2},
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

// The footprints of the eyes asked for and every regulation zone's coverage, for one adjustment of the mirror.
struct FovRun {
  std::vector<EyeFootprint> feet;
  std::vector<const EyeFootprint*> eyes;  // into feet
  std::vector<ZoneResult> results;        // the zones of every regulation, in order
  bool pass = true;                       // every zone
};

FovRun runFov(const Scene& scene, int index, const VehicleFrame& frame, const std::string& eyes_opt,
              const std::vector<Regulation>& regs, const FovOptions& options) {
  FovRun run;
  const RayScene rays(scene);
  const VehicleDesc& v = frame.desc();
  if (eyes_opt == "ellipse") {
    for (const EyeSample& e : eyeEllipseSamples(frame, *v.eye_ellipse))
      run.feet.push_back(traceFootprint(rays, index, frame, e.world, e.eye, options));
  } else {
    if (eyes_opt != "right") run.feet.push_back(traceFootprint(rays, index, frame, v.eye_left, "left", options));
    if (eyes_opt != "left") run.feet.push_back(traceFootprint(rays, index, frame, v.eye_right, "right", options));
  }
  for (const EyeFootprint& f : run.feet) run.eyes.push_back(&f);
  for (const Regulation& r : regs)
    for (const FovZone& z : r.zones) {
      run.results.push_back(evaluateZone(z, frame, run.eyes, options));
      run.pass = run.pass && run.results.back().pass;
    }
  return run;
}

json zoneJson(const Regulation& r, const FovZone& z, const ZoneResult& zr) {
  return {{"regulation", r.id},
          {"zone", z.name},
          {"eyes", eyesName(z.eyes)},
          {"covered_fraction", zr.covered_fraction},
          {"obstructed_fraction", zr.obstructed_fraction},
          {"allowed_obstructed_fraction", z.allowed_obstructed_fraction},
          {"samples", zr.samples},
          {"pass", zr.pass},
          {"verified", z.verified},
          {"polygon", polygonJson(zr.polygon)}};
}

std::string zoneLine(const Regulation& r, const FovZone& z, const ZoneResult& zr) {
  return r.id + " / " + z.name + ": covered " + fmt("%.1f", 100 * zr.covered_fraction) + " %, obstructed " +
         fmt("%.1f", 100 * zr.obstructed_fraction) + " %: " + (zr.pass ? "pass" : "FAIL") +
         (z.verified ? "" : " (values unverified)") + "\n";
}

json radiusJson(const Annex7Radius& a) {
  json pts = json::array();
  for (const Annex7Radius::Point& p : a.points)
    pts.push_back({{"square", {p.square.x, p.square.y}},
                   {"r_i_m", num(p.r_along_m)},
                   {"r_i_prime_m", num(p.r_across_m)},
                   {"r_p_m", num(p.r_p_m)}});
  return {{"r_m", num(a.r_m)},
          {"points", pts},
          {"arc", a.arc_along_u ? "u" : "v"},
          {"arc_length_m", a.arc_length_m},
          {"spherometer_half_span_m", a.half_span_m},
          {"max_principal_deviation", a.max_principal_deviation},
          {"max_point_deviation", a.max_point_deviation},
          {"definition",
           "R46 Annex 7: r_i, r'_i the spherometer radii along and across the longer central arc at 1/3, 1/2, 2/3 "
           "of it; r_p = (r_i + r'_i) / 2; r = (r_p1 + r_p2 + r_p3) / 3 (the points, r_p and r as Directive "
           "2003/97/EC's text has them; the spherometer's span recalled, unverified: pvrr/analysis/fov_radius.h)"}};
}

// The ocular points in the vehicle frame, and where they come from.
json ocularJson(const VehicleFrame& frame) {
  const Vec3 l = frame.eye(true), r = frame.eye(false);
  json o = {{"left", {l.x, l.y, l.z}}, {"right", {r.x, r.y, r.z}}, {"from", "vehicle.ocular_points"}};
  if (const auto& seat = frame.desc().seat_reference) {
    const Vec3 p = frame.toVehicle(seat->point);
    o["from"] = "vehicle.seat_reference";
    o["seat_reference"] = {{"point", {p.x, p.y, p.z}},
                           {"eye_height_m", seat->eye_height_m},
                           {"eye_separation_m", seat->eye_separation_m},
                           {"source",
                            "defaults: UN R46 para. 12.1, two points 65 mm apart and 635 mm vertically above point R "
                            "(recalled, not confirmed in the primary text)"},
                           {"verified", false}};
  }
  return o;
}

// "[x, y, z]" with round-trip precision, for a --set override.
std::string vecText(const Vec3& v) {
  return "[" + fmt("%.17g", v.x) + ", " + fmt("%.17g", v.y) + ", " + fmt("%.17g", v.z) + "]";
}

// The --set overrides that give element `index` the pose `m` (world metres -> the file's units).
std::vector<std::string> poseOverrides(int index, const Mat4& m, double unit_m) {
  const std::string e = "elements[" + std::to_string(index) + "].pose.";
  const Vec3 position = Vec3(m[3]) / unit_m, normal = glm::normalize(Vec3(m[2])), up = glm::normalize(Vec3(m[1]));
  return {e + "position=" + vecText(position), e + "normal=" + vecText(normal), e + "up=" + vecText(up)};
}

}  // namespace

// --aim: the search (pvrr/analysis/fov_aim.h), the aimed scene written, loaded and built afresh and checked at the
// command's own sampling; fov.json's "aim", DIR/aimed.json and the aimed plan view DIR/aimed/fov.png and .svg.
struct AimReport {
  json aim;
  std::string summary;
  std::vector<std::string> written;
};

AimReport runAim(const std::string& scene_path, const std::vector<std::string>& set_overrides, const LoadedScene& ls,
                 int index, const VehicleFrame& frame, const std::string& eyes_opt, const std::vector<Regulation>& regs,
                 const FovOptions& options, const FovRun& before, double aim_range_deg, const std::string& out) {
  AimReport res;
  const Scene& scene = ls.scene;
  const std::string& name = scene.elements[size_t(index)].name;
  AimOptions ao;
  ao.fov = options;
  ao.fov.samples = std::min(options.samples, kAimSamples);
  ao.fov.zone_samples_x = kAimZoneSamplesX;
  ao.fov.zone_samples_y = kAimZoneSamplesY;
  ao.range_deg = aim_range_deg;
  ao.left_eye = eyes_opt != "right";
  ao.right_eye = eyes_opt != "left";
  // --eyes ellipse: aimed for every sample of the eye ellipse (an eye sees a point when any of its samples does).
  if (eyes_opt == "ellipse") ao.eye_samples = eyeEllipseSamples(frame, *ls.desc.vehicle->eye_ellipse);
  const ElementDesc& ed = ls.desc.elements[size_t(index)];
  if (ed.pivot) {
    if (ed.attached_to_observer)
      throw Error(scene_path + ": elements[" + std::to_string(index) +
                  "].pivot: pvrr fov --aim turns a mirror fixed "
                  "to the vehicle, not one attached to the observer");
    ao.pivot = *ed.pivot;
  }
  const std::string pivot_name = ed.pivot ? "pivot" : "vertex";
  std::vector<FovZone> zones;
  for (const Regulation& r : regs) zones.insert(zones.end(), r.zones.begin(), r.zones.end());
  const AimResult ar = aimMirror(scene, index, frame, zones, ao);
  // The answer checked the way the command checks any scene: the aimed file built afresh, evaluated at the
  // command's own sampling.
  std::vector<std::string> overrides = set_overrides;
  for (const std::string& o : poseOverrides(index, ar.local_to_world, ls.desc.unit_m)) overrides.push_back(o);
  const LoadedScene aimed = loadScene(scene_path, overrides);
  const FovRun after = runFov(aimed.scene, index, frame, eyes_opt, regs, options);
  json zones_after = json::array();
  std::vector<FovPlotZone> plot_after;
  size_t zi = 0;
  std::string aim_summary;
  for (const Regulation& r : regs)
    for (const FovZone& z : r.zones) {
      const ZoneResult& zr = after.results[zi++];
      plot_after.push_back({&z, &zr});
      zones_after.push_back(zoneJson(r, z, zr));
      aim_summary += "  aimed " + zoneLine(r, z, zr);
    }
  double worst = 1;
  for (size_t k = 0; k < zones.size(); ++k)
    worst = std::min(worst, after.results[k].covered_fraction +
                                std::min(after.results[k].obstructed_fraction, zones[k].allowed_obstructed_fraction));
  res.aim = {{"pivot", {ar.pivot.x, ar.pivot.y, ar.pivot.z}},
             {"pivot_from", ed.pivot ? "the element's pivot" : "the element's vertex (pose.position)"},
             {"yaw_axis", {ar.yaw_axis.x, ar.yaw_axis.y, ar.yaw_axis.z}},
             {"pitch_axis", {ar.pitch_axis.x, ar.pitch_axis.y, ar.pitch_axis.z}},
             {"yaw_deg", ar.angles.yaw_rad * 180 / kPi},
             {"pitch_deg", ar.angles.pitch_rad * 180 / kPi},
             {"range_deg", aim_range_deg},
             {"pass_before", before.pass},
             {"pass", after.pass},
             {"search_pass", ar.after.pass},
             {"score", worst},
             {"shortfall", 1 - worst},
             {"margin_deg", ar.margin_deg},
             {"evaluations", ar.evaluations},
             {"search_samples", ao.fov.samples},
             {"polish", ar.polish_report},
             {"zones", zones_after},
             {"scene", (fs::path(out) / "aimed.json").string()},
             {"definitions",
              "rotation about the pivot (the element's pivot, default its vertex): yaw about the vehicle's up axis "
              "after pitch about "
              "the horizontal axis in the mirror's plane; score: the smallest over the zones of the covered fraction "
              "plus the obstructed fraction up to its allowance (1: every zone passes); zones: the aimed scene "
              "checked afresh at the command's sampling (pvrr/analysis/fov_aim.h)"}};
  res.summary +=
      "aim: yaw " + fmt("%.2f", ar.angles.yaw_rad * 180 / kPi) + " deg, pitch " +
      fmt("%.2f", ar.angles.pitch_rad * 180 / kPi) + " deg about " + name + "'s " + pivot_name + ": " +
      (after.pass
           ? "every zone passes"
           : "no adjustment within " + fmt("%.0f", aim_range_deg) + " deg meets every zone; the best falls short by " +
                 fmt("%.1f", 100 * (1 - worst)) + " % of a zone") +
      (ar.after.pass != after.pass ? " (the search's coarser sampling said otherwise)" : "") + "\n" + aim_summary;
  view::saveView((fs::path(out) / "aimed.json").string(), scene_path, overrides, aimed.scene.observer, ls.desc.unit_m);
  res.written.push_back((fs::path(out) / "aimed.json").string());
  std::string title = name + " aimed (yaw " + fmt("%.2f", ar.angles.yaw_rad * 180 / kPi) + " deg, pitch " +
                      fmt("%.2f", ar.angles.pitch_rad * 180 / kPi) + " deg)";
  const bool driver_side = regs.front().driver_side;
  for (const std::string& p :
       writeFovPlot((fs::path(out) / "aimed").string(), title, frame, driver_side, after.eyes, plot_after, options))
    res.written.push_back(p);
  return res;
}

int cmdFov(const std::vector<std::string>& argv) {
  Args a("fov", argv, {"element", "regulation", "eyes", "samples", "aim-range", "out", "set"}, {"aim"},
         {"set", "regulation"});
  if (a.positional().size() != 1) usageError("fov", "expected one SCENE");
  const auto out = a.get("out");
  if (!out) usageError("fov", "--out DIR is required");
  const std::string eyes_opt = a.get("eyes", "both");
  if (eyes_opt != "both" && eyes_opt != "left" && eyes_opt != "right" && eyes_opt != "ellipse")
    usageError("fov", "--eyes: expected both, left, right or ellipse, got \"" + eyes_opt + "\"");
  FovOptions options;
  options.samples = a.getInt("samples", options.samples, 2);
  if (options.samples > 1001) usageError("fov", "--samples: expected at most 1001");
  const bool aim = a.has("aim");
  const double aim_range_deg = a.getDouble("aim-range", 10);
  if (!(aim_range_deg >= 1 && aim_range_deg <= 45)) usageError("fov", "--aim-range: expected degrees in [1, 45]");
  const std::string scene_path = a.positional()[0];

  LoadedScene ls = loadScene(scene_path, a.all("set"));
  if (!ls.desc.vehicle)
    throw Error(scene_path + ": vehicle: missing; pvrr fov needs the vehicle frame (docs/scene-format.md \"vehicle\")");
  const VehicleDesc& vehicle = *ls.desc.vehicle;
  if (eyes_opt == "ellipse" && !vehicle.eye_ellipse)
    throw Error(scene_path +
                ": vehicle.eye_ellipse: missing; --eyes ellipse samples it (docs/scene-format.md \"vehicle\")");
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
  if (aim && regs.empty()) usageError("fov", "--aim needs a regulation (--regulation ID or vehicle.regulations)");

  const VehicleFrame frame(vehicle);
  Progress progress("fov", 3.0);  // the surface's figures, its Annex 7 radius, then the footprints
  const SurfaceFigures figures =
      surfaceFigures(RayScene(scene), index, 0.5 * (vehicle.eye_left + vehicle.eye_right), options);
  progress.update(1);
  const Annex7Radius annex7 = annex7Radius(el);
  progress.update(2);
  const FovRun run = runFov(scene, index, frame, eyes_opt, regs, options);
  progress.finish();
  int road = 0;
  for (const EyeFootprint& f : run.feet) road += f.count(RayFate::Road);
  if (road == 0) {
    const EyeFootprint& f = run.feet.front();
    throw Error(el_path + ": the mirror sees no road from the " + f.eye + " ocular point (of " +
                std::to_string(f.fate.size()) + " rays: " + std::to_string(f.count(RayFate::Horizon)) +
                " above the horizon, " + std::to_string(f.count(RayFate::Obstructed)) + " obstructed, " +
                std::to_string(f.count(RayFate::Back)) + " on its back)");
  }

  json j;
  j["scene"] = scene_path;
  j["element"] = el.name;
  j["eyes"] = json::array();
  for (const EyeFootprint& f : run.feet)
    if (std::find(j["eyes"].begin(), j["eyes"].end(), f.eye) == j["eyes"].end()) j["eyes"].push_back(f.eye);
  if (eyes_opt == "ellipse") j["eye_samples"] = run.feet.size();
  j["ocular_points"] = ocularJson(frame);
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
  j["footprint"] = footprintJson(run.feet, frame, eyes_opt == "ellipse");
  j["zones"] = json::array();
  j["regulations"] = json::array();
  std::vector<FovPlotZone> plot_zones;
  bool all_pass = run.pass;
  std::string summary;
  size_t zi = 0;
  for (const Regulation& r : regs) {
    json mirror = json::array();
    for (const MirrorRequirement& q : r.mirror) {
      json req = {{"name", q.name},     {"value", q.value},       {"meaning", q.meaning},
                  {"source", q.source}, {"verified", q.verified}, {"checked", false}};
      // The requirements the surface figures answer; the others are listed, not checked.
      if (q.name == "min_mean_radius_m") {
        req["checked"] = true;
        req["measured"] = num(annex7.r_m);
        req["measured_by"] = "R46 Annex 7's three-point mean radius r (surface.annex7)";
        req["pass"] = annex7.r_m >= q.value;
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
      const ZoneResult& zr = run.results[zi++];
      plot_zones.push_back({&z, &zr});
      j["zones"].push_back(zoneJson(r, z, zr));
      summary += zoneLine(r, z, zr);
    }
  }
  j["pass"] = regs.empty() ? json(nullptr) : json(all_pass);
  j["surface"] = {{"mean_radius_m", num(figures.mean_radius_m)},
                  {"principal_radius_min_m", num(figures.principal_radius_min_m)},
                  {"principal_radius_max_m", num(figures.principal_radius_max_m)},
                  {"magnification_min", num(figures.magnification_min)},
                  {"magnification_max", num(figures.magnification_max)},
                  {"annex7", radiusJson(annex7)},
                  {"eye", "the midpoint of the ocular points"},
                  {"definitions",
                   "radii 1/k (> 0 convex, null where flat); mean_radius_m: the average over the grid of each "
                   "sample's (r1 + r2) / 2; annex7.r_m: the regulation's three-point mean radius, used for "
                   "min_mean_radius_m; magnification: principal angular magnifications of distant objects "
                   "relative to a plane mirror (pvrr/analysis/fov.h)"}};
  summary += "mean radius: R46 Annex 7 r = " + (std::isfinite(annex7.r_m) ? fmt("%.4f", annex7.r_m) + " m" : "inf") +
             " (grid mean " +
             (std::isfinite(figures.mean_radius_m) ? fmt("%.4f", figures.mean_radius_m) + " m" : "inf") + ")\n";

  std::vector<std::string> written;
  if (aim) {
    const AimReport ar =
        runAim(scene_path, a.all("set"), ls, index, frame, eyes_opt, regs, options, run, aim_range_deg, *out);
    j["aim"] = ar.aim;
    summary += ar.summary;
    written = ar.written;
  }

  writeFileAtomic((fs::path(*out) / "fov.json").string(), j.dump(2) + "\n");
  std::string title = el.name + " field of view";
  for (const Regulation& r : regs) title += (&r == &regs.front() ? ": " : ", ") + r.title;
  const bool driver_side = regs.empty() || regs.front().driver_side;
  const std::vector<std::string> plots = writeFovPlot(*out, title, frame, driver_side, run.eyes, plot_zones, options);
  const std::vector<std::string> mag = writeMagnificationPlot(*out, el.name + " magnification", figures);
  std::printf("%s\n", (fs::path(*out) / "fov.json").string().c_str());
  for (const std::string& p : plots) std::printf("%s\n", p.c_str());
  for (const std::string& p : mag) std::printf("%s\n", p.c_str());
  for (const std::string& p : written) std::printf("%s\n", p.c_str());
  std::printf("%s", summary.c_str());
  return 0;
}

}  // namespace pvrr::app
