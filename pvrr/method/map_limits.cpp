#include "pvrr/method/map_limits.h"

#include <algorithm>

#include "pvrr/base/error.h"
#include "pvrr/base/format.h"
#include "pvrr/base/names.h"
#include "pvrr/method/pass_plan.h"

namespace pvrr {

namespace {

// Bytes per texel of the targets (pvrr/gl/renderer.cpp, pvrr_pass.cpp, gl_objects.cpp): RGBA32F 16, RGBA16F
// and RGBA16 8, R32F planes 3 x 4, depth 4.
double frameTargetBytes(const Scene& scene, const MapSizeSettings& s) {
  const double texels = double(scene.observer.width) * double(scene.observer.height);
  return texels * ((s.seen_points ? 16.0 + 2 * 16.0 : 8.0) + 4.0);
}

double pvrrMapBytes(const Scene& scene, int map_size, const MapSizeSettings& s) {
  double bytes = 0;
  for (const Element& el : scene.elements) {
    const size_t views = size_t(std::max(1, el.patches_u * el.patches_v));
    const double side = patchMapSize(map_size, views);
    // A lens's colour may be three R32F planes (RGB dispersion): the smaller of the two counts.
    const double colour = el.type == ElementType::Lens ? 12.0 : 16.0;
    bytes += double(views) * side * side * (colour + (s.seen_points ? 16.0 : 0.0) + 4.0);
  }
  return bytes;
}

double cubeBytes(const Scene& scene, RenderMode mode, int map_size, const MapSizeSettings& s) {
  const double n2 = double(map_size) * double(map_size);
  const bool with_seen = s.seen_points || mode == RenderMode::Impostor;
  return double(scene.elements.size()) * (6.0 * n2 * (8.0 + (with_seen ? 16.0 : 0.0)) + 4.0 * n2);
}

std::string sceneName(const Scene& scene) { return scene.source_path.empty() ? "scene" : scene.source_path; }

std::string gib(double bytes) {
  const double mib = bytes / (1024.0 * 1024.0);
  return mib < 1024 ? fmt("%.4g", mib) + " MiB" : fmt("%.4g", mib / 1024.0) + " GiB";
}

bool usesMaps(const Scene& scene, RenderMode mode) {
  return !scene.elements.empty() &&
         (mode == RenderMode::Pvrr || mode == RenderMode::Envmap || mode == RenderMode::Impostor);
}

// The first GL limit a map of side `map_size` exceeds ("" when none).
std::string mapLimitExceeded(const Scene& scene, RenderMode mode, int map_size, const GlLimits& g) {
  if (!usesMaps(scene, mode)) return "";
  if (mode == RenderMode::Pvrr) {
    // The largest top-level texture is the one of the element with the fewest patches.
    const int target = std::min(g.max_texture_size, g.max_renderbuffer_size);
    for (const Element& el : scene.elements) {
      const int side = patchMapSize(map_size, size_t(std::max(1, el.patches_u * el.patches_v)));
      if (side > target)
        return "a map of " + std::to_string(side) + " x " + std::to_string(side) + " texels exceeds this GL's " +
               (g.max_texture_size <= g.max_renderbuffer_size ? "GL_MAX_TEXTURE_SIZE " : "GL_MAX_RENDERBUFFER_SIZE ") +
               std::to_string(target);
    }
    return "";
  }
  if (map_size > g.max_cube_map_size)
    return "a cube face of " + std::to_string(map_size) + " x " + std::to_string(map_size) +
           " texels exceeds this GL's GL_MAX_CUBE_MAP_TEXTURE_SIZE " + std::to_string(g.max_cube_map_size);
  if (map_size > g.max_renderbuffer_size)
    return "a cube face's depth buffer of " + std::to_string(map_size) + " x " + std::to_string(map_size) +
           " texels exceeds this GL's GL_MAX_RENDERBUFFER_SIZE " + std::to_string(g.max_renderbuffer_size);
  return "";
}

bool fits(const Scene& scene, RenderMode mode, const MapSizeSettings& s, int map_size, const GlLimits& g) {
  if (!mapLimitExceeded(scene, mode, map_size, g).empty()) return false;
  MapSizeSettings t = s;
  t.map_size = map_size;
  return !(g.memory_bytes > 0) || mapMemoryBytes(scene, mode, t) <= g.memory_bytes;
}

// The largest map_size below s.map_size (at least 16, the scene format's least) that fits, or 0.
int largestFitting(const Scene& scene, RenderMode mode, const MapSizeSettings& s, const GlLimits& g) {
  int lo = 16, hi = s.map_size - 1;
  if (hi < lo || !fits(scene, mode, s, lo, g)) return 0;
  while (lo < hi) {  // fits(lo), and memory and limits grow with the size
    const int mid = lo + (hi - lo + 1) / 2;
    if (fits(scene, mode, s, mid, g))
      lo = mid;
    else
      hi = mid - 1;
  }
  return lo;
}

}  // namespace

double mapMemoryBytes(const Scene& scene, RenderMode mode, const MapSizeSettings& settings) {
  double bytes = frameTargetBytes(scene, settings);
  if (!usesMaps(scene, mode)) return bytes;
  if (mode == RenderMode::Pvrr) return bytes + pvrrMapBytes(scene, settings.map_size, settings);
  return bytes + cubeBytes(scene, mode, settings.map_size, settings);
}

void checkMapLimits(const Scene& scene, RenderMode mode, const MapSizeSettings& settings, const GlLimits& limits) {
  const std::string name = sceneName(scene);
  const Observer& ob = scene.observer;
  const int target = std::min(limits.max_texture_size, limits.max_renderbuffer_size);
  if (ob.width > target || ob.height > target)
    throw Error(name + ": observer.image_size " + std::to_string(ob.width) + " x " + std::to_string(ob.height) +
                ": each side must be at most " + std::to_string(target) +
                " pixels on this GL (GL_MAX_TEXTURE_SIZE and GL_MAX_RENDERBUFFER_SIZE)");
  const auto any = [&](ElementType t) {
    return std::any_of(scene.elements.begin(), scene.elements.end(), [t](const Element& el) { return el.type == t; });
  };
  if (mode == RenderMode::Impostor)
    for (const auto& [side, what] :
         {std::pair{any(ElementType::Lens) ? settings.lens_height_map_size : 0, "lens height maps"},
          std::pair{any(ElementType::Mirror) ? settings.surface_map_size : 0, "mirror surface maps"}})
      if (side > limits.max_texture_size)
        throw Error(name + ": impostor mode's " + what + " of " + std::to_string(side) +
                    " texels exceed this GL's GL_MAX_TEXTURE_SIZE " + std::to_string(limits.max_texture_size));
  const std::string setting = name + ": render.map_size " + std::to_string(settings.map_size) + ": ";
  const auto advice = [&] {
    const int best = largestFitting(scene, mode, settings, limits);
    return best > 0 ? "; the largest render.map_size that fits is " + std::to_string(best)
                    : "; no render.map_size fits (lower observer.image_size)";
  };
  const std::string over = mapLimitExceeded(scene, mode, settings.map_size, limits);
  if (!over.empty()) throw Error(setting + over + advice());
  const double need = mapMemoryBytes(scene, mode, settings);
  if (!(limits.memory_bytes > 0) || need <= limits.memory_bytes) return;
  const std::string budget =
      ", over the memory budget of " + gib(limits.memory_bytes) + " (" + limits.memory_source + ")";
  if (!usesMaps(scene, mode))
    throw Error(name + ": observer.image_size " + std::to_string(ob.width) + " x " + std::to_string(ob.height) +
                ": the frame's targets need " + gib(need) + budget);
  throw Error(setting + nameOf(mode) + " mode needs at least " + gib(need) + " for its maps and frame targets" +
              budget + advice());
}

std::vector<double> mapLimitsKey(const Scene& scene, RenderMode mode, const MapSizeSettings& s, const GlLimits& g) {
  std::vector<double> k = {double(int(mode)),
                           double(s.map_size),
                           double(s.seen_points),
                           double(s.lens_height_map_size),
                           double(s.surface_map_size),
                           double(scene.observer.width),
                           double(scene.observer.height),
                           double(g.max_texture_size),
                           double(g.max_cube_map_size),
                           double(g.max_renderbuffer_size),
                           g.memory_bytes};
  for (const Element& el : scene.elements)
    k.insert(k.end(), {double(int(el.type)), double(el.patches_u), double(el.patches_v)});
  return k;
}

}  // namespace pvrr
