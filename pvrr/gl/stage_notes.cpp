#include "pvrr/gl/stage_notes.h"

#include <algorithm>
#include <array>
#include <functional>
#include <map>

#include "pvrr/base/format.h"
#include "pvrr/base/names.h"
#include "pvrr/gl/impostor_maps.h"
#include "pvrr/optics/spectrum.h"
#include "pvrr/method/view_volume.h"

namespace pvrr::gl {

std::string cullNote(const CullCount& c, bool cull_on) {
  if (c.drawn == 0) return "";
  if (!cull_on) return "back faces not culled (off)";
  return "back faces culled on " + std::to_string(c.culled) + " of " + std::to_string(c.drawn) + " closed-mesh draws";
}

namespace {
bool hasLens(const Scene& scene) {
  return std::any_of(scene.elements.begin(), scene.elements.end(),
                     [](const Element& e) { return e.type == ElementType::Lens; });
}
}  // namespace

void noteCpuStagesSkipped(FrameStages& stages, const Scene& scene, RenderMode mode) {
  const size_t n_el = scene.elements.size();
  const bool has_lens = hasLens(scene);
  const std::string why = n_el == 0 ? "no mirror or lens in the scene" : std::string("mode ") + nameOf(mode);
  stages.skipped(stage::kVertexRays, mode == RenderMode::Impostor && n_el > 0
                                         ? why + ": each fragment reflects or refracts its own ray (second pass)"
                                         : why);
  if (mode == RenderMode::Impostor && has_lens)
    stages.skipped(stage::kRefraction, why + ": per fragment, through the lens's refractor height maps (second pass)");
  else
    stages.skipped(stage::kRefraction, has_lens ? why : "no lens in the scene");
  stages.skipped(stage::kViewpointFit, why);
  stages.skipped(stage::kTextureCoordinates, why);
  if (mode == RenderMode::Impostor && has_lens) {
    int most = 1;
    bool spectral = false;
    for (size_t e = 0; e < n_el; ++e) {
      const size_t n = dispersionChannels(scene, int(e)).size();
      most = std::max(most, n > 1 ? 3 : 1);
      spectral = spectral || n > 3;
    }
    if (most > 1)
      stages.ran(stage::kColourChannels, 0, most,
                 std::string("R, G and B refracted with their own index per fragment") +
                     (spectral ? " (spectral dispersion approximated by the C, d and F lines in mode impostor)" : ""));
    else
      stages.skipped(stage::kColourChannels, "dispersion off: one wavelength (the d line)");
  } else {
    stages.skipped(stage::kColourChannels, why);
  }
}

void notePvrrCpuStages(FrameStages& stages, const PvrrCpuStages& s, const std::vector<ElementFrame>& frames) {
  const std::string cached = "eye-fixed cache: no element moved relative to the eye";
  if (s.all_reused) stages.skipped(stage::kVertexRays, cached);
  else
    stages.ran(stage::kVertexRays, s.rays_ms, -1,
               s.mirror_rays == 0 ? std::string()
                                  : std::to_string(s.beside) + " of " + std::to_string(s.mirror_rays) +
                                        " mirror rays traced beside their own mirror");
  if (!s.has_lens) stages.skipped(stage::kRefraction, "no lens in the scene");
  else if (s.all_reused) stages.skipped(stage::kRefraction, cached);
  else stages.ran(stage::kRefraction, s.refraction_ms);
  if (s.all_reused) stages.skipped(stage::kViewpointFit, cached);
  else stages.ran(stage::kViewpointFit, s.fit_ms);
  if (s.any_texcoords) stages.ran(stage::kTextureCoordinates, s.texcoord_ms);
  else stages.skipped(stage::kTextureCoordinates, s.nothing_moved ? "nothing moved since the last frame"
                                                                  : "computed with the viewpoint fit");
  size_t most_channels = 1;
  bool spectral = false;
  for (const ElementFrame& f : frames) {
    most_channels = std::max(most_channels, f.rays.size());
    const bool rgb = f.channels.size() == 3 && f.channels[0].wavelength_nm == kRgbWavelengths_nm[0] &&
                     f.channels[1].wavelength_nm == kRgbWavelengths_nm[1] &&
                     f.channels[2].wavelength_nm == kRgbWavelengths_nm[2];
    spectral = spectral || (f.channels.size() > 1 && !rgb);
  }
  if (most_channels > 1) {
    const size_t sets = (most_channels + 2) / 3;
    stages.ran(stage::kColourChannels, 0, int(most_channels),
               std::to_string(most_channels) + (spectral ? " spectral samples" : " RGB channels (C, d, F lines)") +
                   " from one shared first pass, in " + std::to_string(sets) +
                   (sets == 1 ? " draw" : " additive draws") + " per patch");
  } else {
    stages.skipped(stage::kColourChannels, s.has_lens ? "dispersion off: one colour pass" : "no lens: one colour pass");
  }
}

void noteFirstPassesSkipped(FrameStages& stages, const Scene& scene, RenderMode mode) {
  const bool none = scene.elements.empty();
  stages.skipped(stage::kFirstPass, none ? "no mirror or lens in the scene" : std::string("mode ") + nameOf(mode));
  stages.skipped(stage::kNestedPasses, none ? "no mirror or lens in the scene" : "mode raster");
}

void notePvrrFirstPassSkipped(FrameStages& stages, const std::string& reuse_note) {
  const std::string why = !reuse_note.empty() ? reuse_note
                                              : "eye-fixed cache: neither the elements nor the environment moved relative to the eye";
  stages.skipped(stage::kFirstPass, why);
  stages.skipped(stage::kNestedPasses, why);
}

void notePvrrFirstPass(FrameStages& stages, const Scene& scene, const RendererOptions& options, const PassPlan& plan,
                       const std::vector<bool>& planes_slots, const PvrrFirstPass& s) {
  const std::vector<MapPass>& passes = plan.passes;
  int deepest = 0, rendered = 0;
  for (const MapPass& mp : passes) {
    deepest = std::max(deepest, mp.depth);
    rendered += mp.visible;
  }
  // The note: how many maps of which size (and which are R, G, B planes), and what was not rendered.
  std::map<std::array<int, 3>, int, std::greater<std::array<int, 3>>> sizes;
  for (const MapPass& mp : passes)
    if (mp.visible) {
      const std::array<int, 2> t = mapTexels(mp.owner->views[mp.view].volume, mp.side);
      ++sizes[{t[0], t[1], mp.slot < planes_slots.size() && planes_slots[mp.slot]}];
    }
  std::string note;
  for (const auto& [texels, n] : sizes)
    note += (note.empty() ? "" : ", ") + std::to_string(n) + " x " + std::to_string(texels[0]) + "x" +
            std::to_string(texels[1]) + (texels[2] ? " RGB planes" : "");
  if (s.widen)
    note += "; widened up to " + fmt("%.3g", options.map_reuse_margin_deg) + " deg for reuse (" +
            (s.reuse_note.empty() ? std::string("the environment changed") : s.reuse_note) + ")";
  else if (s.reuse_on)
    note += s.any_forward ? "; not widened for reuse: the last first pass had nested passes or elements drawn dark"
                          : "; not widened for reuse: reversed (zooming) maps are not reused";
  if (rendered != int(passes.size()))
    appendNote(note, std::to_string(passes.size() - size_t(rendered)) +
                         " map(s) of elements outside the observer's view or beyond the depth limit not rendered");
  if (s.unread > 0)
    appendNote(note, fmt("%.2g", 100.0 * double(s.unread) / double(s.texels)) +
                         " % of map texels left unshaded (no element reads them)");
  appendNote(note, cullNote(s.culled, options.cull_back_faces));
  stages.ran(stage::kFirstPass, s.ms, rendered, note);
  const size_t nested = plan.nested(), dark = plan.dark;
  const std::string dark_note =
      dark == 0 ? "" : std::to_string(dark) + " element(s) in a map drawn dark (" +
                           (plan.budget_hit ? "the budget of " + std::to_string(kMaxFirstPasses) + " first passes"
                                            : "render.max_depth = " + std::to_string(scene.render.max_depth)) + ")";
  if (nested > 0)
    stages.ran(stage::kNestedPasses, s.plan_ms, int(nested),
               std::to_string(nested) + " nested first pass(es), maps down to depth " + std::to_string(deepest) +
                   (dark_note.empty() ? "" : "; " + dark_note));
  else if (scene.elements.size() == 1)
    stages.skipped(stage::kNestedPasses, std::string("one ") + (hasLens(scene) ? "lens" : "mirror") + ": no nesting");
  else if (dark > 0)
    stages.skipped(stage::kNestedPasses, dark_note);
  else
    stages.skipped(stage::kNestedPasses, "no element is inside another element's view volume");
}

void noteCubeFirstPass(FrameStages& stages, const Scene& scene, RenderMode mode, bool cull_on, const CubeFirstPass& s) {
  const size_t n_el = scene.elements.size();
  std::string note = mode == RenderMode::Impostor ? "distance impostors: colour and seen-point cube maps" : "";
  if (s.layers > 1)
    appendNote(note, "two layers each where needed (the second depth-peeled, " + std::to_string(s.layer1_size) +
                         "^2 a face)");
  else if (mode == RenderMode::Impostor && scene.render.impostor_layers > 1)
    appendNote(note, "one layer each: too few texture units for the second layers' cubes");
  if (s.follow > 0) appendNote(note, "normal and index cube maps of the elements in them");
  if (s.height_maps > 0) appendNote(note, "refractor height maps of " + std::to_string(s.height_maps) + " lens(es) built");
  if (s.surface_maps > 0) appendNote(note, "surface maps of " + std::to_string(s.surface_maps) + " mirror(s) built");
  appendNote(note, cullNote(s.culled, cull_on));
  stages.ran(stage::kFirstPass, s.ms, -1, note);
  if (s.follow > 0)
    stages.ran(stage::kNestedPasses, 0, s.drawn_in_cubes,
               std::to_string(s.drawn_in_cubes) + " element(s) drawn into other elements' cube maps, with "
               "their normals and index (distance-normal impostors), followed per fragment up to "
               "render.max_depth = " + std::to_string(scene.render.max_depth) +
                   (s.lens_in_cubes ? "; the lens refracted through its height maps there"
                    : s.lens_count > 0 ? "; lenses are absent from other elements' cube maps (more than one)"
                                       : ""));
  else if (n_el == 1)
    stages.skipped(stage::kNestedPasses, std::string("one ") + (hasLens(scene) ? "lens" : "mirror") + ": no nesting");
  else if (mode == RenderMode::Impostor && s.lens_count == n_el)
    stages.skipped(stage::kNestedPasses, "mode impostor: lenses are absent from other elements' cube maps");
  else if (mode == RenderMode::Impostor)
    stages.skipped(stage::kNestedPasses, "mode impostor: more than " + std::to_string(kMaxCubeElements) +
                                             " elements (or too few texture units): other elements are absent from "
                                             "the cube maps");
  else
    stages.skipped(stage::kNestedPasses, std::string("mode ") + nameOf(mode) + ": other elements are absent from the cube maps");
}

std::string secondLayersNote(double ms, const std::string& cull_note, uint64_t pixels) {
  return "second layers drawn (" + fmt("%.1f", ms) + " ms: their cubes, " + cull_note + ", and the second draws): " +
         std::to_string(pixels) + " pixel(s) whose first-layer search ended off a surface";
}

std::string secondLayersSkippedNote() {
  return "second layers not drawn: every pixel's search ended on a surface in the first layer";
}

void noteSecondPass(FrameStages& stages, double ms, const std::string& cull_note, const std::string& layer_note,
                    bool seen_points) {
  std::string second_note = cull_note;
  appendNote(second_note, layer_note);
  stages.ran(stage::kSecondPass, ms, -1, second_note);
  if (seen_points)
    stages.ran(stage::kSeenPoints, 0, -1, "world-position attachments in every pass (for accuracy reports)");
  else
    stages.skipped(stage::kSeenPoints, "not requested: colour only (no seen-point attachments)");
}

}  // namespace pvrr::gl
