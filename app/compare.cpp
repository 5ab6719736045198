// pvrr compare and pvrr vertices: accuracy against the reference, per-vertex data.
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <unistd.h>

#include "app/args.h"
#include "app/compare_caustics.h"
#include "app/progress.h"
#include "app/report.h"
#include "pvrr/base/error.h"
#include "pvrr/base/format.h"
#include "pvrr/base/image.h"
#include "pvrr/optics/spectrum.h"

namespace fs = std::filesystem;
using nlohmann::json;

namespace pvrr::app {

double peakRssMb() {
  std::ifstream in("/proc/self/status");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("VmHWM:", 0) == 0) return std::stod(line.substr(6)) / 1024.0;
  return 0;
}

double currentRssMb() {
  std::ifstream in("/proc/self/statm");
  long pages_total = 0, pages_resident = 0;
  if (!(in >> pages_total >> pages_resident)) return 0;
  return double(pages_resident) * double(::sysconf(_SC_PAGESIZE)) / (1024.0 * 1024.0);
}

int rssBaselineFrame(int frames) { return frames < 100 ? 1 : 100; }

namespace {

// The heat maps' colours: errorHeatColour (pvrr/analysis/accuracy.h), shared with pvrr view's overlay.
Vec3 heat(double x) { return errorHeatColour(x); }

// 3x5 bitmap digits for the colour bar's labels ('.', '0'-'9').
const char* glyph(char c) {
  switch (c) {
    case '0': return "111101101101111";
    case '1': return "010110010010111";
    case '2': return "111001111100111";
    case '3': return "111001111001111";
    case '4': return "101101111001001";
    case '5': return "111100111001111";
    case '6': return "111100111101111";
    case '7': return "111001001001001";
    case '8': return "111101111101111";
    case '9': return "111101111001111";
    case '.': return "000000000000010";
    default: return "000000000000000";
  }
}

void drawText(ImageRGB8& img, int x0, int y0, const std::string& s, int scale) {
  for (size_t k = 0; k < s.size(); ++k) {
    const char* g = glyph(s[k]);
    for (int gy = 0; gy < 5; ++gy)
      for (int gx = 0; gx < 3; ++gx)
        if (g[gy * 3 + gx] == '1')
          for (int sy = 0; sy < scale; ++sy)
            for (int sx = 0; sx < scale; ++sx) {
              const int x = x0 + int(k) * 4 * scale + gx * scale + sx, y = y0 + gy * scale + sy;
              if (x >= 0 && y >= 0 && x < img.width && y < img.height) {
                uint8_t* p = img.at(x, y);
                p[0] = p[1] = p[2] = 255;
              }
            }
  }
}

// The error heat map: per-pixel angular error over element pixels (others dark grey), with a colour bar
// on the right labelled 0 and the scale maximum in arcminutes.
void writeHeatMap(const std::string& path, int w, int h, const std::vector<double>& err, double scale_arcmin) {
  const int bar = 60;
  ImageRGB8 img(w + bar, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const double e = err[size_t(y) * size_t(w) + size_t(x)];
      uint8_t* p = img.at(x, y);
      if (std::isnan(e)) {
        p[0] = p[1] = p[2] = 40;
        continue;
      }
      const Vec3 c = heat(e / scale_arcmin);
      for (int k = 0; k < 3; ++k) p[k] = uint8_t(std::lround(255 * c[k]));
    }
  const int top = 20, bottom = h - 20;
  for (int y = 0; y < h; ++y)
    for (int x = w; x < w + bar; ++x) {
      uint8_t* p = img.at(x, y);
      p[0] = p[1] = p[2] = 0;
      if (y >= top && y <= bottom && x >= w + 8 && x < w + 20) {
        const Vec3 c = heat(double(bottom - y) / double(std::max(1, bottom - top)));
        for (int k = 0; k < 3; ++k) p[k] = uint8_t(std::lround(255 * c[k]));
      }
    }
  char label[32];
  std::snprintf(label, sizeof label, "%.3g", scale_arcmin);
  drawText(img, w + 4, 4, label, 2);
  drawText(img, w + 4, h - 14, "0", 2);
  writePngAtomic(path, img);
}

}  // namespace

