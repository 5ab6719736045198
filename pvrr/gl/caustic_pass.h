// Caustic maps (stage "caustic-maps"; issue 23 item 2, docs/caustics.md "Raster caustics"): the light that a
// light with caustics on (Light::caustics) sends through the mirrors and lenses onto the planar and height-field
// receivers, which the environment's shading adds in every pass (shaders/caustic_lookup.glsl).
//
// Per photon mesh of the plan (pvrr/method/caustic_mesh.h: exact photons at the vertices of a grid over each
// (light, element) aperture, per wavelength sample):
// 1. the caustic map: the mesh rasterized over its aperture into map_size^2 texels, each texel one photon with
//    its exit ray and power per unit aperture measure interpolated between the exact vertices
//    (shaders/caustic_map.*);
// 2. the splat: one point per texel, drawn into the light map of the receiver its ray meets first among the
//    mapped ones, with the reference's tent kernel one cell wide, power / cell area, summed by additive
//    blending in RGBA32F (shaders/caustic_splat.*). Each photon carries its texel's measure of the light's
//    power (irradiance x area, or intensity x solid angle), times the element's reflectance or the Fresnel
//    transmittances of its interfaces and the wavelength sample's colour weight.
//    A curved receiver (a height field over its plane, pvrr/method/caustic_mesh.h heightFieldReceivers): the
//    photon lands at its ray's first hit on the mesh, the texel's distance interpolated between the vertices'
//    exact hits, projected onto the plane, its power weighed by cos(theta) between the hit's normal and the
//    plane's (the irradiance per unit area of the surface); the layer's alpha holds the surface's height over
//    the plane per cell, which the lookup compares with the shaded point's.
//    A mesh that is neither planar nor a height field (a box, a sphere) is mapped per sheet (CausticReceiver::sheet):
//    the photon-mesh vertices carry the id of the sheet their exact hit triangle belongs to (CausticVertex::surface,
//    the direction texture's w), and a photon lands only on its own sheet's map.
// What is not drawn: light landing on a split mesh's triangles that are in no sheet, photons beyond a map's
// window (it holds 99 % of the landed power), the light reflected by a lens's surfaces; the stage's note says
// what the plan left out.
// The maps are made when the renderer's first frame needs them and again only when an element moved (the
// environment and the lights stand still for a renderer, as for the shadow maps).
#pragma once
#include <string>
#include <vector>

#include "pvrr/base/stats.h"
#include "pvrr/gl/gl_objects.h"
#include "pvrr/gl/programs.h"
#include "pvrr/method/caustic_mesh.h"
#include "pvrr/trace/irradiance_grid.h"

namespace pvrr::gl {

inline constexpr const char* kCausticMapsStage = "caustic-maps";

// The defines of an environment program that reads the maps (CAUSTICS); none when no light has caustics on.
std::vector<std::string> causticDefines(const Scene& scene);

// A receiver's light map, read back.
struct CausticMap {
  int mesh = -1;        // Scene::meshes index
  IrradianceGrid grid;  // irradiance per cell (no variance: not a Monte Carlo estimate)
  // A curved receiver: the surface's height over grid.rect's plane per cell (CausticReceiverMap::height); the
  // reference to compare with deposits with DepositOptions::height_field. Empty: planar.
  std::vector<float> height;
  // One sheet of a mesh split into sheets (a box's face; pvrr/method/receiver_sheets.h), or the whole mesh: the
  // reference to compare with deposits with DepositOptions::sheet.
  ReceiverSheet sheet;
};

class CausticPass {
 public:
  // map_size: the caustic map's side (photons per side of each aperture). Its unit is
  // units::causticMaps (pvrr/gl/texture_units.h).
  CausticPass(const Scene& scene, const RayScene& rays, const Programs& programs, int max_texture_units,
              int map_size = 512);
  ~CausticPass();
  CausticPass(const CausticPass&) = delete;
  CausticPass& operator=(const CausticPass&) = delete;

  // Plans and renders the maps if they are missing or an element moved; notes the stage (ran, reused, or
  // skipped with the reason).
  void update(FrameStages& stages);
  bool active() const { return !causticLights(scene_).empty(); }
  // Binds the maps and sets program p's caustic uniforms for a pass whose camera origin is `origin`.
  void bind(const Program& p, const Vec3& origin) const;
  // The receivers' maps as drawn (tests, pvrr compare). Empty before update() or without caustics.
  std::vector<CausticMap> readMaps() const;
  const CausticPlan& plan() const { return plan_; }

 private:
  void render();
  void splat(const CausticMesh& mesh);
  std::vector<Mat4> elementPoses() const;

  const Scene& scene_;
  const RayScene& rays_;
  const Programs& programs_;
  int unit_ = 0, map_size_ = 512;
  CausticPlan plan_;
  int cells_side_ = 0;           // the light maps' texture side (the largest window's cells)
  unsigned maps_ = 0, fbo_ = 0;  // the receivers' light maps (array layers) and a framebuffer
  unsigned photon_fbo_ = 0, photon_tex_[3] = {0, 0, 0}, empty_vao_ = 0;
  std::vector<Mat4> rendered_poses_;
  std::vector<Mat4> rendered_mesh_motion_;  // Scene::mesh_motion when the maps were made (a receiver may move)
  bool rendered_ = false;
};

}  // namespace pvrr::gl
