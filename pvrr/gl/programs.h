// The renderer's GL programs, each compiled on first use and kept: by sources and defines, plus the scene's
// light counts (shaders/shading.glsl) and NO_SEEN_POINTS when RendererOptions::seen_points is off. A renderer
// compiles the sky and its scene's kinds of environment mesh when it is made (EnvironmentPass), so that their
// compile errors come with it; the element programs of a mode when a frame of that mode first needs them.
#pragma once
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "pvrr/gl/program.h"
#include "pvrr/scene/scene.h"

namespace pvrr::gl {

// How an environment draw's fragments are ambient-occluded (the program variant; pvrr/gl/ao_fields.h): not at
// all, from the ground maps (a horizontal plane facing up), from the occlusion volumes, from the pass's
// low-resolution occlusion image (static receivers: pvrr/gl/environment_pass.h), from the vertices' values (a
// faceted face re-tessellated as a grid: pvrr/gl/ao_vertex_receivers.h).
enum class AoReceiver { None, Ground, Volume, Screen, Vertex };

class Programs {
 public:
  Programs(const Scene& scene, bool seen_points) : scene_(scene), seen_points_(seen_points) {}

  // A variant that writes seen points even with RendererOptions::seen_points off (the impostor cube maps,
  // whose seen points are the distances the search reads).
  static constexpr const char* kWithSeenPoints = "#define WITH_SEEN_POINTS";

  // The program of these sources and defines (the scene's added), built on first use.
  const Program& built(const std::string& vert, const std::string& frag, const std::vector<std::string>& d) const;
  // The variant that draws into a planes map (PLANES, shaders/outputs.glsl), which only scenes with a lens with
  // RGB dispersion need.
  const Program& planesVariant(const std::string& vert, const std::string& frag, std::vector<std::string> d) const;

  // Environment meshes (shaders/env.frag), with the shadow maps' defines when a light casts shadows
  // (shadowDefines, pvrr/gl/shadow_pass.h): FACETED (one normal per triangle), TEXTURED (a material with a
  // texture; without, no texture is sampled: llvmpipe samples inside a uniform branch all the same).
  // PEEL: the second layer of an impostor's distance map (shaders/outputs.glsl). ao: its ambient occlusion
  // variant (aoDefines; nothing without render.ambient_occlusion).
  const Program& env(bool faceted, bool textured, bool planes, bool with_seen = false, bool peel = false,
                     AoReceiver ao = AoReceiver::Volume) const;
  // The environment's occlusion alone (AO_IMAGE: colour = the occluded fraction), from the fields (ao: Ground or
  // Volume), into a pass's low-resolution occlusion image.
  const Program& envOcclusion(bool faceted, AoReceiver ao) const;
  // first_layer: an impostor cube's second layer, where nothing lies beyond the first (shaders/sky.frag).
  const Program& sky(bool planes, bool with_seen = false, bool first_layer = false) const;
  // Elements as plain surfaces (raster mode, and elements drawn dark at the depth limit).
  const Program& plain(bool planes) const;
  // Elements in envmap mode: a mirror, or a lens (LENS, the "refraction vectors" baseline).
  const Program& envmap(bool lens) const;
  // A pvrr element: its channels in one draw (1) or in sets of three (more: CHANNELS 3), a lens (LENS), with
  // RGB dispersion (RGB_CHANNELS: its maps are planes); planes: drawn into a planes map. refine > 0: an element
  // whose fragments search their exact rays in its maps with that many secant steps (REFINE,
  // shaders/pvrr_refine.glsl): a mirror's reflected ray, or each of a lens's channels' exit rays.
  // spheres (a refined lens): bit 0 its front, bit 1 its back is a sphere or plane, met in closed form
  // (SPHERE_FRONT, SPHERE_BACK); bit 2 its outline is an ellipse or circle, tested in closed form
  // (OUTLINE_ELLIPSE).
  // refine kRefineQuadratic: a refined mirror's triangles that need no search (REFINE_P2).
  // count (refine > 0): the variant that counts its fallbacks in atomic counters (REFINE_COUNT); llvmpipe
  // shades such a shader's fragments markedly slower, so only the draws whose counts are read take it.
  static constexpr int kRefineQuadratic = -1;
  const Program& pvrr(bool lens, size_t channels, bool rgb, bool planes, int refine = 0, int spheres = 0,
                      bool count = false) const;
  // Distance-impostor elements (shaders/element_impostor.frag): a mirror, or a lens with one or three
  // wavelengths; cube_elements > 0: searches that meet a mirror in a cube go on in its cubes (CUBE_ELEMENTS).
  // lens_in_cubes: the scene's one lens is drawn in the other elements' cubes and refracted through there.
  // layers: of each distance map (IMPOSTOR_LAYERS; 2: the second depth-peeled, searched where the first fails).
  // layer_draw, with two layers: 0 the first draw (it discards where it would search them), 1 the second
  // (LAYER_MARCH), 2 the probe between them (LAYER_PROBE: no search; pvrr/gl/cube_pass.cpp).
  const Program& impostor(bool lens, int channels, int cube_elements, bool lens_in_cubes, int layers,
                          int layer_draw) const;
  // An element drawn into another element's impostor cubes (CUBE_GEOMETRY): a mirror's exact surface point
  // and normal, a lens's mesh point; and its index.
  const Program& cubeGeometry(bool lens, bool peel) const;
  // A shadow map's casters (shaders/shadow_caster.*; pvrr/gl/shadow_pass.h): depth only, or (lens) depth and
  // the lens's transmittance. No scene defines.
  const Program& shadowCaster(bool lens) const;
  // The depth mask of a first pass's unread texels (shaders/map_mask.*; no scene defines).
  const Program& mask() const;

 private:
  std::vector<std::string> defines(std::vector<std::string> d) const;

  const Scene& scene_;
  bool seen_points_;
  mutable std::map<std::string, std::unique_ptr<Program>> built_;
  mutable std::unique_ptr<Program> mask_;
  mutable std::unique_ptr<Program> shadow_casters_[2];
};

}  // namespace pvrr::gl