namespace {

json statsJson(const ErrorStats& s) {
  return {{"pixels", s.pixels},
          {"angular_error_arcmin", {{"median", s.median_arcmin}, {"p95", s.p95_arcmin}, {"max", s.max_arcmin}}}};
}

json fringeJson(const FringeStats& f) {
  return {{"pixels", f.pixels},
          {"median_blue_minus_red_deviation_arcmin", f.median_blue_minus_red_arcmin},
          {"fraction_blue_bends_more", f.fraction_blue_bends_more},
          {"blue_bends_more", f.pixels > 0 && f.median_blue_minus_red_arcmin > 0}};
}

// The CPU vertex stages (rays, fit, view volumes) of the given elements from the observer's eye, with the
// channels the renderer uses (dispersionChannels: R, G, B or the spectral samples for a dispersive lens).
std::vector<ElementFrame> vertexStageFrames(const Scene& scene, const RayScene& rays, const std::vector<int>& which) {
  std::vector<ElementFrame> frames;
  for (int e : which) {
    VertexStageOptions o;
    o.channels = dispersionChannels(scene, e);
    o.viewpoint.solver = scene.render.viewpoint_solver;
    o.viewer_clip = scene.observer.visibilityProjection() * scene.observer.view();  // as the renderer fits
    ElementFrame f = prepareElement(scene, e);
    traceVertexRays(rays, f, scene.observer.eye, o);
    fitPatchViews(scene, f, o);
    frames.push_back(std::move(f));
  }
  return frames;
}

const char* kDefinitions[][2] = {
    {"frame_ms", "a mode's median full-frame time over --frames frames after a warm-up, every stage run (no cache), "
                 "the GPU finished, drawn as pvrr render draws it: colour only, without the seen-point attachments "
                 "that the accuracy figures are read from (those come from one more frame with them on), and not "
                 "read back from the GPU (a viewer presents the frame); the reference's: one multithreaded "
                 "ray-traced frame"},
    {"angular_error", "per pixel where the reference sees a mirror or lens: the angle, at the reference's surface point, "
                      "between the directions to the mode's seen point and to the reference's"},
    {"depth_limit", "element pixels where the reference's path ended at the depth limit (render.max_depth): it has no "
                    "seen point there (the reference draws them black), so they are left out of angular_error and "
                    "compared by colour only: drawn_lit counts those the mode draws lit (an sRGB channel above 0.15), "
                    "psnr_db is the mode's colour PSNR over them; drawn_dark_where_reference_lit counts the other "
                    "element pixels the reference draws lit and the mode draws dark (every sRGB channel below 0.05)"},
    {"zooming_region", "pixels whose reference seen point lies behind the fitted virtual viewpoint of the pvrr patch under "
                       "the pixel (the patch of the nearest element vertex), along the patch's forward direction (the "
                       "normalised mean of its outgoing rays, the axis of its forward view volume): (seen - viewpoint) . "
                       "forward <= 0, e.g. objects nearer a concave mirror than the point where its rays converge; "
                       "outside_zooming: the other element pixels whose path meets only that element; "
                       "not_classified: pixels whose reference path goes on to another element (or is totally "
                       "reflected inside a lens), where the seen point is not the element's own hit"},
    {"channels", "with rgb dispersion: channel c's error compares the reference's channel-c ray (R = C line 656.3 nm, "
                 "G = d line 587.6 nm, B = F line 486.1 nm) with the mode's channel-c seen point (pvrr: rendered once per "
                 "channel; other modes have one seen point for all channels)"},
    {"psnr_db", "colour PSNR over the element pixels (sRGB-encoded, clamped to [0, 1]) against the reference, which "
                "traces one ray through each pixel centre: fine detail aliases in it, and a mode that point-samples "
                "the same way scores higher"},
    {"psnr_supersampled_db", "the same against the reference traced at twice the size, each pixel the linear mean "
                             "of its 2 x 2: closer to the true picture (reference.frame_ms is the one-ray frame's)"},
    {"over_time", "with --fps: the reference and each mode at the instants time_s + i / fps, i < --frames (the "
                  "scene's animation posed at each); per frame and mode the angular error and PSNR as above, and "
                  "the worst frame: the one with the largest p95 angular error (DIR/frames.csv holds the same rows)"},
    {"fringe", "over dispersive lens pixels: the deviation of a channel is the angle between the eye ray and the line from "
               "the lens point to that channel's seen point; blue bends more than red where deviation(B) > deviation(R); "
               "pixels where the two differ by less than 0.01 arcmin are left out"}};

// The reference traced at twice the size, each pixel the linear mean of its 2 x 2 (rows top-down).
std::vector<Vec3> supersampledReference(const LoadedScene& ls, const std::string& gl_name) {
  LoadedScene fine = ls;
  fine.scene.observer.width *= 2;
  fine.scene.observer.height *= 2;
  RenderSession none;
  const RenderedFrame f = renderFrame(fine, RenderMode::Raytrace, gl_name, &none);
  const int w = ls.scene.observer.width, h = ls.scene.observer.height;
  std::vector<Vec3> out(size_t(w) * size_t(h), Vec3(0.0));
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int dy = 0; dy < 2; ++dy)
        for (int dx = 0; dx < 2; ++dx)
          out[size_t(y) * size_t(w) + size_t(x)] += 0.25 * f.color[size_t(2 * y + dy) * size_t(2 * w) + size_t(2 * x + dx)];
  return out;
}

