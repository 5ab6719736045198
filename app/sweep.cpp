// pvrr sweep: compare over a grid of tessellations, map sizes and --vary values; pvrr plot: redraw the plots.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <sstream>
#include <unistd.h>

#include "app/args.h"
#include "app/plot.h"
#include "app/progress.h"
#include "app/report.h"
#include "pvrr/base/error.h"

namespace pvrr::app {

namespace {

std::vector<std::string> splitList(const std::string& s, char sep) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, sep))
    if (!item.empty()) out.push_back(item);
  return out;
}

std::vector<int> intList(const Args& a, const std::string& name, std::vector<int> fallback) {
  auto v = a.get(name);
  if (!v) return fallback;
  std::vector<int> out;
  for (const std::string& s : splitList(*v, ',')) {
    char* end = nullptr;
    const long n = std::strtol(s.c_str(), &end, 10);
    if (*end || n < 2 || n > 4096) usageError("sweep", "--" + name + ": expected integers 2..4096, got \"" + s + "\"");
    out.push_back(int(n));
  }
  if (out.empty()) usageError("sweep", "--" + name + ": empty list");
  return out;
}

}  // namespace

int cmdSweep(const std::vector<std::string>& argv) {
  Args a("sweep", argv, {"tessellation", "map-size", "vary", "modes", "size", "out", "gl", "frames", "set"}, {}, {"vary", "set"});
  if (a.positional().size() != 1) usageError("sweep", "expected one scene file");
  auto out = a.get("out");
  if (!out) usageError("sweep", "--out DIR is required");
  const std::string scene_path = a.positional()[0];
  const auto size = a.getSize("size");
  const int frames = a.getInt("frames", 3, 1);
  const std::vector<int> tess = intList(a, "tessellation", {7, 15, 33});
  std::vector<RenderMode> modes;
  for (const std::string& m : splitList(a.get("modes", "pvrr,envmap"), ',')) modes.push_back(parseModeOption(m, false));
  // --vary PATH=V1,V2: the cartesian product of all --vary lists.
  std::vector<std::vector<std::string>> vary_sets = {{}};
  for (const std::string& v : a.all("vary")) {
    const size_t eq = v.find('=');
    if (eq == std::string::npos || eq == 0) usageError("sweep", "--vary: expected PATH=V1,V2,..., got \"" + v + "\"");
    std::vector<std::vector<std::string>> next;
    for (const auto& base : vary_sets)
      for (const std::string& value : splitList(v.substr(eq + 1), ',')) {
        auto b = base;
        b.push_back(v.substr(0, eq) + "=" + value);
        next.push_back(b);
      }
    vary_sets = next;
  }
  const std::string gl_name = a.get("gl", gl::glBackendName(gl::glBackendFromEnvironment(gl::GlBackend::Auto)));
  gl::parseGlBackend(gl_name);
  // Map sizes default to the scene's own.
  LoadedScene probe = loadScene(scene_path, a.all("set"), size ? size->first : 0, size ? size->second : 0);
  const std::vector<int> maps = intList(a, "map-size", {probe.scene.render.map_size});

  std::vector<SweepRow> rows;
  const size_t total = vary_sets.size() * tess.size() * maps.size() * modes.size();
  size_t done = 0;
  Progress progress("sweep", double(total));
  for (const auto& vary : vary_sets) {
    std::vector<std::string> base_sets = a.all("set");
    base_sets.insert(base_sets.end(), vary.begin(), vary.end());
    // The reference depends on the scene only, not on the tessellation or the map size.
    LoadedScene ref_scene = loadScene(scene_path, base_sets, size ? size->first : 0, size ? size->second : 0);
    RenderSession none;
    const RenderedFrame ref = renderFrame(ref_scene, RenderMode::Raytrace, gl_name, &none);
    std::string vary_label;
    for (const std::string& v : vary) vary_label += (vary_label.empty() ? "" : ";") + v;
    for (int n : tess)
      for (int map : maps) {
        std::vector<std::string> sets = base_sets;
        // Explicit map sizes are the maps' sizes: not lowered to the element's pixels (a --set of
        // render.map_texels_per_pixel, coming later, still wins).
        if (a.has("map-size")) sets.insert(sets.begin(), "render.map_texels_per_pixel=0");
        for (size_t e = 0; e < ref_scene.scene.elements.size(); ++e)
          sets.push_back("elements[" + std::to_string(e) + "].tessellation=" + std::to_string(n));
        sets.push_back("render.map_size=" + std::to_string(map));
        LoadedScene ls = loadScene(scene_path, sets, size ? size->first : 0, size ? size->second : 0);
        long vertices = 0;
        for (const Element& el : ls.scene.elements) vertices += long(el.tess_u) * long(el.tess_v);
        for (const RenderMode m : modes) {
          double frame_ms = 0;
          const RenderedFrame f = timedFrame(ls, m, gl_name, frames, &frame_ms);
          const ErrorStats st = compareToReference(ref, f, nullptr);
          SweepRow r;
          r.mode = nameOf(m);
          r.tessellation = n;
          r.map_size = map;
          r.vary = vary_label;
          r.vertices = vertices;
          r.frame_ms = frame_ms;
          r.reference_ms = ref.frame_ms;
          r.median_arcmin = st.median_arcmin;
          r.p95_arcmin = st.p95_arcmin;
          r.max_arcmin = st.max_arcmin;
          r.psnr_db = st.psnr_db;
          rows.push_back(r);
          progress.update(double(++done));
        }
      }
  }
  progress.finish();
  writeFileAtomic(*out + "/sweep.csv", sweepCsv(rows));
  writeSweepPlots(*out, rows);
  std::printf("%s/sweep.csv\n%s/error_vs_time.png\n%s/error_vs_time.svg\n%s/error_vs_vertices.png\n", out->c_str(), out->c_str(),
              out->c_str(), out->c_str());
  return 0;
}

int cmdPlot(const std::vector<std::string>& argv) {
  Args a("plot", argv, {"out"});
  if (a.positional().size() != 1) usageError("plot", "expected one sweep.csv");
  const std::string csv = a.positional()[0];
  const std::vector<SweepRow> rows = readSweepCsv(csv);
  std::string dir = a.get("out", std::filesystem::path(csv).parent_path().string());
  if (dir.empty()) dir = ".";
  writeSweepPlots(dir, rows);
  std::printf("%s/error_vs_time.png\n%s/error_vs_time.svg\n%s/error_vs_vertices.png\n", dir.c_str(), dir.c_str(), dir.c_str());
  return 0;
}

}  // namespace pvrr::app
