// Shared pieces of the subcommands, and `render`, `gl-info`, `trace`.
#include "app/commands.h"

#include <nlohmann/json.hpp>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <glm/gtc/matrix_transform.hpp>
#include <random>
#include <time.h>

#include "app/args.h"
#include "app/progress.h"
#include "app/report.h"
#include "pvrr/base/error.h"
#include "pvrr/gl/context.h"
#include "pvrr/gl/gl.h"
#include "pvrr/gl/stage_notes.h"
#include "pvrr/base/format.h"
#include "pvrr/base/image.h"
#include "pvrr/scene/scene_json.h"
#include "pvrr/optics/spectrum.h"
#include "pvrr/base/frame.h"
#include "pvrr/method/reference_setup.h"

namespace fs = std::filesystem;
using nlohmann::json;

namespace pvrr::app {

LoadedScene loadScene(const std::string& path, const std::vector<std::string>& overrides, int width, int height) {
  LoadedScene ls;
  ls.desc = pvrr::loadScene(path, overrides);
  if (width > 0) {
    ls.desc.observer.image_width = width;
    ls.desc.observer.image_height = height;
  }
  ls.scene = buildScene(ls.desc, readMeshFile);
  return ls;
}

int chooseElement(const Scene& scene, const Args& a, const std::string& scene_path, ElementType type,
                  const std::string& none, const std::string& plural) {
  const std::optional<std::string> asked = a.get("element");
  int index = -1, of_type = 0;
  for (size_t i = 0; i < scene.elements.size(); ++i) {
    const Element& e = scene.elements[i];
    if (asked ? e.name == *asked : (e.type == type && index < 0)) index = int(i);
    of_type += e.type == type;
  }
  if (asked && index < 0) {
    std::vector<std::string> names;
    for (const Element& e : scene.elements) names.push_back(e.name);
    const std::string hint = nearest(*asked, names);
    throw Error(scene_path + ": elements: no element named \"" + *asked + "\"" +
                (hint.empty() ? "" : "; did you mean \"" + hint + "\"?"));
  }
  if (index < 0) throw Error(scene_path + ": elements: " + none);
  if (!asked && of_type > 1)
    throw Error(scene_path + ": elements: " + std::to_string(of_type) + " " + plural + "; choose one with --element");
  return index;
}

size_t writeLinearPng(const std::string& path, int width, int height, const std::vector<Vec3>& linear) {
  size_t bad = 0;
  const ImageRGB8 img = srgbPicture(width, height, linear, &bad);
  writePngAtomic(path, img, MissingFolder::Create);
  return bad;
}

namespace {

gl::GlBackend backendArg(const Args& a) {
  auto v = a.get("gl");
  return v ? gl::parseGlBackend(*v) : gl::glBackendFromEnvironment(gl::GlBackend::Auto);
}

json vec(const Vec3& v) { return json::array({v.x, v.y, v.z}); }

}  // namespace

json stagesJson(const FrameStages& s) {
  json a = json::array();
  for (const StageTiming& t : s.stages) {
    json j = {{"name", t.name}, {"ms", t.ms}, {"ran", t.ran}, {"reason", t.reason}};
    if (t.count >= 0) j["count"] = t.count;
    if (!t.note.empty()) j["note"] = t.note;
    a.push_back(std::move(j));
  }
  return a;
}

json patchQualityJson(const PatchQuality& q) {
  return {{"verdict", toString(q.verdict)},
          {"reasons", q.reasons},
          {"action", q.action},
          {"fov_deg", q.fov_deg},
          {"fov_limited", q.fov_limited},
          {"hits_behind_viewpoint", q.hits_behind},
          {"fit_rms_angle_arcmin", q.fit_rms_arcmin},
          {"fit_max_angle_arcmin", q.fit_max_arcmin},
          {"st_outside_share", q.st_outside_share},
          {"max_ray_spread_deg", q.max_ray_spread_deg},
          {"max_normal_spread_deg", q.max_normal_spread_deg},
          {"max_traced_spread_deg", q.max_traced_spread_deg},
          {"max_edge_spread_deg", q.max_edge_spread_deg},
          {"tir_share", q.tir_share}};
}

void printQuality(const json& elements, const std::string& prefix) {
  for (const json& e : elements) {
    if (e.contains("quality") && !e["quality"].value("note", "").empty())
      std::printf("%snote: %s\n", prefix.c_str(), e["quality"]["note"].get<std::string>().c_str());
    if (!e.contains("quality") || e["quality"]["verdict"] == "good") continue;
    std::string line = prefix + "quality: " + e["name"].get<std::string>() + " " + e["quality"]["verdict"].get<std::string>() +
                       ": " + e["quality"]["action"].get<std::string>();
    for (const json& p : e["patches"])
      if (p["quality"]["verdict"] != "good")
        line += "; patch " + std::to_string(p["patch"].get<int>()) + " " + p["quality"]["verdict"].get<std::string>() +
                " (" + p["quality"]["reasons"].get<std::string>() + ")";
    std::printf("%s\n", line.c_str());
  }
}

json elementsJson(const Scene& scene, const std::vector<ElementFrame>& frames) {
  json out = json::array();
  for (const ElementFrame& f : frames) {
    const Element& el = scene.elements[size_t(f.element)];
    json e = {{"name", el.name},
              {"type", el.type == ElementType::Lens ? "lens" : "mirror"},
              {"vertices", f.world_pos.size()},
              {"grid", {f.grid.grid_u, f.grid.grid_v}},
              {"patches_grid", {f.patches_u, f.patches_v}},
              {"split_note", f.split_note},
              {"vertex_rays_ms", f.rays_ms},
              {"viewpoint_fit_ms", f.fit_ms}};
    int escapes = 0, tirs = 0;
    for (const auto& ch : f.rays)
      for (const VertexRay& r : ch) {
        escapes += r.status == VertexStatus::Escape;
        tirs += r.status == VertexStatus::Tir;
      }
    e["escaping_rays"] = escapes;
    e["tir_rays"] = tirs;
    json patches = json::array();
    for (const PatchView& pv : f.views) {
      const auto& gp = f.grid_patches[size_t(pv.patch)];
      patches.push_back({{"patch", pv.patch},
                         {"vertices", gp.vertices.size()},
                         {"viewpoint", vec(pv.fit.eye)},
                         {"fit_condition_number", std::isfinite(pv.fit.condition_number) ? json(pv.fit.condition_number) : json("inf")},
                         {"fit_cost", pv.fit.cost_final},
                         {"fit_rms_angle_arcmin", arcminutes(pv.fit.rms_angle_rad)},
                         {"fit_max_angle_arcmin", arcminutes(pv.fit.max_angle_rad)},
                         {"fit_accepted", pv.fit.accepted},
                         {"fit_solver", pv.fit.solver_report},
                         {"fallback", pv.fit.fallback},
                         {"frustum_fov_deg", {degrees(pv.volume.fov_x_rad), degrees(pv.volume.fov_y_rad)}},
                         {"view_volume_note", pv.volume.note},
                         {"zooming_hits", pv.volume.zooming.size()},
                         {"quality", patchQualityJson(pv.quality)}});
    }
    e["patches"] = patches;
    e["quality"] = {{"verdict", toString(f.quality.verdict)}, {"action", f.quality.action}, {"note", f.quality.note}};
    out.push_back(e);
  }
  return out;
}

int cmdGlInfo(const std::vector<std::string>& argv) {
  Args a("gl-info", argv, {"gl"});
  if (!a.positional().empty()) usageError("gl-info", "unexpected argument \"" + a.positional()[0] + "\"");
  auto ctx = gl::GlContext::create(backendArg(a));
  // The limits the renderer adapts to: map sizes, and the texture units of impostor mode's several elements.
  GLint max_size = 0, units = 0;
  glGetIntegerv(GL_MAX_TEXTURE_SIZE, &max_size);
  glGetIntegerv(GL_MAX_TEXTURE_IMAGE_UNITS, &units);
  std::printf("backend: %s\nGL_VERSION: %s\nGL_RENDERER: %s\nGL_VENDOR: %s\nGLSL: %s\nhardware: %s\n"
              "GL_MAX_TEXTURE_SIZE: %d\nGL_MAX_TEXTURE_IMAGE_UNITS: %d\n",
              ctx->backendName().c_str(), ctx->glVersion().c_str(), ctx->glRenderer().c_str(), ctx->glVendor().c_str(),
              ctx->glslVersion().c_str(), ctx->isHardware() ? "yes" : "no", max_size, units);
  return 0;
}

RenderMode parseModeOption(const std::string& text, bool raytrace_ok) {
  const std::optional<RenderMode> mode = parseName<RenderMode>(text);
  if (!mode || (!raytrace_ok && !isRasterMode(*mode)))
    throw Error("mode: expected one of " + nameListIf<RenderMode>(isRasterMode) + ", " + nameOf(RenderMode::Raytrace) +
                "; got \"" + text + "\"");
  return *mode;
}

RenderedFrame timedFrame(LoadedScene& ls, RenderMode mode, const std::string& gl_backend_name, int frames,
                         double* median_ms) {
  // Timed as pvrr render draws for viewing (colour only, no seen-point attachments): one warm-up frame
  // (shader compilation, first uploads), then the median of N with the cache cleared, so every measured
  // frame does all of its stages. The pixels and seen points come from one more frame with seen points on.
  std::vector<double> times;
  RenderedFrame timed;
  {
    // Its own scope: its renderer is released while its context is current, before the next one exists.
    RenderSession timing;
    timing.seen_points = false;
    timing.read_back = false;  // the pixels come from the frame below: no readback in the timed frames
    for (int i = 0; i <= frames; ++i) {
      timing.cache = gl::FrameCache{};
      timed = renderFrame(ls, mode, gl_backend_name, &timing);
      if (i > 0) times.push_back(timed.frame_ms);
    }
  }
  std::sort(times.begin(), times.end());
  *median_ms = times[times.size() / 2];
  if (mode == RenderMode::Raytrace) return timed;
  RenderSession accuracy;
  RenderedFrame f = renderFrame(ls, mode, gl_backend_name, &accuracy);
  f.stages = std::move(timed.stages);
  for (StageTiming& t : f.stages.stages)
    if (t.name == gl::stage::kSeenPoints)
      t.reason = "timed colour-only, as pvrr render draws; the errors come from one more frame drawn with them";
  f.frame_ms = timed.frame_ms;
  return f;
}

// Renders one frame of a loaded scene in `mode` (raytrace or a raster mode). Used by render and compare.
RenderedFrame renderFrame(LoadedScene& ls, RenderMode mode, const std::string& gl_backend_name,
                          RenderSession* session) {
  RenderedFrame out;
  Scene& scene = ls.scene;
  if (mode == RenderMode::Raytrace) {
    RayScene rays(scene);
    // The scene's options and the caustic light of the lights with caustics on, once per render.
    const ReferenceSetup setup(rays);
    Tracer tracer(rays, setup.options());
    Progress progress("ray tracing", 1.0);
    Frame f = tracer.render([&](double frac) { progress.update(frac); });
    progress.finish();
    static_cast<Frame&>(out) = std::move(f);  // with its stage "ray-trace"
    if (setup.hasCaustics())
      out.stages.stages.insert(out.stages.stages.begin(), setup.stages().stages.begin(), setup.stages().stages.end());
    out.gl_backend = "none (CPU, Embree)";
    return out;
  }
  if (!session->context) session->context = gl::GlContext::create(gl::parseGlBackend(gl_backend_name));
  session->context->makeCurrent();
  if (!session->rays) {
    RaySceneOptions o;
    o.moving_elements = session->moving_elements;
    session->rays = std::make_unique<RayScene>(scene, o);
  }
  if (!session->renderer) {
    gl::RendererOptions ro = gl::rendererOptionsFor(scene);
    ro.seen_channel = session->seen_channel;
    ro.seen_points = session->seen_points;
    session->renderer = std::make_unique<gl::Renderer>(scene, *session->rays, ro);
  }
  session->renderer->setReadBack(session->read_back);
  gl::RasterFrame f = session->renderer->render(mode, &session->cache);
  out.elements = elementsJson(scene, f.elements);
  static_cast<Frame&>(out) = std::move(static_cast<Frame&>(f));
  out.gl_backend = session->context->backendName() + " (" + session->context->glRenderer() + ")";
  return out;
}

bool poseSceneAt(LoadedScene& ls, double t_s, RenderSession* session) {
  if (!isAnimated(ls.desc) || !applyAnimation(ls.scene, ls.desc, t_s)) return false;
  if (session->rays) {  // in place: only what moved (the renderer finds its moved meshes itself)
    session->rays->updateElementPoses();
    session->rays->updateEnvironmentMeshes();
  }
  return true;
}

namespace {
// The process's CPU time (every thread: llvmpipe's rasterizer threads too), ms.
double processCpuMs() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return double(ts.tv_sec) * 1e3 + double(ts.tv_nsec) * 1e-6;
}
// Frames left out of the per-frame CPU figures at the start of a run: the first is cold (shaders compiled, data
// uploaded), the next few still settle (caches filled, a split's parts drawn once, driver allocations).
constexpr int kCpuWarmupFrames = 3;
}  // namespace