// Compare over time (--fps): the reference and every mode at each instant t_i = time0 + i / fps, i < frames;
// per mode the angular error of each frame and the worst frame (largest p95). One renderer (one GL context)
// draws every mode, each with its own frame cache (on, as pvrr render --frames runs); what moves is updated in
// place (poseSceneAt, Renderer::render). Sets frames.csv's rows in `csv`.
json compareOverTime(LoadedScene& ls, const std::vector<RenderMode>& modes, const std::string& gl_name, int frames,
                     double time0_s, double fps, std::string* csv) {
  RenderSession session;
  std::vector<gl::FrameCache> caches(modes.size());
  json per_frame = json::array();
  std::vector<std::pair<int, ErrorStats>> worst(modes.size(), {-1, ErrorStats{}});
  *csv = "frame,time_s,mode,pixels,median_arcmin,p95_arcmin,max_arcmin,psnr_db\n";
  for (int i = 0; i < frames; ++i) {
    const double t = time0_s + double(i) / fps;
    const bool moved = poseSceneAt(ls, t, &session);
    // The renderer follows the moved objects itself (Renderer::render, pvrr/gl/renderer.h).
    for (gl::FrameCache& c : caches)
      if (i > 0) c.environment_changed = false;
    RenderSession none;
    const RenderedFrame ref = renderFrame(ls, RenderMode::Raytrace, gl_name, &none);
    json jf = {{"frame", i}, {"time_s", t}, {"moved", moved}, {"modes", json::object()}};
    for (size_t k = 0; k < modes.size(); ++k) {
      const std::string m = nameOf(modes[k]);
      session.cache = std::move(caches[k]);
      const RenderedFrame f = renderFrame(ls, modes[k], gl_name, &session);
      caches[k] = std::move(session.cache);
      const ErrorStats st = compareToReference(ref, f);
      jf["modes"][m] = {{"pixels", st.pixels},
                        {"angular_error_arcmin", {{"median", st.median_arcmin}, {"p95", st.p95_arcmin}, {"max", st.max_arcmin}}},
                        {"psnr_db", st.psnr_db}};
      *csv += std::to_string(i) + "," + fmt("%.6g", t) + "," + m + "," + std::to_string(st.pixels) + "," +
              fmt("%.6g", st.median_arcmin) + "," + fmt("%.6g", st.p95_arcmin) + "," + fmt("%.6g", st.max_arcmin) +
              "," + fmt("%.6g", st.psnr_db) + "\n";
      if (worst[k].first < 0 || st.p95_arcmin > worst[k].second.p95_arcmin) worst[k] = {i, st};
    }
    per_frame.push_back(jf);
  }
  json jw = json::object();
  for (size_t k = 0; k < modes.size(); ++k) {
    const std::string m = nameOf(modes[k]);
    const ErrorStats& st = worst[k].second;
    const double t = time0_s + double(worst[k].first) / fps;
    jw[m] = {{"frame", worst[k].first}, {"time_s", t},
             {"angular_error_arcmin", {{"median", st.median_arcmin}, {"p95", st.p95_arcmin}, {"max", st.max_arcmin}}},
             {"psnr_db", st.psnr_db}};
    std::printf("%-8s over %d frames (t = %.4g .. %.4g s): worst frame %d (t = %.4g s): median %.4f' p95 %.4f' max %.3f'\n",
                m.c_str(), frames, time0_s, time0_s + double(frames - 1) / fps, worst[k].first, t, st.median_arcmin,
                st.p95_arcmin, st.max_arcmin);
  }
  return {{"time_s", time0_s}, {"fps", fps}, {"frames", per_frame}, {"worst_frame", jw}};
}

}  // namespace

