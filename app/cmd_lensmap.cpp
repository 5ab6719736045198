// pvrr lensmap: power, astigmatism, prism, distortion and lateral colour of a spectacle lens as worn
// (issue 27; the computation and its conventions: pvrr/analysis/lensmap.h; docs/lensmap.md).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "app/args.h"
#include "app/commands.h"
#include "app/lensmap_plot.h"
#include "app/progress.h"
#include "pvrr/analysis/lensmap.h"
#include "pvrr/base/error.h"
#include "pvrr/base/format.h"

namespace fs = std::filesystem;
using nlohmann::json;

namespace pvrr::app {

namespace {

std::string full(double v) {
  if (!std::isfinite(v)) return "";
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

// JSON numbers at full precision (nlohmann prints doubles round-trip); null for non-finite values.
json num(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }

const char* kCsvHeader =
    "gaze_x_deg,gaze_y_deg,lens_x_mm,lens_y_mm,sphere_d,cylinder_d,axis_deg,mean_power_d,power_error_d,"
    "unwanted_cylinder_d,prism_h,prism_v,distortion_pct,lateral_colour_arcmin,tangential_d,sagittal_d,"
    "prentice_h,prentice_v,object_x_deg,object_y_deg";

std::string csv(const LensmapResult& r) {
  std::string s = std::string(kCsvHeader) + "\n";
  for (const LensmapPoint& p : r.points) {
    s += full(p.gaze_x_deg) + "," + full(p.gaze_y_deg);
    if (p.valid) {
      for (double v : {p.lens_x_mm, p.lens_y_mm, p.sphere_d, p.cylinder_d, p.axis_deg, p.mean_power_d, p.power_error_d,
                       p.unwanted_cylinder_d, p.prism_h, p.prism_v, p.distortion_pct, p.lateral_colour_arcmin,
                       p.tangential_d, p.sagittal_d, p.prentice_h, p.prentice_v, p.object_x_deg, p.object_y_deg})
        s += "," + full(v);
    } else {
      s += std::string(18, ',');
    }
    s += "\n";
  }
  return s;
}

json pointJson(const LensmapPoint& p) {
  return {{"gaze_x_deg", num(p.gaze_x_deg)},
          {"gaze_y_deg", num(p.gaze_y_deg)},
          {"lens_x_mm", num(p.lens_x_mm)},
          {"lens_y_mm", num(p.lens_y_mm)},
          {"sphere_d", num(p.sphere_d)},
          {"cylinder_d", num(p.cylinder_d)},
          {"axis_deg", num(p.axis_deg)},
          {"mean_power_d", num(p.mean_power_d)},
          {"tangential_d", num(p.tangential_d)},
          {"sagittal_d", num(p.sagittal_d)},
          {"prism_h", num(p.prism_h)},
          {"prism_v", num(p.prism_v)},
          {"lateral_colour_arcmin", num(p.lateral_colour_arcmin)}};
}

json resultJson(const LensmapResult& r, const std::string& scene_path) {
  json j;
  j["scene"] = scene_path;
  j["element"] = r.element;
  j["material"] = {{"n_d", num(r.n_d)}, {"abbe_v_d", num(r.abbe)}};
  j["conventions"] = {{"frame",
                       "lens frame: +x the wearer's right, +y up, +z towards the eye; lens_x_mm, lens_y_mm: the chief "
                       "ray on the eye-side surface"},
                      {"rotation_centre",
                       "on the lens axis, rotation_centre_mm behind the eye-side vertex; powers are taken on "
                       "the vertex sphere (about the rotation centre, through the eye-side vertex)"},
                      {"gaze",
                       "Fick angles: gaze_x_deg turns the eye towards the wearer's right about the vertical axis, then "
                       "gaze_y_deg turns it up"},
                      {"power",
                       "dioptres, positive converging; wavefront vergence on the vertex sphere minus the object's own "
                       "vergence there (0 at infinity); sphere/cylinder in minus-cylinder form"},
                      {"axis", "TABO: 0-180 deg, counter-clockwise as seen facing the wearer, 0 at the wearer's left"},
                      {"prism",
                       "prism dioptres = 100 tan(deviation) in the eye's own horizontal/vertical frame; base right "
                       "(prism_h > 0) and base up (prism_v > 0) positive"},
                      {"prentice",
                       "Prentice's rule beside it: -100 x (centre power matrix) x (decentration on the eye-side "
                       "surface, m); an approximation (ignores form, thickness, obliquity)"},
                      {"power_error", "mean power minus the prescription's (the straight-ahead reading)"},
                      {"unwanted_cylinder", "|cylinder| (>= 0) of the power matrix minus the prescription's"},
                      {"distortion",
                       "100 (|t_gaze| / |J0^-1 (t_obj - t_obj0)| - 1): the gaze's tangents (the image) against the "
                       "paraxial image of the object's tangents seen from the rotation centre; < 0 barrel, > 0 "
                       "pincushion"},
                      {"lateral_colour",
                       "angle between the object-side chief rays at the F (486.13 nm) and C (656.27 nm) lines, "
                       "arcmin"}};
  j["rotation_centre_mm"] = 1e3 * r.options.rotation_centre_m;
  j["object_distance_m"] = num(r.options.object_distance_m);
  j["grid"] = r.options.grid;
  j["gaze_max_deg"] = r.options.gaze_max_deg;
  j["prescription"] = {{"sphere_d", num(r.centre.sphere_d)},
                       {"cylinder_d", num(r.centre.cylinder_d)},
                       {"axis_deg", num(r.centre.axis_deg)},
                       {"mean_power_d", num(r.centre.mean_power_d)},
                       {"source", "the straight-ahead gaze (0, 0)"}};
  j["centre"] = pointJson(r.centre);
  // Ranges of every CSV column over the gazes that pass.
  json ranges = json::object();
  auto range = [&](const char* name, double LensmapPoint::*f) {
    double lo = kInf, hi = -kInf;
    for (const LensmapPoint& p : r.points)
      if (p.valid && std::isfinite(p.*f)) {
        lo = std::min(lo, p.*f);
        hi = std::max(hi, p.*f);
      }
    ranges[name] = {num(lo), num(hi)};
  };
  range("sphere_d", &LensmapPoint::sphere_d);
  range("cylinder_d", &LensmapPoint::cylinder_d);
  range("mean_power_d", &LensmapPoint::mean_power_d);
  range("power_error_d", &LensmapPoint::power_error_d);
  range("unwanted_cylinder_d", &LensmapPoint::unwanted_cylinder_d);
  range("prism_h", &LensmapPoint::prism_h);
  range("prism_v", &LensmapPoint::prism_v);
  range("distortion_pct", &LensmapPoint::distortion_pct);
  range("lateral_colour_arcmin", &LensmapPoint::lateral_colour_arcmin);
  range("lens_x_mm", &LensmapPoint::lens_x_mm);
  range("lens_y_mm", &LensmapPoint::lens_y_mm);
  j["ranges"] = ranges;
  j["gazes"] = r.points.size();
  j["empty"] = {{"count", r.empty},
                {"miss", r.empty_miss},
                {"tir", r.empty_tir},
                {"meaning",
                 "gazes whose chief ray or bundle misses a surface inside the outline (miss) or is "
                 "totally reflected (tir): their CSV cells are empty"}};
  const LensmapResult::Focimeter& f = r.focimeter;
  j["focimeter"] = f.found ? json{{"found", true},
                                  {"optical_centre_lens_mm", {num(f.lens_x_mm), num(f.lens_y_mm)}},
                                  {"optical_centre_gaze_deg", {num(f.gaze_x_deg), num(f.gaze_y_deg)}},
                                  {"sphere_d", num(f.sphere_d)},
                                  {"cylinder_d", num(f.cylinder_d)},
                                  {"axis_deg", num(f.axis_deg)},
                                  {"newton_iterations", f.iterations},
                                  {"residual_prism", num(f.residual_prism)},
                                  {"meaning",
                                   "back vertex power at the optical centre (zero prism) with a "
                                   "parallel beam, measured on the eye-side surface"}}
                           : json{{"found", false}, {"reason", f.reason}};
  const LensmapResult::Progressive& pr = r.progressive;
  if (pr.detected)
    j["progressive"] = {
        {"add_d", num(pr.add_d)},
        {"far_point",
         {{"gaze_y_deg", num(pr.far_gaze_y_deg)},
          {"lens_y_mm", num(pr.far_lens_y_mm)},
          {"mean_power_d", num(pr.far_mean_d)}}},
        {"near_point",
         {{"gaze_y_deg", num(pr.near_gaze_y_deg)},
          {"lens_y_mm", num(pr.near_lens_y_mm)},
          {"mean_power_d", num(pr.near_mean_d)}}},
        {"corridor_length_mm", num(pr.corridor_length_mm)},
        {"corridor_width_mm", num(pr.corridor_width_mm)},
        {"corridor_width_gaze_y_deg", num(pr.corridor_mid_gaze_y_deg)},
        {"definitions",
         "searched along the vertical meridian gaze_x = 0 (no inset) in 0.25 deg steps. Far point: straight ahead (the "
         "prescription). add_d: the highest mean power on the meridian minus the far point's. Near point: the first "
         "gaze down the meridian reaching 95 % of the add. Corridor length: far point to 85 % of the add, lens y on "
         "the eye-side surface. Corridor width: at 50 % of the add, the lens x extent with unwanted cylinder below "
         "0.5 D"}};
  else
    j["progressive"] = nullptr;
  j["elapsed_ms"] = r.elapsed_ms;
  return j;
}

// Straight object lines: the paraxial images of a square grid of gaze tangents (the reference), and the gazes
// that really see them (gazeForObject), 11 lines each way.
DistortionGrid distortionGrid(const Lensmap& map, double gaze_max_deg) {
  constexpr int kLines = 11, kSamples = 61;
  const double t = std::tan(radians(gaze_max_deg));
  DistortionGrid g;
  for (int dir = 0; dir < 2; ++dir)
    for (int i = 0; i < kLines; ++i) {
      const double c = t * (2.0 * i / (kLines - 1) - 1);
      std::vector<Vec2> ref, seen;
      for (int k = 0; k < kSamples; ++k) {
        const double u = t * (2.0 * k / (kSamples - 1) - 1);
        const Vec2 tg = dir == 0 ? Vec2(c, u) : Vec2(u, c);
        ref.push_back(tg);
        const std::optional<Vec2> s = map.gazeForObject(map.paraxialObject(tg));
        if (s) {
          seen.push_back(*s);
        } else if (!seen.empty()) {
          g.seen.push_back(seen);
          seen.clear();
        }
      }
      g.reference.push_back(ref);
      if (seen.size() > 1) g.seen.push_back(seen);
    }
  return g;
}

}  // namespace

int cmdLensmap(const std::vector<std::string>& argv) {
  Args a("lensmap", argv, {"element", "grid", "object-distance", "gaze-max", "out", "set"}, {}, {"set"});
  if (a.positional().size() != 1) usageError("lensmap", "expected one SCENE");
  const auto out = a.get("out");
  if (!out) usageError("lensmap", "--out DIR is required");
  const std::string scene_path = a.positional()[0];
  LensmapOptions options;
  options.grid = a.getInt("grid", options.grid, 1);
  if (options.grid > 401) usageError("lensmap", "--grid: expected at most 401");
  options.gaze_max_deg = a.getDouble("gaze-max", options.gaze_max_deg);
  if (!(options.gaze_max_deg > 0 && options.gaze_max_deg < 80))
    usageError("lensmap", "--gaze-max: expected degrees in (0, 80)");
  if (a.has("object-distance")) {
    options.object_distance_m = a.getDouble("object-distance", 0);
    if (!(options.object_distance_m > 0)) usageError("lensmap", "--object-distance: expected metres > 0");
  }

  LoadedScene ls = loadScene(scene_path, a.all("set"));
  const Scene& scene = ls.scene;
  const int index = chooseElement(scene, a, scene_path, ElementType::Lens, "no lens to map", "lenses");
  const Element& el = scene.elements[size_t(index)];
  const std::string el_path = "elements[" + std::to_string(index) + "] (" + el.name + ")";
  if (el.type != ElementType::Lens)
    throw Error(scene_path + ": " + el_path + ": pvrr lensmap maps a lens, not a mirror");
  options.rotation_centre_m = el.eye_rotation_centre_m;
  if (!(options.object_distance_m > options.rotation_centre_m))
    usageError("lensmap", "--object-distance: must exceed the rotation centre's distance, " +
                              fmt("%g", 1e3 * options.rotation_centre_m) + " mm");

  RayScene rays(scene);
  LensmapResult r;
  DistortionGrid grid;
  try {
    Progress progress("lensmap", 2.0);  // the map (one multithreaded call), then the distortion grid
    const Lensmap map(rays, index, options);
    r = map.run();
    progress.update(1);
    grid = distortionGrid(map, options.gaze_max_deg);
    progress.finish();
  } catch (const Error& e) {
    throw Error(scene_path + ": " + el_path + ": " + e.what());
  }
  writeFileAtomic((fs::path(*out) / "lensmap.csv").string(), csv(r));
  writeFileAtomic((fs::path(*out) / "lensmap.json").string(), resultJson(r, scene_path).dump(2) + "\n");
  const std::vector<std::string> maps = writeLensmapPlots(*out, r, grid);
  std::printf("%s\n", (fs::path(*out) / "lensmap.csv").string().c_str());
  std::printf("%s\n", (fs::path(*out) / "lensmap.json").string().c_str());
  for (const std::string& m : maps) std::printf("%s\n", m.c_str());
  std::printf("%s: centre %+.3f / %+.3f x %.0f, %d of %zu gazes empty, %.0f ms\n", el.name.c_str(), r.centre.sphere_d,
              r.centre.cylinder_d, r.centre.axis_deg, r.empty, r.points.size(), r.elapsed_ms);
  return 0;
}

}  // namespace pvrr::app