int cmdRender(const std::vector<std::string>& argv) {
  Args a("render", argv, {"mode", "size", "out", "gl", "set", "stats", "frames", "orbit", "time", "fps", "alternate"}, {},
         {"set", "alternate"});
  if (a.positional().size() > 1) usageError("render", "expected at most one scene file");
  const std::string scene_path = a.positional().empty() ? kDefaultScene : a.positional()[0];
  const auto size = a.getSize("size");
  const int frames = a.getInt("frames", 1, 1);
  const double orbit_deg = a.getDouble("orbit", 0.0);
  const double time0_s = a.getDouble("time", 0.0), fps = a.getDouble("fps", 30.0);
  if (!(fps > 0)) usageError("render", "--fps: expected a number > 0, got \"" + *a.get("fps") + "\"");
  LoadedScene ls = loadScene(scene_path, a.all("set"), size ? size->first : 0, size ? size->second : 0);
  const auto mode_arg = a.get("mode");
  // Validated before any work.
  const RenderMode mode = mode_arg ? parseModeOption(*mode_arg, true) : ls.scene.render.mode;
  const std::string out_path = a.get("out", ls.scene.render.output);
  const std::string gl_name = gl::glBackendName(backendArg(a));

  // --alternate PATH=VALUE: a second copy of the scene with these overrides too, drawn after each frame of the
  // first in its own session (context, renderer, caches), so that both are timed side by side frame by frame:
  // the machine's load, which shifts whole runs, falls on both alike.
  const std::vector<std::string> alt_sets = a.all("alternate");
  std::unique_ptr<LoadedScene> alt;
  RenderSession alt_session;
  std::vector<double> alt_cpu_ms;
  if (!alt_sets.empty()) {
    if (orbit_deg != 0 || isAnimated(ls.desc) || mode == RenderMode::Raytrace)
      usageError("render", "--alternate: only for a raster mode's steady frames (no --orbit, no animated scene)");
    std::vector<std::string> sets = a.all("set");
    sets.insert(sets.end(), alt_sets.begin(), alt_sets.end());
    alt = std::make_unique<LoadedScene>(loadScene(scene_path, sets, size ? size->first : 0, size ? size->second : 0));
    alt_session.seen_points = false;
    alt_session.read_back = false;
    alt_cpu_ms.reserve(size_t(frames));
  }
  RenderSession session;
  RenderedFrame last;
  std::vector<double> frame_times, frame_cpu_ms;
  frame_times.reserve(size_t(frames));
  frame_cpu_ms.reserve(size_t(frames));
  std::map<std::string, std::pair<int, int>> stage_counts;  // name -> (ran, skipped)
  std::map<std::string, double> stage_ms_sum;  // running sums: the bookkeeping of a long run stays O(1) a frame
  // Per stage, its skip reasons by kind (the text before the first ':', e.g. "map reuse", "eye-fixed cache"):
  // how many frames, and the last full text. Bounded by the kinds, not by the frames.
  std::map<std::string, std::map<std::string, std::pair<int, std::string>>> skip_reasons;
  const Vec3 eye0 = ls.scene.observer.eye, target0 = ls.scene.observer.target;
  const bool any_attached = std::any_of(ls.scene.elements.begin(), ls.scene.elements.end(),
                                        [](const Element& e) { return e.attached_to_observer; });
  session.moving_elements = frames > 1 && orbit_deg != 0 && any_attached;
  session.seen_points = false;  // the picture only: no seen-point attachments (stage "seen-points" skipped)
  // Memory soak (issue 7): resident memory after the baseline frame and at the end; a long run must not grow.
  const int rss_frame = rssBaselineFrame(frames);
  double rss_baseline_mb = 0;
  json rss_samples = json::array();  // [frame, MB] at about 20 points of the run, to tell growth from settling
  const int sample_every = std::max(1, frames / 20);
  const bool animated = isAnimated(ls.desc);
  int moved_frames = 0;  // frames in which something moved (updated in place in the renderer and the ray scene)
  for (int i = 0; i < frames; ++i) {
    if (frames > 1 && orbit_deg != 0) {
      // Turn the head about the vertical axis through the eye.
      const double angle = radians(orbit_deg) * (frames > 1 ? double(i) / double(frames - 1) : 0.0);
      const Mat4 rot = glm::rotate(Mat4(1.0), angle, ls.scene.observer.up);
      ls.scene.observer.eye = eye0;
      ls.scene.observer.target = eye0 + Vec3(rot * Vec4(target0 - eye0, 0.0));
      updateAttachedElements(ls.scene, ls.desc);
      // Re-committing the Embree scene rebuilds its BVH (tens of milliseconds): only when some element moves
      // with the head.
      if (session.rays && any_attached) session.rays->updateElementPoses();
      session.cache.environment_changed = false;
    }
    if (i > 0 && orbit_deg == 0) session.cache.environment_changed = false;
    // Time advances by 1 / fps a frame from --time (after the orbit: attached elements take both).
    if (poseSceneAt(ls, time0_s + double(i) / fps, &session) && i > 0) ++moved_frames;
    session.read_back = i + 1 == frames;  // only the last frame is written out
    const double cpu0 = processCpuMs();
    last = renderFrame(ls, mode, gl_name, &session);
    frame_cpu_ms.push_back(processCpuMs() - cpu0);
    if (alt) {
      if (i > 0) alt_session.cache.environment_changed = false;
      const double alt0 = processCpuMs();
      renderFrame(*alt, mode, gl_name, &alt_session);
      alt_cpu_ms.push_back(processCpuMs() - alt0);
    }
    if (i + 1 == rss_frame) rss_baseline_mb = currentRssMb();
    if ((i + 1) % sample_every == 0 || i + 1 == frames) rss_samples.push_back({i + 1, currentRssMb()});
    frame_times.push_back(last.frame_ms);
    for (const StageTiming& s : last.stages.stages) {
      auto& c = stage_counts[s.name];
      (s.ran ? c.first : c.second)++;
      if (s.ran) stage_ms_sum[s.name] += s.ms;
      else {
        auto& kind = skip_reasons[s.name][s.reason.substr(0, s.reason.find(':'))];
        ++kind.first;
        kind.second = s.reason;
      }
    }
  }
  // The first frame is cold (shaders compiled, scene data uploaded, caches empty): a newcomer's single frame
  // would report that as the frame time. One more frame, not read back, with the cache cleared so that every
  // stage runs again, gives the steady figure; the written picture stays the first frame's.
  const double first_ms = frame_times.front();
  double steady_ms = -1;
  if (frames == 1 && mode != RenderMode::Raytrace) {
    session.read_back = false;
    session.cache = gl::FrameCache{};
    steady_ms = renderFrame(ls, mode, gl_name, &session).frame_ms;
  }
  const double rss_end_mb = currentRssMb();
  const size_t bad = writeLinearPng(out_path, last.width, last.height, last.color);
  if (bad) std::fprintf(stderr, "pvrr render: warning: %zu non-finite pixels written as black\n", bad);
  const double frame_ms = median(frame_times);
  double mean_ms = 0;
  for (double t : frame_times) mean_ms += t;
  mean_ms /= double(frame_times.size());
  const double max_ms = *std::max_element(frame_times.begin(), frame_times.end());
  // The frames' CPU time (process CPU around each frame: the calling thread and llvmpipe's), over the frames
  // after the first kCpuWarmupFrames and before the last (which reads the picture back): without start-up, and
  // a preempted or cache-thrashed frame lands above the 10th percentile, which a loaded machine moves least.
  const int cpu_first = frames > kCpuWarmupFrames + 1 ? kCpuWarmupFrames : 0;
  const int cpu_end = frames > kCpuWarmupFrames + 1 ? frames - 1 : frames;
  const std::vector<double> cpu_steady(frame_cpu_ms.begin() + cpu_first, frame_cpu_ms.begin() + cpu_end);
  const double cpu_p10 = quantile(cpu_steady, 0.1), cpu_median = quantile(cpu_steady, 0.5),
               cpu_p90 = quantile(cpu_steady, 0.9);
  json alternate;
  if (alt) {
    const std::vector<double> steady(alt_cpu_ms.begin() + cpu_first, alt_cpu_ms.begin() + cpu_end);
    std::vector<double> paired;  // each frame's time over the first scene's frame just before it
    for (int i = cpu_first; i < cpu_end; ++i) paired.push_back(alt_cpu_ms[size_t(i)] / frame_cpu_ms[size_t(i)]);
    const double p10 = quantile(steady, 0.1), med = quantile(steady, 0.5);
    alternate = {{"sets", alt_sets},
                 {"frame_cpu_ms", {{"p10", p10}, {"median", med}, {"p90", quantile(steady, 0.9)},
                                   {"first", cpu_first + 1}, {"last", cpu_end}, {"first_frame", alt_cpu_ms.front()}}},
                 {"ratio_p10", p10 / cpu_p10}, {"ratio_median", med / cpu_median}, {"ratio_paired_median", median(paired)}};
    // Its renderer released while its own context is current; then the first session's context again.
    alt_session.context->makeCurrent();
    alt_session.renderer.reset();
    session.context->makeCurrent();
  }
  std::printf("%s\n", out_path.c_str());
  // With several frames the mean and the slowest too: a frame that renders its maps again (map reuse) or
  // re-traces its vertices stands out from the median.
  const std::string spread = frames > 1 ? ", median of " + std::to_string(frames) + " frames; mean " + fmt("%.3f", mean_ms) +
                                              " ms, slowest " + fmt("%.3f", max_ms) + " ms"
                                        : "";
  if (steady_ms >= 0) {
    std::printf("frame time: %.3f ms steady (a second frame, every stage run again); first frame %.3f ms (cold: shaders "
                "compiled, data uploaded) (%s, %dx%d, mode %s)\n",
                steady_ms, first_ms, last.gl_backend.c_str(), last.width, last.height, nameOf(mode));
  } else {
    std::printf("frame time: %.3f ms (%s, %dx%d, mode %s%s%s)\n", frame_ms, last.gl_backend.c_str(), last.width,
                last.height, nameOf(mode), spread.c_str(),
                (frames > 1 ? "; first frame " + fmt("%.3f", first_ms) + " ms (cold)" : std::string()).c_str());
  }
  if (frames > 1)
    std::printf("frame CPU time: p10 %.3f ms, median %.3f ms, p90 %.3f ms (process CPU, every thread; frames %d to %d of "
                "%d)\n",
                cpu_p10, cpu_median, cpu_p90, cpu_first + 1, cpu_end, frames);
  std::string alt_text;
  for (const std::string& set : alt_sets) alt_text += (alt_text.empty() ? "" : " --alternate ") + set;
  if (alt)
    std::printf("alternate frames (--alternate %s): frame CPU time p10 %.3f ms, median %.3f ms; over the scene as given: "
                "p10 %.3f, median %.3f, frame by frame (median) %.3f\n",
                alt_text.c_str(), alternate["frame_cpu_ms"]["p10"].get<double>(),
                alternate["frame_cpu_ms"]["median"].get<double>(), alternate["ratio_p10"].get<double>(),
                alternate["ratio_median"].get<double>(), alternate["ratio_paired_median"].get<double>());
  if (animated && frames == 1) std::printf("animation: t = %.4g s\n", time0_s);
  if (animated && frames > 1)
    std::printf("animation: t = %.4g s to %.4g s at %.4g fps; in %d of %d frame(s) after the first something moved "
                "(updated in place: the moved meshes' buffers and their own ray scene, the cube maps where they are)\n",
                time0_s, time0_s + double(frames - 1) / fps, fps, moved_frames, frames - 1);
  printQuality(last.elements, "");
  if (auto stats = a.get("stats")) {
    json j = {{"scene", scene_path}, {"mode", nameOf(mode)}, {"size", {last.width, last.height}}, {"gl", last.gl_backend},
              {"frame_ms", frame_ms}, {"frame_ms_mean", mean_ms}, {"frame_ms_max", max_ms}, {"frames", frames},
              {"frame_ms_first", first_ms}, {"time_s", time0_s}, {"fps", fps}, {"animated", animated},
              {"frames_moved", moved_frames},
              // Per frame, process CPU time (every thread), over frames first..last (1-based) of the run.
              {"frame_cpu_ms", {{"p10", cpu_p10}, {"median", cpu_median}, {"p90", cpu_p90},
                                {"first", cpu_first + 1}, {"last", cpu_end}, {"first_frame", frame_cpu_ms.front()}}},
              {"stages", stagesJson(last.stages)},
              {"elements", last.elements}, {"peak_rss_mb", peakRssMb()}};
    // Resident memory (MB) after frame `after_frame` and after the last frame, before the PNG is written.
    j["memory"] = {{"after_frame", rss_frame},
                   {"rss_after_frame_mb", rss_baseline_mb},
                   {"rss_end_mb", rss_end_mb},
                   {"rss_growth_mb", rss_end_mb - rss_baseline_mb},
                   {"peak_rss_mb", peakRssMb()},
                   {"rss_samples", rss_samples}};
    if (frames > 1) {
      json per = json::array();
      for (const auto& [name, c] : stage_counts) {
        // "reason": the most frequent kind's last text; "reasons": every kind with its frames.
        json reasons = json::array();
        std::string reason;
        int most = 0;
        for (const auto& [kind, n_text] : skip_reasons[name]) {
          reasons.push_back({{"frames", n_text.first}, {"reason", n_text.second}});
          if (n_text.first > most) most = n_text.first, reason = n_text.second;
        }
        per.push_back({{"name", name}, {"frames_ran", c.first}, {"frames_skipped", c.second},
                       {"mean_ms", c.first > 0 ? stage_ms_sum[name] / double(c.first) : 0.0},
                       {"reason", reason}, {"reasons", reasons}});
      }
      j["stage_frames"] = per;
      j["orbit_deg"] = orbit_deg;
    }
    if (steady_ms >= 0) j["frame_ms_steady"] = steady_ms;
    if (alt) j["alternate"] = alternate;
    writeFileAtomic(*stats, j.dump(2) + "\n");
  }
  return 0;
}