int cmdCompare(const std::vector<std::string>& argv) {
  Args a("compare", argv, {"modes", "size", "frames", "out", "gl", "set", "fps", "time"}, {}, {"set"});
  if (a.positional().size() != 1) usageError("compare", "expected one scene file");
  auto out_dir = a.get("out");
  if (!out_dir) usageError("compare", "--out DIR is required");
  const auto size = a.getSize("size");
  const int frames = a.getInt("frames", 5, 1);
  // --fps: over time, --frames instants from --time; otherwise --frames times each mode's frame at --time.
  const bool over_time = a.has("fps");
  const double time0_s = a.getDouble("time", 0.0), fps = a.getDouble("fps", 30.0);
  if (!(fps > 0)) usageError("compare", "--fps: expected a number > 0, got \"" + *a.get("fps") + "\"");
  std::vector<RenderMode> modes;
  {
    std::stringstream ss(a.get("modes", "pvrr,envmap"));
    std::string m;
    while (std::getline(ss, m, ','))
      if (!m.empty()) {
        if (parseName<RenderMode>(m) == RenderMode::Raytrace || m == "reference") usageError("compare", "the reference is always rendered; list only raster modes");
        modes.push_back(parseModeOption(m, false));
      }
  }
  const std::string scene_path = a.positional()[0];
  LoadedScene ls = loadScene(scene_path, a.all("set"), size ? size->first : 0, size ? size->second : 0);
  const auto backend = a.get("gl");
  const std::string gl_name = backend ? *backend : gl::glBackendName(gl::glBackendFromEnvironment(gl::GlBackend::Auto));
  gl::parseGlBackend(gl_name);
  RenderSession posing;
  poseSceneAt(ls, time0_s, &posing);

  // Units: the reference 1, the 2x2 supersampled reference 4, each mode 1.
  Progress progress("compare", 5.0 + double(modes.size()));
  size_t modes_done = 0;
  RenderSession none;
  RenderedFrame ref = renderFrame(ls, RenderMode::Raytrace, gl_name, &none);
  progress.update(1);
  const int w = ref.width, h = ref.height;
  json metrics = {{"scene", scene_path}, {"size", {w, h}}, {"reference", {{"frame_ms", ref.frame_ms}}}};
  json definitions = json::object();
  for (const auto& d : kDefinitions) definitions[d[0]] = d[1];
  metrics["definitions"] = definitions;
  writeLinearPng(*out_dir + "/reference.png", w, h, ref.color);
  const std::vector<Vec3> ref_ss = supersampledReference(ls, gl_name);
  metrics["reference"]["psnr_supersampled_db"] = elementPsnr(ref, ref_ss, ref.color);
  {
    size_t limited = 0;
    for (size_t i = 0; i < ref.element.size(); ++i) limited += ref.element[i] >= 0 && depthLimited(ref, i);
    metrics["reference"]["depth_limit_pixels"] = limited;
  }
  progress.update(5);

  // The zooming region (issue 5), from the CPU vertex stages of every element: the same patches, viewpoints
  // and view volumes as the pvrr mode's.
  std::vector<int> all_elements;
  for (size_t e = 0; e < ls.scene.elements.size(); ++e) all_elements.push_back(int(e));
  std::vector<int8_t> zooming;
  {
    RayScene rays(ls.scene);
    zooming = zoomingRegion(ref, vertexStageFrames(ls.scene, rays, all_elements), &ls.scene);
  }
  // Per-channel seen points (issue 6): the reference traces one ray per channel in rgb dispersion mode.
  const bool per_channel = !ref.channel_seen[0].empty();
  const char* channel_names[3] = {"R", "G", "B"};
  std::vector<int8_t> lens_mask(ref.element.size(), 0);
  for (size_t i = 0; i < ref.element.size(); ++i) {
    const int e = ref.element[i];
    lens_mask[i] = e >= 0 && ls.scene.elements[size_t(e)].type == ElementType::Lens && ls.scene.elements[size_t(e)].dispersion_on;
  }
  FringeStats ref_fringe;
  if (per_channel) {
    ref_fringe = fringeStats(ls.scene.observer.eye, ref.element_point, ref.channel_seen[0], ref.channel_seen[2], lens_mask);
    metrics["reference"]["fringe"] = fringeJson(ref_fringe);
  }

  json jm = json::object();
  std::string gl_used;
  for (const RenderMode mode : modes) {
    const std::string m = nameOf(mode);
    double frame_ms = 0;
    const RenderedFrame f = timedFrame(ls, mode, gl_name, over_time ? 1 : frames, &frame_ms);
    gl_used = f.gl_backend;
    progress.clear();
    std::vector<double> err;
    const ErrorStats st = compareToReference(ref, f, &err);
    writeLinearPng(*out_dir + "/" + m + ".png", w, h, f.color);
    const double scale = heatMapScaleArcmin(st);
    writeHeatMap(*out_dir + "/" + m + "-error.png", w, h, err, scale);
    const json stages = stagesJson(f.stages);
    json per_element = json::array();
    for (size_t e = 0; e < ls.scene.elements.size(); ++e) {
      const ErrorStats es = compareToReference(ref, f, nullptr, int(e));
      const DepthLimitColour ed = depthLimitColour(ref, f, int(e));
      per_element.push_back({{"name", ls.scene.elements[e].name}, {"pixels", es.pixels},
                             {"angular_error_arcmin", {{"median", es.median_arcmin}, {"p95", es.p95_arcmin}, {"max", es.max_arcmin}}},
                             {"depth_limit", {{"pixels", ed.pixels}, {"drawn_lit", ed.drawn_lit}}},
                             {"drawn_dark_where_reference_lit", ed.drawn_dark}});
    }
    const DepthLimitColour dl = depthLimitColour(ref, f);
    const ErrorStats zs = summarizeErrors(err, &zooming, 1), os = summarizeErrors(err, &zooming, 0),
                     ns = summarizeErrors(err, &zooming, 2);
    jm[m] = {{"frame_ms", frame_ms},
             {"stages", stages},
             {"speedup_vs_reference", frame_ms > 0 ? ref.frame_ms / frame_ms : 0.0},
             {"pixels", st.pixels},
             {"angular_error_arcmin", {{"median", st.median_arcmin}, {"p95", st.p95_arcmin}, {"max", st.max_arcmin}}},
             {"regions", {{"zooming", statsJson(zs)}, {"outside_zooming", statsJson(os)}, {"not_classified", statsJson(ns)}}},
             {"depth_limit", {{"pixels", dl.pixels}, {"drawn_lit", dl.drawn_lit}, {"psnr_db", dl.psnr_db}}},
             {"drawn_dark_where_reference_lit", dl.drawn_dark},
             {"reference_lit_pixels", dl.reference_lit},
             {"heat_map_scale_arcmin", scale},
             {"psnr_db", st.psnr_db},
             {"psnr_supersampled_db", elementPsnr(ref, ref_ss, f.color)},
             {"rmse", st.rmse},
             {"elements", per_element},
             {"element_stats", f.elements}};
    std::printf("%-8s %8.2f ms  median %.4f' p95 %.4f' max %.3f'  PSNR %.2f dB (%.2f dB against 2x2)  (%zu px)\n",
                m.c_str(), frame_ms, st.median_arcmin, st.p95_arcmin, st.max_arcmin, st.psnr_db,
                jm[m]["psnr_supersampled_db"].get<double>(), st.pixels);
    if (dl.pixels > 0)
      std::printf("%-8s %zu pixels where the reference's path ended at the depth limit (render.max_depth %d): compared "
                  "by colour only: %zu drawn lit where the reference draws them black, PSNR %.2f dB\n",
                  m.c_str(), dl.pixels, ls.scene.render.max_depth, dl.drawn_lit, dl.psnr_db);
    if (dl.drawn_dark > 0)
      std::printf("%-8s %zu of %zu element pixels the reference draws lit are drawn dark\n", m.c_str(), dl.drawn_dark,
                  dl.reference_lit);
    printQuality(f.elements, m + std::string(m.size() < 8 ? 8 - m.size() : 0, ' ') + " ");
    if (zs.pixels > 0)
      std::printf("%-8s zooming region: median %.4f' p95 %.4f' (%zu px); outside: median %.4f' (%zu px)\n", m.c_str(),
                  zs.median_arcmin, zs.p95_arcmin, zs.pixels, os.median_arcmin, os.pixels);
    if (per_channel) {
      // pvrr: each channel's own texture coordinates feed the seen point, one render per channel (the timed
      // frame is the middle channel's); impostor: each channel's own refracted ray, likewise. Other modes
      // have one seen point for every channel.
      std::array<std::vector<Vec3>, 3> seen;
      const bool own = mode == RenderMode::Pvrr || mode == RenderMode::Impostor;
      for (int c = 0; c < 3; ++c) {
        if (!own || c == 1) {
          seen[size_t(c)] = f.seen;
          continue;
        }
        RenderSession s;
        s.seen_channel = c;
        seen[size_t(c)] = renderFrame(ls, mode, gl_name, &s).seen;
      }
      json ch = json::object();
      for (int c = 0; c < 3; ++c) {
        const ErrorStats cs = summarizeErrors(angularErrors(ref, ref.channel_seen[size_t(c)], seen[size_t(c)]));
        json j = statsJson(cs);
        j["wavelength_nm"] = kRgbWavelengths_nm[c];
        ch[channel_names[c]] = j;
        std::printf("%-8s channel %s: median %.4f' p95 %.4f'\n", m.c_str(), channel_names[c], cs.median_arcmin, cs.p95_arcmin);
      }
      jm[m]["channels"] = ch;
      jm[m]["channel_seen"] = own ? "per channel (one render per channel)" : "one seen point for all channels";
      if (own) {
        const FringeStats fs = fringeStats(ls.scene.observer.eye, ref.element_point, seen[0], seen[2], lens_mask);
        json fj = fringeJson(fs);
        fj["agrees_with_reference"] = fs.pixels > 0 && ref_fringe.pixels > 0 &&
                                      (fs.median_blue_minus_red_arcmin > 0) == (ref_fringe.median_blue_minus_red_arcmin > 0);
        jm[m]["fringe"] = fj;
        std::printf("%-8s fringe: blue - red deviation median %.4f' (reference %.4f'), blue bends more at %.0f%% of %zu px\n",
                    m.c_str(), fs.median_blue_minus_red_arcmin, ref_fringe.median_blue_minus_red_arcmin,
                    100 * fs.fraction_blue_bends_more, fs.pixels);
      }
    }
    progress.update(5.0 + double(++modes_done));
  }
  progress.finish();
  // Light (issue 23 item 4): the caustics' irradiance error beside the angular error, where they are on.
  if (json caustics = compareCaustics(ls, gl_name, *out_dir); !caustics.is_null()) metrics["caustics"] = caustics;
  metrics["gl"] = gl_used;
  metrics["modes"] = jm;
  metrics["time_s"] = time0_s;
  if (over_time) {
    std::string csv;
    metrics["over_time"] = compareOverTime(ls, modes, gl_name, frames, time0_s, fps, &csv);
    writeFileAtomic(*out_dir + "/frames.csv", csv);
  }
  metrics["peak_rss_mb"] = peakRssMb();
  writeFileAtomic(*out_dir + "/metrics.json", metrics.dump(2) + "\n");
  std::printf("reference %.1f ms; wrote %s/metrics.json\n", ref.frame_ms, out_dir->c_str());
  return 0;
}

