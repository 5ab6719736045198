#include "pvrr/gl/programs.h"

#include <algorithm>

#include "pvrr/gl/caustic_pass.h"
#include "pvrr/gl/ao_fields.h"
#include "pvrr/gl/shadow_pass.h"

namespace pvrr::gl {

// A program's defines, plus the scene's light counts (shaders/shading.glsl) and NO_SEEN_POINTS when
// RendererOptions::seen_points is off, unless the variant writes seen points all the same (kWithSeenPoints).
std::vector<std::string> Programs::defines(std::vector<std::string> d) const {
  int dir = 0, point = 0;
  for (const Light& l : scene_.lights) {
    dir += l.type == Light::Type::Directional;
    point += l.type == Light::Type::Point;
  }
  d.push_back("#define NUM_DIR_LIGHTS " + std::to_string(dir));
  d.push_back("#define NUM_POINT_LIGHTS " + std::to_string(point));
  if (!seen_points_ && std::find(d.begin(), d.end(), kWithSeenPoints) == d.end()) d.push_back("#define NO_SEEN_POINTS");
  return d;
}

const Program& Programs::built(const std::string& vert, const std::string& frag, const std::vector<std::string>& d) const {
  std::string key = vert + " " + frag;
  for (const std::string& x : d) key += "|" + x;
  std::unique_ptr<Program>& p = built_[key];
  if (!p) p = std::make_unique<Program>(vert, frag, defines(d));
  return *p;
}

const Program& Programs::planesVariant(const std::string& vert, const std::string& frag, std::vector<std::string> d) const {
  d.push_back("#define PLANES");
  return built(vert, frag, d);
}

const Program& Programs::env(bool faceted, bool textured, bool planes, bool with_seen, bool peel, AoReceiver ao) const {
  std::vector<std::string> d;
  if (with_seen) d.push_back(kWithSeenPoints);
  if (peel) d.push_back("#define PEEL");
  if (faceted) d.push_back("#define FACETED");
  if (textured) d.push_back("#define TEXTURED");
  if (planes) d.push_back("#define PLANES");
  for (const std::string& s : shadowDefines(scene_)) d.push_back(s);
  for (const std::string& s : causticDefines(scene_)) d.push_back(s);
  for (const std::string& s : aoDefines(scene_, ao)) d.push_back(s);
  return built("env.vert", "env.frag", d);
}

const Program& Programs::envOcclusion(bool faceted, AoReceiver ao) const {
  std::vector<std::string> d = {"#define AO_IMAGE"};
  if (seen_points_) d.push_back("#define NO_SEEN_POINTS");  // (defines() adds it otherwise)
  if (faceted) d.push_back("#define FACETED");
  for (const std::string& s : aoDefines(scene_, ao)) d.push_back(s);
  return built("env.vert", "env.frag", d);
}

const Program& Programs::sky(bool planes, bool with_seen, bool first_layer) const {
  if (first_layer) return built("sky.vert", "sky.frag", {kWithSeenPoints, "#define PEEL", "#define FIRST_LAYER"});
  if (with_seen && !seen_points_) return built("sky.vert", "sky.frag", {kWithSeenPoints});
  return planes ? planesVariant("sky.vert", "sky.frag", {}) : built("sky.vert", "sky.frag", {});
}

const Program& Programs::plain(bool planes) const {
  return planes ? planesVariant("element.vert", "element_plain.frag", {}) : built("element.vert", "element_plain.frag", {});
}

const Program& Programs::envmap(bool lens) const {
  return lens ? built("element.vert", "element_envmap.frag", {"#define LENS"})
              : built("element.vert", "element_envmap.frag", {});
}

const Program& Programs::pvrr(bool lens, size_t channels, bool rgb, bool planes, int refine, int spheres,
                              bool count) const {
  std::vector<std::string> d = {channels > 1 ? "#define CHANNELS 3" : "#define CHANNELS 1"};
  if (lens) d.push_back("#define LENS");
  if (rgb) d.push_back("#define RGB_CHANNELS");
  if (refine == kRefineQuadratic) d.push_back("#define REFINE_P2");
  if (refine > 0) {
    // Its depth edge test (shaders/pvrr_refine.glsl): GL 4.0's textureGather, in a GLSL 3.30 shader; counting,
    // GL 4.2's atomic counters and early fragment tests.
    d.push_back("#extension GL_ARB_texture_gather : require");
    if (count) {
      d.push_back("#extension GL_ARB_shader_atomic_counters : require");
      d.push_back("#extension GL_ARB_shader_image_load_store : require");
      d.push_back("#define REFINE_COUNT");
    }
    d.push_back("#define REFINE " + std::to_string(refine));
    if (spheres & 1) d.push_back("#define SPHERE_FRONT");
    if (spheres & 2) d.push_back("#define SPHERE_BACK");
    if (spheres & 4) d.push_back("#define OUTLINE_ELLIPSE");
  }
  return planes ? planesVariant("element.vert", "element_pvrr.frag", d) : built("element.vert", "element_pvrr.frag", d);
}

const Program& Programs::impostor(bool lens, int channels, int cube_elements, bool lens_in_cubes, int layers,
                                  int layer_draw) const {
  std::vector<std::string> d{"#define IMPOSTOR_ITERATIONS " + std::to_string(scene_.render.impostor_iterations),
                             "#define IMPOSTOR_CHANNELS " + std::to_string(channels),
                             "#define IMPOSTOR_LAYERS " + std::to_string(layers)};
  if (lens) d.push_back("#define LENS");
  if (cube_elements > 0) d.push_back("#define CUBE_ELEMENTS " + std::to_string(cube_elements));
  if (cube_elements > 0 && lens_in_cubes) d.push_back("#define LENS_IN_CUBES");
  if (layer_draw == 1) d.push_back("#define LAYER_MARCH");
  if (layer_draw == 2) d.push_back("#define LAYER_PROBE");
  return built("element.vert", "element_impostor.frag", d);
}

const Program& Programs::cubeGeometry(bool lens, bool peel) const {
  std::vector<std::string> d{"#define IMPOSTOR_ITERATIONS 0", "#define IMPOSTOR_CHANNELS 1",
                             "#define IMPOSTOR_LAYERS 1", "#define CUBE_GEOMETRY", kWithSeenPoints};
  if (lens) d.push_back("#define LENS");
  if (peel) d.push_back("#define PEEL");
  return built("element.vert", "element_impostor.frag", d);
}

const Program& Programs::shadowCaster(bool lens) const {
  std::unique_ptr<Program>& p = shadow_casters_[lens];
  if (!p)
    p = std::make_unique<Program>("shadow_caster.vert", "shadow_caster.frag",
                                  lens ? std::vector<std::string>{"#define LENS"} : std::vector<std::string>{});
  return *p;
}

const Program& Programs::mask() const {
  if (!mask_) mask_ = std::make_unique<Program>("map_mask.vert", "map_mask.frag");
  return *mask_;
}

}  // namespace pvrr::gl