int cmdTrace(const std::vector<std::string>& argv) {
  Args a("trace", argv, {"ray", "pixel", "size", "wavelength", "set"}, {}, {"set"});
  if (a.positional().size() != 1) usageError("trace", "expected one scene file");
  if (a.has("ray") == a.has("pixel")) usageError("trace", "give exactly one of --ray and --pixel");
  const auto size = a.getSize("size");
  LoadedScene ls = loadScene(a.positional()[0], a.all("set"), size ? size->first : 0, size ? size->second : 0);
  const double wl = a.getDouble("wavelength", 0.0);
  if (a.has("wavelength") && (wl < 300 || wl > 1100)) usageError("trace", "--wavelength: expected 300..1100 nm");
  Vec3 o, d;
  if (a.has("ray")) {
    std::vector<double> r = a.getNumbers("ray", 6);
    o = Vec3(r[0], r[1], r[2]);
    d = Vec3(r[3], r[4], r[5]);
    if (glm::length(d) == 0) usageError("trace", "--ray: the direction must not be zero");
  } else {
    std::vector<double> p = a.getNumbers("pixel", 2);
    const Observer& ob = ls.scene.observer;
    if (p[0] < 0 || p[1] < 0 || p[0] > ob.width || p[1] > ob.height)
      usageError("trace", "--pixel: outside the " + std::to_string(ob.width) + "x" + std::to_string(ob.height) + " image");
    o = ob.eye;
    d = ob.pixelDirection(p[0], p[1]);
  }
  RayScene rays(ls.scene);
  TraceOptions to;
  to.max_depth = ls.scene.render.max_depth;
  Tracer tracer(rays, to);
  std::vector<PathSegment> path;
  tracer.trace(o, glm::normalize(d), wl, &path);
  json segs = json::array();
  for (const PathSegment& s : path) {
    json j = {{"origin", vec(s.origin)}, {"direction", vec(s.direction)}, {"event", s.event},
              {"element", s.element >= 0 ? json(ls.scene.elements[size_t(s.element)].name) : json(nullptr)},
              {"point", s.has_point ? vec(s.point) : json(nullptr)},
              {"normal", s.has_point ? vec(s.normal) : json(nullptr)}, {"n1", s.n1}, {"n2", s.n2}};
    segs.push_back(j);
  }
  json out = {{"segments", segs}};
  // Full double precision: 17 significant digits round-trip every double.
  std::printf("%s\n", out.dump(2).c_str());
  return 0;
}

}  // namespace pvrr::app