int cmdVertices(const std::vector<std::string>& argv) {
  Args a("vertices", argv, {"element", "out", "set"}, {}, {"set"});
  if (a.positional().size() != 1) usageError("vertices", "expected one scene file");
  auto out = a.get("out");
  if (!out) usageError("vertices", "--out FILE.csv is required");
  const std::string ext = fs::path(*out).extension().string();
  if (ext != ".csv" && ext != ".vtp") usageError("vertices", "--out: expected a .csv or .vtp file, got \"" + *out + "\"");
  LoadedScene ls = loadScene(a.positional()[0], a.all("set"));
  const Scene& scene = ls.scene;
  std::vector<int> which;
  for (size_t e = 0; e < scene.elements.size(); ++e)
    if (!a.has("element") || scene.elements[e].name == *a.get("element")) which.push_back(int(e));
  if (which.empty()) {
    if (a.has("element")) {
      std::vector<std::string> names;
      for (const Element& e : scene.elements) names.push_back(e.name);
      std::string hint = nearest(*a.get("element"), names);
      throw Error(ls.desc.source + ": no element named \"" + *a.get("element") + "\"" +
                  (hint.empty() ? "" : "; did you mean \"" + hint + "\"?"));
    }
    throw Error(ls.desc.source + ": the scene has no mirror or lens");
  }
  RayScene rays(scene);
  const std::vector<ElementFrame> frames = vertexStageFrames(scene, rays, which);
  if (ext == ".vtp") {
    writeVerticesVtp(*out, scene, frames);
    std::printf("%s\n", out->c_str());
    return 0;
  }
  const bool any_lens = std::any_of(which.begin(), which.end(), [&](int e) { return scene.elements[size_t(e)].type == ElementType::Lens; });
  std::ostringstream csv;
  csv.precision(17);
  csv << "element,patch,vertex,channel,px,py,pz,nx,ny,nz,dx,dy,dz,status,hx,hy,hz,s,t";
  if (any_lens) csv << ",ix,iy,iz,bx,by,bz,bnx,bny,bnz";
  csv << "\n";
  json cams = json::array();
  for (const ElementFrame& f : frames) {
    const Element& el = scene.elements[size_t(f.element)];
    json patches = json::array();
    const gl::RendererOptions ro = gl::rendererOptionsFor(scene);
    for (const PatchView& pv : f.views) {
      const cad::GridPatch& gp = f.grid_patches[size_t(pv.patch)];
      const std::array<int, 2> texels = mapTexels(pv.volume, gl::topLevelMapSide(scene, f, pv, ro));
      for (size_t c = 0; c < pv.st.size(); ++c) {
        const double wl = f.channels[c].wavelength_nm > 0 ? f.channels[c].wavelength_nm : kLineD_nm;
        auto rm = [](const Mat4& m) { auto r = rowMajor16(m); return json(std::vector<double>(r.begin(), r.end())); };
        patches.push_back({{"patch", pv.patch}, {"channel", c}, {"eye", {pv.volume.eye.x, pv.volume.eye.y, pv.volume.eye.z}},
                           {"view_matrix", rm(pv.volume.view)}, {"projection_matrix", rm(pv.volume.projection)},
                           {"map_size", {texels[0], texels[1]}},
                           {"wavelength_nm", wl},
                           {"n", el.type == ElementType::Lens ? el.dispersion.index(wl) : 1.0}});
        for (size_t k = 0; k < gp.vertices.size(); ++k) {
          const uint32_t vi = gp.vertices[k];
          const VertexRay& r = f.rays[c][vi];
          const Vec3 p = f.world_pos[vi], n = f.world_normal[vi];
          csv << el.name << ',' << pv.patch << ',' << vi << ',' << c << ',' << p.x << ',' << p.y << ',' << p.z << ','
              << n.x << ',' << n.y << ',' << n.z << ',' << r.dir.x << ',' << r.dir.y << ',' << r.dir.z << ','
              << nameOf(r.status) << ',' << r.hit.x << ',' << r.hit.y << ',' << r.hit.z << ',' << pv.st[c][k].x << ','
              << pv.st[c][k].y;
          if (any_lens)
            csv << ',' << r.internal_dir.x << ',' << r.internal_dir.y << ',' << r.internal_dir.z << ',' << r.back_point.x
                << ',' << r.back_point.y << ',' << r.back_point.z << ',' << r.back_normal.x << ',' << r.back_normal.y << ','
                << r.back_normal.z;
          csv << "\n";
        }
      }
    }
    cams.push_back({{"name", el.name}, {"patches", patches}});
  }
  json j = {{"observer", {scene.observer.eye.x, scene.observer.eye.y, scene.observer.eye.z}}, {"n_outside", 1.0}, {"elements", cams}};
  const std::string json_path = (fs::path(*out).replace_extension(".json")).string();
  writeFileAtomic(*out, csv.str());
  writeFileAtomic(json_path, j.dump(2) + "\n");
  std::printf("%s\n%s\n", out->c_str(), json_path.c_str());
  return 0;
}

}  // namespace pvrr::app
