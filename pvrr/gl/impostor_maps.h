// Impostor mode's per-element maps and its texture-unit plan: each lens's refractor height maps
// (pvrr/impostor/lens_height_map.h) and each mirror's surface maps (pvrr/impostor/surface_map.h), built on first use; which
// elements the fragments follow through each other's cubes (distance-normal impostors), how many layers each
// distance map has, and the units the element programs read them from.
#pragma once
#include <array>
#include <memory>
#include <vector>

#include "cad/lens.h"
#include "pvrr/gl/gl_objects.h"
#include "pvrr/gl/program.h"
#include "pvrr/gl/renderer.h"
#include "pvrr/impostor/lens_height_map.h"
#include "pvrr/impostor/surface_map.h"

namespace pvrr::gl {

// Impostor mode with several elements ([Dancsik and Minarik]'s distance-normal impostors): each element's cubes also show
// the other mirrors, with their surface points and normals, and a search that meets one goes on in that
// mirror's cubes; and the scene's lens, if it has one only (lensInCubes), through which the search refracts
// with the lens's height maps. The number of elements the fragment loop switches between (CUBE_ELEMENTS), or
// 0: one element, no mirror to meet, or more elements than kMaxCubeElements or the texture units allow (then
// each cube shows the environment only).
constexpr int kMaxCubeElements = 4;
// The element's own maps: a mirror's four surface maps (setMirrorMaps: position, du, dv, normal) or a lens's
// three height maps (setLensMaps), from kElementMapsUnit on, after a cube pair or a pvrr map (0, 1).
constexpr int kElementMapsUnit = 2;
constexpr int kSurfaceMapUnits = 4;
constexpr int kFirstCubeUnit = kElementMapsUnit + kSurfaceMapUnits;  // impostor mode: the cubes after them
// Pvrr mode's refinement (shaders/pvrr_refine.glsl): the patch's map depth after the surface maps.
constexpr int kRefineDepthUnit = kElementMapsUnit + kSurfaceMapUnits;
constexpr int kPeelUnit = 1;       // the first layer's seen points while its second layer is drawn

class ImpostorMaps {
 public:
  ImpostorMaps(const Scene& s, const RendererOptions& o, int texture_units)
      : scene(s), options(o), max_texture_units(texture_units) {}
  ~ImpostorMaps();
  ImpostorMaps(const ImpostorMaps&) = delete;
  ImpostorMaps& operator=(const ImpostorMaps&) = delete;

  // Lens e's height maps (RGBA32F: z and the outward normal) and outline mask (R32F), rebuilt when missing or
  // built from other surfaces or another outline; returns 1 when built.
  int updateLensMaps(size_t e);
  // Mirror e's surface maps, rebuilt when missing or built from another surface or outline; returns 1 when
  // built.
  int updateMirrorMaps(size_t e);
  // The uniforms of a mirror's impostor draw: its surface maps on kSurfaceMapUnits units from kElementMapsUnit,
  // the samples' placement in
  // their textures, and its pose.
  void setMirrorMaps(const Program& p, size_t e) const;
  // The uniforms of a lens's impostor draw (shaders/element_impostor.frag with LENS): its height maps
  // and outline mask on 3 units from kElementMapsUnit, their placement, its pose, its index at the R, G and B
  // wavelengths, and the tracer's depth limit and far distance. first_unit and rotation: where a mirror's program that
  // meets the lens in its cubes takes them (LENS_IN_CUBES: after the cubes, u_lens_to_local).
  void setLensMaps(const Program& p, size_t e, int first_unit = kElementMapsUnit,
                   const char* rotation = "u_to_local") const;

  // --- the texture-unit plan ---
  size_t lensCount() const;
  int cubeElements(RenderMode mode) const;
  // The layers of each impostor distance map (render.impostor_layers; [Umenhoffer et al.]): 2 where the texture units allow
  // the second layer's cubes (two more for one element, three more an element with CUBE_ELEMENTS), else 1.
  int impostorLayers(RenderMode mode) const;
  // Whether the lens is drawn in the other elements' cubes: the scene has one (the mirrors' programs take its
  // maps; its own program, which meets it again through a mirror, has them already).
  bool lensInCubes(RenderMode mode) const { return cubeElements(mode) > 0 && lensCount() == 1; }
  // The colour channels of element e's impostor program (IMPOSTOR_CHANNELS): a lens with dispersion refracts R,
  // G and B with their own indices, and so does a mirror that can show such a lens in its cubes.
  int impostorChannels(size_t e) const;
  // The uniforms of the fragment loop over every element's cubes (CUBE_ELEMENTS), for element e drawn from a
  // camera at `origin`: three cubes per element on units from kFirstCubeUnit (and, with two layers, the second
  // layer's three after them, from `cubes1`), their origins, the mirrors' materials, and the tracer's depth
  // limit.
  void setCubeElements(const Program& p, size_t e, const Vec3& origin, int layers,
                       const std::vector<std::unique_ptr<CubeTarget>>& cubes,
                       const std::vector<std::unique_ptr<CubeTarget>>& cubes1) const;

 private:
  const Scene& scene;
  const RendererOptions& options;
  int max_texture_units = 0;  // GL_MAX_TEXTURE_IMAGE_UNITS
  // Each lens's refractor height maps, built on first use (a lens's shape in its own frame never changes; its
  // pose reaches the shader as u_to_local).
  struct LensMaps {
    unsigned front = 0, back = 0, mask = 0;
    cad::SagSurfacePtr front_surface, back_surface;  // what they were built from (held: never a reused address)
    cad::Outline outline;                            // and the outline of their mask
    LensHeightMap map;
  };
  std::vector<LensMaps> lens_maps;
  // Each mirror's surface maps (position, derivatives, normal over its parameter domain), built on first use
  // and again if its surface changes.
  struct MirrorMaps {
    std::array<unsigned, 4> textures{};  // position (RGBA32F, w: outline mask), du, dv (RGBA16F), normal (RGBA32F)
    cad::SurfacePtr surface;             // what they were built from (held: never a reused address)
    bool has_outline = false;            // and the outline of their mask
    cad::Outline outline;
    SurfaceMap map;                      // its domain and size; the samples are dropped once uploaded
  };
  std::vector<MirrorMaps> mirror_maps;
};

}  // namespace pvrr::gl
